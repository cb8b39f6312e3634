"""Moving lights and a moving camera against Cycles, each check shown to fail on a render 3% too dark.

A point, a spot and an area light slide across a grey floor over the shutter (linear keys),
seen from above. Cycles does not blur lights (measured: with motion blur on, a moving light
renders exactly as at the frame), so its reference is the mean of still renders at SUBFRAMES
evenly spaced times over the shutter (the midpoint rule of the time integral DRT samples).
A perspective camera sliding past a cube on the floor under an area light is compared with
Cycles' own camera motion blur.

Checks, on the average of two DRT seeds against Cycles' reference: each channel's image mean
within BIAS (1%), and the mean relative difference over 4x4-pixel blocks brighter than 5% of
the image mean within BIAS plus twice the same statistic between the two DRT seeds (noise).
Every case also runs the checks on the DRT image scaled by 0.97 and requires them to fail,
so a 3% loss of light cannot pass. The point light (radius 0) has an analytic answer in
tests/core/test_moving_light_irradiance.py.
"""
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world
from test_cycles_compare import add_light, focused_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sample_scenes"))
from scene_helpers import fcurves  # noqa: E402

SUBFRAMES = 8
SHUTTER = 1.0
BIAS = 0.01
BLOCK = 4
FLOOR = 0.05
DARKER = 0.97


def grey_floor(scene):
    mat = new_material("Floor")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    mesh = bpy.data.meshes.new("Floor")
    mesh.from_pydata([(-5, -5, 0), (5, -5, 0), (5, 5, 0), (-5, 5, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(mat)
    scene.collection.objects.link(bpy.data.objects.new("Floor", mesh))
    return mat


def slide(obj, start, end):
    """Linear keys: ``start`` at frame 0, ``end`` at frame 2; the shutter is centred on frame 1."""
    for frame, location in ((0, start), (2, end)):
        obj.location = location
        obj.keyframe_insert("location", frame=frame)
    for curve in fcurves(obj):
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"


def moving_light_scene(kind, props):
    scene = focused_scene(32, 32, 2.4, (0.0, 0.0, 2.0), 0.0)
    grey_floor(scene)
    light = add_light(scene, kind, (0.0, 0.0, 0.6), energy=30.0, **props)
    slide(light, (-1.2, 0.0, 0.6), (1.2, 0.0, 0.6))  # 1.2 units over the 1-frame shutter
    return scene


def moving_camera_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rh.set_resolution(scene, 32, 32)
    scene.world = new_world("World")
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    mat = grey_floor(scene)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.0, 0.0, 0.3))
    bpy.context.active_object.data.materials.append(mat)
    add_light(scene, "AREA", (0.4, -0.3, 2.0), energy=200.0, shape="SQUARE", size=0.5)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.rotation_euler = (np.radians(35.0), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    slide(camera, (-0.8, -2.5, 3.5), (0.8, -2.5, 3.5))
    return scene


def still_average(scene, samples, tmp_path):
    """Cycles at SUBFRAMES evenly spaced times over the shutter, blur off, averaged."""
    scene.render.use_motion_blur = False
    images = []
    for k in range(SUBFRAMES):
        time = 1.0 - SHUTTER / 2 + SHUTTER * (k + 0.5) / SUBFRAMES
        scene.frame_set(int(time), subframe=time - int(time))
        images.append(rh.render(scene, "CYCLES", samples, k, tmp_path, name=f"still{k}").rgb.astype(np.float64))
    scene.frame_set(1)
    return np.mean(images, axis=0)


def blurred(scene, engine, samples, seed, tmp_path):
    scene.frame_set(1)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = SHUTTER
    scene.render.motion_blur_position = "CENTER"
    return rh.render(scene, engine, samples, seed, tmp_path).rgb.astype(np.float64)


def block_mard(a, b, reference):
    h, w, c = reference.shape

    def blocks(x):
        return x.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, c).mean(axis=(1, 3))

    ba, bb, br = blocks(a), blocks(b), blocks(reference)
    keep = br > FLOOR * reference.mean()
    return float((np.abs(ba - bb)[keep] / br[keep]).mean())


def failures(drt_pair, reference) -> list[str]:
    """What is wrong with the mean of the two DRT renders against the reference, as messages."""
    d0, d1 = drt_pair
    drt = (d0 + d1) / 2
    out = []
    for c, channel in enumerate("RGB"):
        diff = drt[..., c].mean() / reference[..., c].mean() - 1.0
        if abs(diff) > BIAS:
            out.append(f"{channel} mean {diff:+.2%}")
    noise = block_mard(d0, d1, reference)
    mard = block_mard(drt, reference, reference)
    if mard > BIAS + 2 * noise:
        out.append(f"block MARD {mard:.2%} > {BIAS + 2 * noise:.2%} (noise {noise:.2%})")
    return out


def assert_matches(drt_pair, reference):
    darker = failures([DARKER * d for d in drt_pair], reference)
    wrong = failures(drt_pair, reference)
    drt = (drt_pair[0] + drt_pair[1]) / 2
    print(f"\nDRT / reference means {drt.mean(axis=(0, 1)) / reference.mean(axis=(0, 1)) - 1}, block MARD "
          f"{block_mard(drt, reference, reference):.2%}, noise {block_mard(*drt_pair, reference):.2%}; "
          f"3% darker: {'; '.join(darker)}")
    assert darker, "the checks pass a render 3% too dark"
    assert not wrong, "; ".join(wrong)


@pytest.mark.parametrize("kind, props", [
    ("POINT", {"shadow_soft_size": 0.1}),
    ("SPOT", {"shadow_soft_size": 0.1, "spot_size": np.radians(100.0), "spot_blend": 0.3}),
    ("AREA", {"shape": "RECTANGLE", "size": 0.4, "size_y": 0.2}),
], ids=("point", "spot", "area"))
def test_moving_light_matches_cycles_still_frames(drt, tmp_path, kind, props):
    scene = moving_light_scene(kind, props)
    reference = still_average(scene, 64, tmp_path)
    pair = [blurred(scene, "DRT", 64, seed, tmp_path) for seed in (0, 1)]
    assert np.ptp(pair[0].mean(axis=(0, 2))) > 0.2 * pair[0].mean(), "the light should light the floor unevenly"
    assert_matches(pair, reference)


def test_moving_camera_matches_cycles_motion_blur(drt, tmp_path):
    scene = moving_camera_scene()
    reference = (blurred(scene, "CYCLES", 256, 0, tmp_path) + blurred(scene, "CYCLES", 256, 1, tmp_path)) / 2
    pair = [blurred(scene, "DRT", 64, seed, tmp_path) for seed in (0, 1)]
    assert_matches(pair, reference)
    scene.render.use_motion_blur = False  # the checks see the blur: DRT without it fails them
    sharp = [rh.render(scene, "DRT", 64, seed, tmp_path, name="sharp").rgb.astype(np.float64) for seed in (0, 1)]
    assert failures(sharp, reference)
