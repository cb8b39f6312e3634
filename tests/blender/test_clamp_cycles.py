"""Cycles' Clamp Direct and Clamp Indirect against Cycles with the same settings.

A bright room corner under a black world: a light floor and a red wall lit by a strong small area
light, so that both the light a camera hit takes (direct) and the light after a bounce
(indirect, with diffuse bounces 2) pass 1 by far. Each clamp is set to 1 alone (Clamp Direct
without diffuse bounces, whose unclamped noise would swamp the comparison); both renderers
clamp every contribution (a light sample, an emitter a ray finds) to 3 x 1 on the sum of its RGB,
direct before the path's first bounce and indirect after (Cycles' film_clamp_light). Min Light
Bounces 8 keeps Russian roulette out (Cycles starts it at bounce 2 even without diffuse bounces).
The rule is procedural_scenes.parity's; each test also compares DRT without the clamp, which
must be far outside the limit, so a clamp left unread fails.
"""
from __future__ import annotations

import bpy
import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.blender_scenes import add_light
from tests.support.datablocks import new_material

SIZE = 48
SAMPLES = 128


def _diffuse(name, color):
    mat = new_material(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = 1.0
    return mat


def bright_corner(bounces):
    scene = ps.dark_scene(SIZE, (3.0, -4.0, 2.5), 30.0, False)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, _diffuse("Floor", (0.8, 0.8, 0.8, 1.0)), "Floor", size=4.0)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, _diffuse("Wall", (0.8, 0.2, 0.2, 1.0)), "Wall", size=4.0,
                     location=(0.0, 1.0, 2.0), rotation=(1.5708, 0.0, 0.0))
    add_light(scene, "AREA", location=(0.5, -0.5, 1.5), energy=1000.0, size=0.3)
    scene.drt.diffuse_bounces, scene.drt.min_light_bounces = bounces, 8
    return scene


@pytest.mark.parametrize("setting", ["sample_clamp_direct", "sample_clamp_indirect"])
def test_clamp_matches_cycles(drt, tmp_path, setting):
    scene = bright_corner(0 if setting == "sample_clamp_direct" else 2)
    setattr(scene.drt, setting, 1.0)
    image, cycles0, cycles1 = [r.rgb for r in ps.parity_renders(scene, tmp_path, setting)]
    rh.save_side_by_side(setting, image, cycles0)
    figures = ps.parity(image, cycles0, cycles1)
    setattr(scene.drt, setting, 0.0)
    unclamped = ps.worst_block(rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name=f"{setting}-off").rgb, cycles0)
    print(f"{setting} 1: worst block {figures['worst']:.4f} (limit {figures['limit']:.4f}, "
          f"Cycles' seeds {figures['cycles_seeds']:.4f}); unclamped {unclamped:.4f}")
    assert figures["ok"], ps.message(f"{setting} 1", figures)
    assert unclamped > 3.0 * figures["limit"]
