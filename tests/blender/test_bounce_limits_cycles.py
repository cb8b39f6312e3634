"""Cycles' Glossy and Transmission bounce limits against Cycles with the same Light Paths.

Two scenes under a grey world with a sun on a red diffuse sphere: a hall of two facing glossy
mirrors (glossy bounces 1: the camera's first mirror shows the sphere and the world, the second
mirror in it shows only what its terminated rays see, no lit surface), and a glass ball over a
diffuse floor (transmission bounces 1: the ray leaving the ball is the path's second
transmission, so the floor seen through the ball is dark but for the world). The rule is
procedural_scenes.parity's (worst 4x4-block difference from Cycles seed 0 within 1.5x Cycles' own
seed-to-seed worst plus 0.002); each test also renders DRT with the limit at the Total (8, where it
never binds) and asserts that image is far outside the limit, so a limit left unread fails.
Measured (48 x 48, 64 samples): glossy bounces 1, worst block 0.0076 against the limit 0.0155
(limit ignored: 0.4231); transmission bounces 1, 0.0133 against 0.0212 (ignored: 0.4499).
"""
from __future__ import annotations

import bpy

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.blender_scenes import add_light
from tests.support.datablocks import new_material, new_world

SIZE = 48
SAMPLES = 128


def _bsdf_material(name, node_type, **inputs):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new(node_type)
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def _base_scene(camera, lens):
    scene = ps.dark_scene(SIZE, camera, lens, False)
    world = new_world("Grey")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.4, 0.5, 0.6, 1.0)
    scene.world = world
    red = _bsdf_material("Red", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.1, 0.1, 1.0))
    ps.add_primitive(bpy.ops.mesh.primitive_uv_sphere_add, red, "Sphere", radius=0.6, location=(0.0, 0.0, 0.0),
                     segments=32, ring_count=16)
    add_light(scene, "SUN", rotation=(0.5, 0.4, 0.0), energy=3.0)
    return scene


def mirror_hall():
    """The red sphere between two glossy mirrors facing each other across x."""
    scene = _base_scene((0.4, -3.5, 0.3), 18.0)
    mirror = _bsdf_material("Mirror", "ShaderNodeBsdfGlossy", Color=(0.9, 0.9, 0.9, 1.0), Roughness=0.1)
    for x in (-1.2, 1.2):
        ps.add_primitive(bpy.ops.mesh.primitive_plane_add, mirror, f"Mirror {x}", size=8.0, location=(x, 0.0, 0.0),
                         rotation=(0.0, 1.5708, 0.0))
    return scene


def glass_ball():
    """A glass ball in front of the red sphere, over a light diffuse floor."""
    scene = _base_scene((0.0, -6.0, 2.5), 35.0)
    floor = _bsdf_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, floor, "Floor", size=8.0, location=(0.0, 0.0, -0.6))
    glass = _bsdf_material("Glass", "ShaderNodeBsdfGlass", Roughness=0.0, IOR=1.45)
    ps.smooth_sphere("Ball", 0.0, glass)
    ball = bpy.data.objects["Ball"]
    ball.location, ball.scale = (0.0, -1.6, 0.1), (0.8, 0.8, 0.8)
    return scene


def _compare(scene, setting, limit, tmp_path, name):
    setattr(scene.drt, setting, limit)
    image, cycles0, cycles1 = [r.rgb for r in ps.parity_renders(scene, tmp_path, name)]
    rh.save_side_by_side(name, image, cycles0)
    figures = ps.parity(image, cycles0, cycles1)
    setattr(scene.drt, setting, scene.drt.max_depth)  # the limit at the Total: never binds
    ignored = ps.worst_block(rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name=f"{name}-ignored").rgb, cycles0)
    print(f"{name}, {setting} {limit}: worst block {figures['worst']:.4f} (limit {figures['limit']:.4f}, "
          f"Cycles' seeds {figures['cycles_seeds']:.4f}); limit ignored {ignored:.4f}")
    assert figures["ok"], ps.message(f"{name}, {setting} {limit}", figures)
    assert ignored > 3.0 * figures["limit"]


def test_glossy_bounces_match_cycles(drt, tmp_path):
    _compare(mirror_hall(), "glossy_bounces", 1, tmp_path, "glossy_bounces_1")


def test_transmission_bounces_match_cycles(drt, tmp_path):
    _compare(glass_ball(), "transmission_bounces", 1, tmp_path, "transmission_bounces_1")
