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
from tests.support.coat_scenes import coat_normal_scene

SAMPLES = 256


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
