"""Mist, Object Index and Material Index against Cycles on a scene built for them: a perspective
camera over a floor, two spheres and a box at different distances (so the mist ramp crosses the
image), each object and material with its own pass index, one material half transparent (Mist
weighs a hit by its opacity), under a world whose mist starts in front of the nearest object.

Mist follows the node parity's rule (procedural_scenes.parity): DRT's worst 4x4-block difference
from Cycles (seed 0) at most 1.5x Cycles' own between seeds 0 and 1, plus 0.002. The indices are
one sample's value, not a mean (Cycles writes its sample 0; DRT its first sample): they must equal
Cycles' exactly on every pixel whose 3x3 neighbourhood has one index in Cycles' image; on edge
pixels the first sample of either renderer may land on either side (counted, not compared)."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.film import film as film_module
from drt_engine.core.film import mist as mist_module
from drt_engine.core.integrator.integrator import Integrator
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world

WIDTH, HEIGHT = 48, 32
SAMPLES = 16
PASSES = ("Mist", "IndexOB", "IndexMA")
FALLOFFS = ("QUADRATIC", "LINEAR", "INVERSE_QUADRATIC")


def _material(name, color, index, alpha=1.0):
    mat = new_material(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Alpha"].default_value = alpha
    mat.pass_index = index
    return mat


def _add(op, mat, index, **kw):
    op(**kw)
    obj = bpy.context.active_object
    obj.data.materials.append(mat)
    obj.pass_index = index
    return obj


def mist_scene(falloff="QUADRATIC", camera="PERSP"):
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, (0.0, -9.0, 3.0))
    scene.camera.data.lens = 35.0
    scene.camera.data.type = camera
    scene.camera.data.ortho_scale = 9.0
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.05, 0.06, 1.0)
    world.mist_settings.start, world.mist_settings.depth = 4.0, 14.0
    world.mist_settings.falloff = falloff or "LINEAR"
    scene.world = world if falloff is not None else None  # None: Cycles' film defaults
    floor, red, glassy = (_material("Floor", (0.5, 0.5, 0.5), 1), _material("Red", (0.8, 0.1, 0.1), 2),
                          _material("Veil", (0.1, 0.3, 0.8), 4, alpha=0.6))
    _add(bpy.ops.mesh.primitive_plane_add, floor, 11, size=40.0)
    _add(bpy.ops.mesh.primitive_uv_sphere_add, red, 12, radius=1.0, location=(-1.6, -2.0, 1.0))
    _add(bpy.ops.mesh.primitive_uv_sphere_add, glassy, 13, radius=1.2, location=(1.2, 1.5, 1.2))
    _add(bpy.ops.mesh.primitive_cube_add, red, 14, size=1.5, location=(-0.5, 6.0, 0.75))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(sun)
    return scene


def renders(scene, tmp_path, name):
    """DRT seed 0, Cycles seeds 0 and 1 (procedural_scenes.RUNS), with the three passes."""
    return [rh.render(scene, engine, SAMPLES, seed, tmp_path, passes=PASSES, name=name) for engine, seed in ps.RUNS]


def interior(index: np.ndarray) -> np.ndarray:
    """Pixels whose 3x3 neighbourhood holds one index value (the pixel filter reaches 1.5 pixels)."""
    pad = np.pad(index, 1, mode="edge")
    same = np.ones(index.shape, bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= pad[dy:dy + index.shape[0], dx:dx + index.shape[1]] == index
    return same


def index_figures(drt: np.ndarray, cycles: np.ndarray) -> dict:
    inside = interior(cycles)
    return {"interior": int(inside.sum()), "interior_differ": int((drt != cycles)[inside].sum()),
            "edge": int((~inside).sum()), "edge_differ": int((drt != cycles)[~inside].sum()),
            "values": sorted(set(np.unique(cycles).tolist())), "drt_values": sorted(set(np.unique(drt).tolist()))}


@pytest.mark.parametrize("falloff, camera", [(f, "PERSP") for f in FALLOFFS] + [("LINEAR", "ORTHO"), (None, "PERSP")])
def test_mist_matches_cycles(drt, falloff, camera, tmp_path):
    """Orthographic cameras measure the distance along the view axis (Cycles' camera_distance); a
    scene without a world has Cycles' film defaults (start 0, depth 100, linear)."""
    drt_r, c0, c1 = renders(mist_scene(falloff, camera), tmp_path, f"mist-{falloff}-{camera.lower()}")
    figures = ps.parity(drt_r.passes["Mist"], c0.passes["Mist"], c1.passes["Mist"])
    print(f"Mist {falloff} {camera}: {figures}")
    assert figures["ok"], ps.message(f"Mist {falloff} {camera}", figures)
    assert c0.passes["Mist"].min() < 0.3 and c0.passes["Mist"].max() > 0.99  # the ramp crosses the image


@pytest.mark.parametrize("name", ["IndexOB", "IndexMA"])
def test_indices_match_cycles(drt, name, tmp_path):
    drt_r, c0, _ = renders(mist_scene(), tmp_path, f"index-{name}")
    figures = index_figures(drt_r.passes[name][..., 0], c0.passes[name][..., 0])
    print(f"{name}: {figures}")
    assert len(figures["values"]) >= 4  # the scene shows several indices and the background's 0
    assert figures["interior_differ"] == 0, figures
    assert set(figures["drt_values"]) <= set(figures["values"]), figures  # edges too: an index, never a blend


def test_the_comparisons_fail_without_the_computation(drt, monkeypatch, tmp_path):
    """With DRT's data passes switched off, Mist and both indices fail the comparisons above."""
    scene = mist_scene()
    _, c0, c1 = renders(scene, tmp_path, "off")
    monkeypatch.setattr(Integrator, "_data_passes", lambda self, group, shader, out: None)
    off = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, passes=PASSES, name="off-drt")
    assert not ps.parity(off.passes["Mist"], c0.passes["Mist"], c1.passes["Mist"])["ok"]
    for name in ("IndexOB", "IndexMA"):
        assert index_figures(off.passes[name][..., 0], c0.passes[name][..., 0])["interior_differ"] > 0, name


