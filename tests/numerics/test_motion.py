"""Motion blur through Blender: shutter 0, a 720° spin over a 10-frame shutter, a teleport,
a parented animated hierarchy. Camera 5 m above looking down, black world, emissive subjects."""
import math

import bpy
import numpy as np
import pytest

from tests.support import blender_scenes as bs
from scene_helpers import fcurves

HALF_VIEW = 1.0  # orthographic view of 2 m x 2 m


def motion_scene(drt, res=32, samples=16):
    scene = bs.new_scene(res, res, samples)
    cam = scene.camera
    cam.location = (0, 0, 5)
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2 * HALF_VIEW
    scene.render.use_motion_blur = True
    scene.render.motion_blur_position = "START"
    scene.drt.filter_type = "BOX"  # each pixel integrates its own footprint: sums are areas,
    scene.render.filter_size = 1.0  # and nothing spills into pixels the subject never covers
    scene.frame_set(1)
    return scene


def linear_keys(obj, path, values):
    """Keys of ``path`` (all components) at {frame: value}, linearly interpolated."""
    for frame, value in values.items():
        setattr(obj, path, value)
        obj.keyframe_insert(path, frame=frame)
    for curve in fcurves(obj):
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"


def bar(scene, half_length=0.8, half_width=0.02, name="Bar"):
    h, w = half_length, half_width
    return bs.add_mesh(scene, name, [(-h, -w, 0), (h, -w, 0), (h, w, 0), (-h, w, 0)], [(0, 1, 2, 3)],
                       mat=bs.material("EMISSION", strength=1.0))


PIXEL_AREA = (2 * HALF_VIEW / 32) ** 2


def moving_and_still(scene, out_dir):
    """Red channel of the scene with motion blur as set, then with motion blur off."""
    moving = bs.render(scene, out_dir, "moving")["Combined"][..., 0]
    scene.render.use_motion_blur = False
    return moving, bs.render(scene, out_dir, "still")["Combined"][..., 0]


def pixel_radius(res):
    c = (np.arange(res) + 0.5) / res * 2 * HALF_VIEW - HALF_VIEW
    x, y = np.meshgrid(c, -c)
    return np.hypot(x, y), np.arctan2(y, x)


def test_shutter_zero_is_no_blur(drt, tmp_path):
    scene = motion_scene(drt)
    obj = bar(scene)
    linear_keys(obj, "location", {1: (0, 0, 0), 2: (0.5, 0, 0)})
    scene.frame_set(1)
    scene.render.motion_blur_shutter = 0.0
    zero = bs.render(scene, tmp_path, "zero")["Combined"]
    scene.render.use_motion_blur = False
    off = bs.render(scene, tmp_path, "off")["Combined"]
    assert np.array_equal(zero, off)


@pytest.mark.parametrize("turns", [2, 4])
def test_ten_frame_shutter_with_whole_turns_sweeps_a_whole_disk(drt, tmp_path, turns):
    """An arm 0.8 m long and 0.2 m wide, from the centre out, spins ``turns`` times over frames 1-11:
    every radius r < 0.8 m is lit a fraction asin(w / 2r) / π of the shutter, evenly around;
    nothing beyond the arm's reach (0.806 m). (With the shutter sampled at 5 fixed times, 4 turns put the arm at the same
    angle at every sample and it stood still; 2 turns, 180° apart, left slerp's direction to chance.)"""
    scene = motion_scene(drt, res=48, samples=64)
    obj = bs.add_mesh(scene, "Arm", [(0, -0.1, 0), (0.8, -0.1, 0), (0.8, 0.1, 0), (0, 0.1, 0)], [(0, 1, 2, 3)],
                      mat=bs.material("EMISSION", strength=1.0))
    linear_keys(obj, "rotation_euler", {1: (0, 0, 0), 11: (0, 0, turns * 2 * math.pi)})
    scene.frame_set(1)
    scene.render.motion_blur_shutter = 10.0
    image = bs.render(scene, tmp_path)["Combined"][..., 0]
    r, phi = pixel_radius(48)
    ring = (r > 0.3) & (r < 0.7)
    ratio = image[ring].mean() / (np.arcsin(0.1 / r[ring]) / math.pi).mean()
    quadrant = [image[ring & (np.floor((phi + math.pi) / (math.pi / 2)) == q)].mean() for q in range(4)]
    print(f"{turns} turns: ring brightness / expected {ratio:.3f}, quadrants max/min "
          f"{max(quadrant) / max(min(quadrant), 1e-12):.3f}, beyond reach {image[r > 0.836].max()}")
    assert abs(ratio - 1) < 0.08  # no shrinking: the whole disk is swept, with the right weight
    assert max(quadrant) / min(quadrant) < 1.15, quadrant  # evenly around, not a partial sweep
    assert image[r > 0.806 + 0.03].max() == 0.0  # silhouette: nothing outside the arm's reach


