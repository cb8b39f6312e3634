"""New materials, worlds and lights with the node trees Blender 5.0 gives them, and a compositor node tree,
in every Blender the tests run under (``make test-versions``).

Blender 5.0 gives a new material a Principled BSDF node tree and a new world a Background one, and
deprecates ``use_nodes``; Blender 4.x makes the same trees when ``use_nodes`` is switched on. The
tests build their scenes through these so that each version renders the same scene.
"""
import bpy


def with_nodes(idblock):
    """``idblock`` (a material, world or light) with its node tree, switching ``use_nodes`` on only
    where it has none (Blender 5.2 deprecates the switch for lights too)."""
    if idblock.node_tree is None:
        idblock.use_nodes = True
    return idblock


def new_material(name: str) -> bpy.types.Material:
    return with_nodes(bpy.data.materials.new(name))


def new_world(name: str) -> bpy.types.World:
    return with_nodes(bpy.data.worlds.new(name))


def new_compositor(scene) -> bpy.types.NodeTree:
    """An empty compositor node tree for ``scene``: a node group of its own in Blender 5.0+, the
    scene's own tree (``use_nodes``) in 4.x."""
    if not hasattr(scene, "compositing_node_group"):
        scene.use_nodes = True
        scene.node_tree.nodes.clear()
        return scene.node_tree
    scene.compositing_node_group = bpy.data.node_groups.new("Compositing", "CompositorNodeTree")
    return scene.compositing_node_group