def test_orthographic_mist_fails_with_the_distance_from_the_camera(drt, monkeypatch, tmp_path):
    """An orthographic camera's mist measured from the camera's position instead of along its axis."""
    scene = mist_scene("LINEAR", "ORTHO")
    _, c0, c1 = renders(scene, tmp_path, "euclid")
    made = mist_module.Mist.__init__

    def from_position(self, camera, world):
        made(self, camera, world)
        self.axis = None

    monkeypatch.setattr(mist_module.Mist, "__init__", from_position)
    wrong = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, passes=PASSES, name="euclid-drt")
    assert not ps.parity(wrong.passes["Mist"], c0.passes["Mist"], c1.passes["Mist"])["ok"]


def test_mist_fails_when_hits_count_as_opaque(drt, monkeypatch, tmp_path):
    """The half-transparent sphere's mist taken whole (no opacity weight)."""
    scene = mist_scene("LINEAR")
    _, c0, c1 = renders(scene, tmp_path, "opaque")
    monkeypatch.setattr(MaterialShader, "transparency", lambda self, mu_o, rows=None: np.zeros((len(mu_o), 3)))
    wrong = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, passes=PASSES, name="opaque-drt")
    assert not ps.parity(wrong.passes["Mist"], c0.passes["Mist"], c1.passes["Mist"])["ok"]


def test_averaged_indices_fail(drt, monkeypatch, tmp_path):
    """With the film averaging the indices as it averages other passes, edge pixels blend two indices."""
    scene = mist_scene()
    _, c0, _ = renders(scene, tmp_path, "averaged")
    monkeypatch.setattr(film_module, "FIRST_SAMPLE_PASSES", ())
    averaged = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, passes=PASSES, name="averaged-drt")
    for name in ("IndexOB", "IndexMA"):
        figures = index_figures(averaged.passes[name][..., 0], c0.passes[name][..., 0])
        assert not set(figures["drt_values"]) <= set(figures["values"]), name
