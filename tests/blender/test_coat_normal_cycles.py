"""Principled's Coat Normal against Cycles: two smooth coated spheres under an area light and a
point light, the coat's highlights following a normal of their own. The left one's coat normal is
a Bump of wave bands (its base keeps the sphere's normal); the right one's base normal is a Bump of
noise and its coat normal an object-space Normal Map tilted sideways, so that each layer shades
about a different normal.

Parity as procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles (seed 0) at most
1.5x Cycles' own between seeds 0 and 1, plus 0.002; DRT with the Coat Normal unlinked (the coat on
the base's normal, as before DRT read it) must fail that limit."""
from __future__ import annotations

import bpy

from drt_engine.core.integrator import integrator
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

WIDTH, HEIGHT = 64, 32
SAMPLES = 256


def _coated(name, colour):
    material, node = ps.closure_material(name, "ShaderNodeBsdfPrincipled", Base_Color=colour, Roughness=0.6,
                                         Coat_Weight=1.0, Coat_Roughness=0.15)
    return material, node


def _bump(tree, height, strength=1.0, distance=0.2):
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = strength
    bump.inputs["Distance"].default_value = distance
    tree.links.new(height, bump.inputs["Height"])
    return bump.outputs["Normal"]


def _banded_coat():
    """The coat normal a Bump of wave bands across the sphere, the base on the sphere's normal."""
    material, node = _coated("Banded coat", (0.05, 0.08, 0.25, 1.0))
    tree = material.node_tree
    wave = tree.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 2.0
    tree.links.new(_bump(tree, wave.outputs["Fac"]), node.inputs["Coat Normal"])
    return material


def _tilted_coat():
    """The base normal a Bump of noise, the coat normal an object-space Normal Map tilted along x."""
    material, node = _coated("Tilted coat", (0.25, 0.06, 0.03, 1.0))
    tree = material.node_tree
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 6.0
    tree.links.new(_bump(tree, noise.outputs["Fac"], strength=0.6), node.inputs["Normal"])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    normal_map.space = "OBJECT"
    normal_map.inputs["Color"].default_value = (0.85, 0.35, 0.75, 1.0)
    normal_map.inputs["Strength"].default_value = 0.7
    tree.links.new(normal_map.outputs["Normal"], node.inputs["Coat Normal"])
    return material



def coat_normal_scene():
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    ps.add_light(scene, "Area", "AREA", 200.0, (1.5, -3.0, 3.0), size=1.5)
    ps.add_light(scene, "Point", "POINT", 300.0, (-3.0, -2.5, 1.0))
    ps.smooth_sphere("Banded", -1.1, _banded_coat())
    ps.smooth_sphere("Tilted", 1.1, _tilted_coat())
    return scene


def test_coat_normal_matches_cycles(drt, tmp_path):
    scene = coat_normal_scene()
    drt_img, cycles0, cycles1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name="coat-normal")
                                 for engine, seed in ps.RUNS]
    figures = ps.parity(drt_img.rgb, cycles0.rgb, cycles1.rgb)
    print("coat normal", figures)
    assert figures["ok"], ps.message("coat normal", figures)
    for material in bpy.data.materials:
        node = material.node_tree.nodes.get("Principled BSDF") if material.node_tree else None
        if node is not None:
            for link in list(node.inputs["Coat Normal"].links):
                material.node_tree.links.remove(link)
    unlinked = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="coat-unlinked")
    off = ps.parity(unlinked.rgb, cycles0.rgb, cycles1.rgb)
    print("coat normal unlinked", off)
    assert not off["ok"], f"the coat on the base's normal passes too: {off}"


def test_coat_normal_without_bump_map_correction(drt, tmp_path, monkeypatch):
    """With Bump Map Correction off Cycles takes the Coat Normal as it is, even where the view lies
    below it (the coat then reflects nothing there); DRT raising it anyway must fail the limit."""
    scene = coat_normal_scene()
    for material in bpy.data.materials:
        material.cycles.use_bump_map_correction = False
    drt_img, cycles0, cycles1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name="coat-uncorrected")
                                 for engine, seed in ps.RUNS]
    figures = ps.parity(drt_img.rgb, cycles0.rgb, cycles1.rgb)
    print("coat normal uncorrected", figures)
    assert figures["ok"], ps.message("coat normal uncorrected", figures)
    coat_turned = integrator._coat_turned
    monkeypatch.setattr(integrator, "_coat_turned", lambda shader, hits, raises: coat_turned(shader, hits, True))
    raised = ps.parity(rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="coat-raised").rgb, cycles0.rgb, cycles1.rgb)
    print("coat normal raised anyway", raised)
    assert not raised["ok"], f"DRT passes raising the coat normal too: {raised}"
