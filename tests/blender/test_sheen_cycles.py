"""The Sheen BSDF against Cycles: two smooth spheres of Cycles' microfiber sheen (roughness 0.2 and
0.8) under an area light behind them and a point light in front, the sheen's rim light at grazing
views; and with diffuse bounces 2 over a grey floor (paths continue through the sheen, sampled
through its transformed cosine); and under a uniform white world with no light, where the world's
light sample is drawn from the sheen (tests/support/sheen_scenes.py).

Parity as procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles (seed 0) at most
1.5x Cycles' own between seeds 0 and 1, plus 0.002; the same scene with the Sheen BSDF left out
(rendered default grey, as before DRT had it) must fail that limit.

Principled's sheen (Sheen Weight 1, tinted, over a dark base, and over a coat on the second sphere):
the sheen above the coat above the rest, each layer below attenuated by one minus the albedo of the
one above, as Cycles' closure.h stacks them; DRT with Sheen Weight 0 (as before) must fail."""
from __future__ import annotations

import bpy

from drt_engine.blender.export import materials as export_materials
from drt_engine.core.lights.collection import Lights
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.sheen_scenes import HEIGHT, WIDTH, sheen_scene

SAMPLES = 256


def test_sheen_bsdf_matches_cycles(drt, tmp_path, monkeypatch):
    scene = sheen_scene()
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, "sheen")
    monkeypatch.delitem(export_materials.CLOSURE_NODES, "ShaderNodeBsdfSheen")
    grey = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="grey")
    off = ps.parity(grey.rgb, cycles0.rgb, cycles1.rgb)
    print("left grey", off)
    assert not off["ok"], f"the Sheen BSDF left grey passes too: {off}"


def test_sheen_bsdf_with_diffuse_bounces_matches_cycles(drt, tmp_path):
    """With diffuse bounces on, paths continue through the sheen too, over a grey floor."""
    scene = sheen_scene(floor=True)
    scene.drt.diffuse_bounces = 2
    ps.assert_parity(scene, SAMPLES, tmp_path, "sheen-bounces")


def test_sheen_bsdf_under_a_white_world_matches_cycles(drt, tmp_path, monkeypatch):
    """Under a uniform world and no light, where Cycles finds the world by BSDF rays alone (it leaves
    such a world out of light sampling): DRT draws the world's light sample from the sheen itself
    (core.integrator.world_lobes); cosine-weighted about the normal, as before, its noise was nearly four
    times Cycles' and failed the limit."""
    scene = sheen_scene(white_world=True)
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, "sheen-white-world")
    monkeypatch.setattr(Lights, "uniform_world", property(lambda self: False))
    cosine = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="cosine")
    off = ps.parity(cosine.rgb, cycles0.rgb, cycles1.rgb)
    print("cosine-weighted world sample", off)
    assert not off["ok"], f"the cosine-weighted world sample passes too: {off}"


def principled_sheen_scene():
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    ps.add_light(scene, "Back", "AREA", 400.0, (0.5, 3.0, 2.5), size=2.0)
    ps.add_light(scene, "Point", "POINT", 300.0, (-3.0, -2.5, 1.0))
    for name, x, coat, tint in (("Velvet", -1.1, 0.0, (1.0, 0.6, 0.8, 1.0)), ("Coated velvet", 1.1, 1.0,
                                                                               (0.7, 0.9, 1.0, 1.0))):
        material, _ = ps.closure_material(name, "ShaderNodeBsdfPrincipled", Base_Color=(0.05, 0.03, 0.02, 1.0),
                                          Roughness=0.5, Sheen_Weight=1.0, Sheen_Roughness=0.4, Sheen_Tint=tint,
                                          Coat_Weight=coat, Coat_Roughness=0.2)
        ps.smooth_sphere(name, x, material)
    return scene


def test_principled_sheen_matches_cycles(drt, tmp_path):
    scene = principled_sheen_scene()
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, "principled-sheen")
    for material in bpy.data.materials:
        node = material.node_tree.nodes.get("Principled BSDF") if material.node_tree else None
        if node is not None:
            node.inputs["Sheen Weight"].default_value = 0.0
    plain = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="no-sheen")
    off = ps.parity(plain.rgb, cycles0.rgb, cycles1.rgb)
    print("sheen weight 0", off)
    assert not off["ok"], f"the Principled without its sheen passes too: {off}"
