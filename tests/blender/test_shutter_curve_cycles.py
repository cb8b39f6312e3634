"""Motion blur's shutter curve and Cycles' rolling shutter in DRT against Cycles.

An emissive half-plane slides across an orthographic camera's view over a one-frame shutter, so
the blurred edge is a ramp whose shape is how long the shutter is open at each moment: a curve that
opens fast and closes slowly bends it, and a rolling shutter moves the ramp from row to row. The
rule is the node parity's (procedural_scenes.parity) over RGBA. DRT with the curve or the rolling
shutter ignored fails each case. The flat default curve is read through Cycles' table too, whose
times run from 0.002 to 0.994 of the shutter (times uniform over the whole shutter failed it: 0.0090
against a limit of 0.0068).
"""
from __future__ import annotations

import sys
from pathlib import Path

import bpy
import pytest
from conftest import emission_material

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sample_scenes"))
from scene_helpers import linear_keys  # noqa: E402

CURVE = ((0.0, 0.0), (0.2, 1.0), (1.0, 0.15))
"""Shutter openness over the shutter: opens fast, closes slowly."""

CASES = {  # name -> (shutter curve points or None for the flat default, rolling shutter duration or None,
    # whether a fisheye camera slides over the still edge instead)
    "flat": (None, None, False),
    "curve": (CURVE, None, False),
    "rolling": (None, 0.3, False),
    "curve_and_rolling": (CURVE, 0.5, False),
    "curve_panoramic_camera_moving": (CURVE, None, True),
}

SAMPLES = 256


def sliding_edge_scene(curve=None, rolling=None, camera_moves=False):
    """A glowing half-plane x < X(t) sliding 1.5 m per frame (linear keys, frame 1 blurred over one
    frame) under an orthographic camera 2 m wide (64 x 32 pixels); ``camera_moves``: the half-plane
    still and a fisheye (fov 2 radians) 1 m above it sliding 0.6 m per frame the other way."""
    scene = ps._scene(64, 32)
    ps.black_world(scene)
    mesh = bpy.data.meshes.new("edge")
    mesh.from_pydata([(-50, -50, 0), (0, -50, 0), (0, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(emission_material(1.0))
    edge = bpy.data.objects.new("edge", mesh)
    scene.collection.objects.link(edge)
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 1.0 if camera_moves else 5.0), (0.0, 0.0, 0.0)
    if camera_moves:
        cam.data.type, cam.data.panorama_type, cam.data.fisheye_fov = "PANO", "FISHEYE_EQUIDISTANT", 2.0
    else:
        cam.data.type, cam.data.ortho_scale = "ORTHO", 2.0
    moving, speed = (cam, -0.6) if camera_moves else (edge, 1.5)
    for frame in (0, 2):
        moving.location.x = speed * (frame - 1)
        moving.keyframe_insert("location", index=0, frame=frame)
    linear_keys(moving)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    if curve is not None:
        mapping = scene.render.motion_blur_shutter_curve
        points = mapping.curves[0].points
        while len(points) > 2:
            points.remove(points[1])
        points[0].location, points[1].location = curve[0], curve[-1]
        for x, y in curve[1:-1]:
            points.new(x, y)
        mapping.update()
    if rolling is not None:
        scene.cycles.rolling_shutter_type = "TOP"
        scene.cycles.rolling_shutter_duration = rolling
    scene.frame_set(1)
    return scene


@pytest.mark.parametrize("case", CASES)
def test_shutter_curve_and_rolling_shutter_match_cycles(drt, tmp_path, case):
    scene = sliding_edge_scene(*CASES[case])
    renders = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name=case) for engine, seed in ps.RUNS]
    rh.save_side_by_side(f"shutter-{case}", renders[0].rgb, renders[1].rgb)
    combined = [r.passes["Combined"] for r in renders]
    figures = ps.parity(*combined)
    print(f"{case}: DRT {figures['worst']:.4f}, Cycles' seeds {figures['cycles_seeds']:.4f}")
    assert figures["ok"], ps.message(case, figures)
    ramp = combined[1][..., 0]
    assert ((ramp > 0.05) & (ramp < 0.95)).mean() > 0.2  # the blur is seen


def test_a_flat_shutter_curve_reads_cycles_table(drt):
    camera = render_export(sliding_edge_scene()).camera
    assert camera.rolling_shutter is None
    assert abs(camera.shutter_table[0] - 0.002) < 1e-3 and abs(camera.shutter_table[-1] - 0.994) < 1e-3
