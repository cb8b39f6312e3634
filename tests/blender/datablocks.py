"""New materials and worlds with the node trees Blender 5.0 gives them, in every Blender the tests
run under (``make test-versions``).

Blender 5.0 gives a new material a Principled BSDF node tree and a new world a Background one, and
deprecates ``use_nodes``; Blender 4.x makes the same trees when ``use_nodes`` is switched on. The
tests build their scenes through these so that each version renders the same scene.
"""
import bpy


def _with_nodes(idblock):
    if idblock.node_tree is None:
        idblock.use_nodes = True
    return idblock


def new_material(name: str) -> bpy.types.Material:
    return _with_nodes(bpy.data.materials.new(name))


def new_world(name: str) -> bpy.types.World:
    return _with_nodes(bpy.data.worlds.new(name))