def test_teleporting_object_keeps_its_energy(drt, tmp_path):
    """Constant keys: a 0.4 m square jumps from x = -0.5 to x = +0.5 at frame 2, mid-shutter. The
    motion between the sampled shutter times is interpolated, so the square smears between its
    two places (as Cycles, which also interpolates its motion steps); its total light is that of
    the square at rest, and none lands outside the path it can take."""
    scene = motion_scene(drt, samples=32)
    obj = bs.add_mesh(scene, "Square", [(-0.2, -0.2, 0), (0.2, -0.2, 0), (0.2, 0.2, 0), (-0.2, 0.2, 0)],
                      [(0, 1, 2, 3)], mat=bs.material("EMISSION", strength=1.0))
    linear_keys(obj, "location", {1: (-0.5, 0, 0), 2: (0.5, 0, 0)})
    for curve in fcurves(obj):
        for key in curve.keyframe_points:
            key.interpolation = "CONSTANT"
    scene.frame_set(1)
    scene.render.motion_blur_position = "CENTER"
    scene.render.motion_blur_shutter = 2.0
    moving, still = moving_and_still(scene, tmp_path)
    assert still.sum() * PIXEL_AREA == pytest.approx(0.16, rel=0.01)
    assert moving.sum() * PIXEL_AREA == pytest.approx(0.16, rel=0.03)
    c = (np.arange(32) + 0.5) / 32 * 2 - 1
    outside_rows = np.abs(c) > 0.25
    assert moving[outside_rows].max() == 0.0


def test_parented_animated_hierarchy(drt, tmp_path):
    """A parent spins 90° over the shutter about the view axis; its child, 0.6 m out along x,
    also slides 0.2 m outward in its parent's frame. The child's light lands on the arc from
    angle 0 to 90° between radii 0.45 and 0.95 m, and its total equals the still child's."""
    scene = motion_scene(drt, samples=32)
    parent = bpy.data.objects.new("Parent", None)  # an empty
    scene.collection.objects.link(parent)
    child = bs.add_mesh(scene, "Child", [(-0.1, -0.1, 0), (0.1, -0.1, 0), (0.1, 0.1, 0), (-0.1, 0.1, 0)],
                        [(0, 1, 2, 3)], mat=bs.material("EMISSION", strength=1.0))
    child.parent = parent
    linear_keys(parent, "rotation_euler", {1: (0, 0, 0), 2: (0, 0, math.pi / 2)})
    linear_keys(child, "location", {1: (0.6, 0, 0), 2: (0.8, 0, 0)})
    scene.frame_set(1)
    scene.render.motion_blur_shutter = 1.0
    moving, still = moving_and_still(scene, tmp_path)
    assert still.sum() * PIXEL_AREA == pytest.approx(0.04, rel=0.03)
    assert moving.sum() * PIXEL_AREA == pytest.approx(0.04, rel=0.05)
    r, phi = pixel_radius(32)
    on_arc = (r > 0.4) & (r < 1.0) & (phi > -0.3) & (phi < math.pi / 2 + 0.3)  # a pixel of margin
    assert moving[~on_arc].max() == 0.0
    # the sweep covers the whole arc: light in each third of it
    for lo, hi in ((0.0, 0.5), (0.5, 1.0), (1.0, 1.5)):
        assert moving[on_arc & (phi > lo) & (phi < hi)].sum() > 0.15 * moving.sum()
