"""The Sheen BSDF's scenes against Cycles (tests/blender/test_sheen_cycles.py, and the white-world
row of bench/node_parity.py): two smooth spheres of Cycles' microfiber sheen, roughness 0.2 and 0.8."""
from __future__ import annotations

import bpy

from tests.support import procedural_scenes as ps
from tests.support.datablocks import new_world

WIDTH, HEIGHT = 64, 32


def sheen_scene(floor=False, white_world=False):
    """The sheen spheres under an area light behind them and a point light in front over a black
    world; with ``floor`` over a grey diffuse floor; with ``white_world`` under a uniform white world
    and no light (a world Cycles finds by BSDF rays alone, core.integrator.world_lobes)."""
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    if white_world:
        world = new_world("White")
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        scene.world = world
    else:
        ps.add_light(scene, "Back", "AREA", 400.0, (0.5, 3.0, 2.5), size=2.0)
        ps.add_light(scene, "Point", "POINT", 300.0, (-3.0, -2.5, 1.0))
    for name, x, rough, colour in (("Fine sheen", -1.1, 0.2, (0.9, 0.7, 0.5, 1.0)),
                                   ("Rough sheen", 1.1, 0.8, (0.5, 0.7, 0.9, 1.0))):
        material, _ = ps.closure_material(name, "ShaderNodeBsdfSheen", Color=colour, Roughness=rough)
        ps.smooth_sphere(name, x, material)
    if floor:
        material, _ = ps.closure_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
        bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, -1.0))
        bpy.context.active_object.data.materials.append(material)
    return scene
