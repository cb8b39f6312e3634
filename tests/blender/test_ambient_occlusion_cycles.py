"""The Ambient Occlusion node against Cycles: a cube standing on a floor (filling the view, so no
edge of it against the black world rules the figures) with a sphere beside it,
all of one emission material whose Strength is the node's AO, under a black world, so the image
is the AO field itself. Cases: the defaults (Distance 1, 16 samples), Distance 0.25, Inside, and
Only Local with the cube and the floor one object (the sphere's shadow on the floor goes, the
cube's stays).

Parity as procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles (seed 0) at most
1.5x Cycles' own between seeds 0 and 1, plus 0.002; the node left out (its Strength socket's own
value 1 everywhere) must fail that limit by far, and so must each case's setting left at the node's
default. Measured (64x48 px, 128 spp): default 0.0027 against a limit of 0.0069 (Cycles' seeds
0.0033), Distance 0.25 0.0031 against 0.0050, Inside 0.0069 against 0.0100, Only Local 0.0022
against 0.0067; the node ignored 0.49, 0.30, 0.70, 0.37; the setting ignored 0.31, 0.69, 0.49."""
from __future__ import annotations

import pytest

from drt_engine.blender.export.shader_graph import Compiler
from tests.support import node_scenes as ns
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export

SAMPLES = 128
CASES = ns.AO_CASES


@pytest.mark.parametrize("case", CASES)
def test_ambient_occlusion_matches_cycles(drt, tmp_path, monkeypatch, case):
    scene = ns.ambient_occlusion_scene(**CASES[case])
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, case)
    if CASES[case]:  # the case's setting left at the node's default must fail the limit too
        node = scene.objects["Sphere"].active_material.node_tree.nodes["Ambient Occlusion"]
        node.inputs["Distance"].default_value, node.inside, node.only_local = 1.0, False, False
        plain = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="plain")
        off = ps.parity(plain.rgb, cycles0.rgb, cycles1.rgb)
        print("setting ignored", off)
        assert off["worst"] > 2 * off["limit"], off
    monkeypatch.delattr(Compiler, "_node_ShaderNodeAmbientOcclusion")
    ignored = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="ignored")
    off = ps.parity(ignored.rgb, cycles0.rgb, cycles1.rgb)
    print("node ignored", off)
    assert off["worst"] > 5 * off["limit"], off


def test_ambient_occlusion_needs_no_warning(drt):
    """The node is rendered: no material warning names it."""
    data = render_export(ns.ambient_occlusion_scene())
    assert not any("Ambient Occlusion" in w for w in data.warnings), data.warnings


def test_distance_zero_is_the_worlds_ao_distance(drt, tmp_path):
    """Distance 0 unlinked is Cycles' global radius, the world's AO distance: the image of Distance
    0.25 when the world's is 0.25 (Cycles gives the very same image, seed for seed)."""
    scene = ns.ambient_occlusion_scene(distance=0.0)
    scene.world.light_settings.distance = 0.25
    data = render_export(scene)
    assert not any("Ambient Occlusion" in w for w in data.warnings), data.warnings
    glob = rh.render(scene, "DRT", 16, 0, tmp_path, name="global").rgb
    short = rh.render(ns.ambient_occlusion_scene(distance=0.25), "DRT", 16, 0, tmp_path, name="short").rgb
    assert (glob == short).all()
    far = rh.render(ns.ambient_occlusion_scene(distance=10.0), "DRT", 16, 0, tmp_path, name="far").rgb
    assert abs(float(far.mean()) - float(short.mean())) > 0.02
