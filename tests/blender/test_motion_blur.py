"""Motion blur through Blender: the shutter opens where Blender's settings say.

An emissive half-plane x < X(t) slides along x at v m per frame (linear keys), seen by an
orthographic camera. Rendered at frame 1 with a shutter of s frames, the edge leaves a
linear ramp v*s wide whose centre sits at X(1) + v*s/2 for START (the shutter opens at the
frame), X(1) for CENTER and X(1) - v*s/2 for END.
"""
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from conftest import emission_material, render_exr
from tests.support.datablocks import new_world

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sample_scenes"))
from scene_helpers import linear_keys  # noqa: E402

V, SHUTTER, WIDTH, HALF = 1.0, 0.5, 64, 1.0


def sliding_edge_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, 4
    scene.render.resolution_percentage = 100
    scene.render.filter_size = 1.0
    scene.drt.filter_type = "BOX"
    scene.drt.samples = 64
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = SHUTTER
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 2 * HALF
    camera = bpy.data.objects.new("Camera", cam_data)
    camera.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    mesh = bpy.data.meshes.new("Edge")
    mesh.from_pydata([(-50, -50, 0), (0, -50, 0), (0, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
    edge = bpy.data.objects.new("Edge", mesh)
    edge.data.materials.append(emission_material(1.0))
    scene.collection.objects.link(edge)
    for frame in (0, 2):
        edge.location.x = V * (frame - 1)
        edge.keyframe_insert("location", index=0, frame=frame)
    linear_keys(edge)
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    scene.frame_set(1)
    return scene


@pytest.mark.parametrize("position, centre", [("START", V * SHUTTER / 2), ("CENTER", 0.0),
                                               ("END", -V * SHUTTER / 2)])
def test_shutter_position_places_the_ramp(drt, tmp_path, position, centre):
    scene = sliding_edge_scene()
    scene.render.motion_blur_position = position
    channels = render_exr(scene, tmp_path / f"{position}.exr")
    profile = channels["ViewLayer.Combined.R"].mean(axis=0)
    x = -HALF + (np.arange(WIDTH) + 0.5) * 2 * HALF / WIDTH
    # coverage: the fraction of the shutter during which the edge is right of x (box-filtered)
    fine = x[None, :] + np.linspace(-0.5, 0.5, 41)[:, None] * (2 * HALF / WIDTH)
    expected = np.clip(0.5 - (fine - centre) / (V * SHUTTER), 0, 1).mean(axis=0)
    assert np.abs(profile - expected).max() < 0.05
    assert np.interp(0.5, profile[::-1], x[::-1]) == pytest.approx(centre, abs=0.5 * 2 * HALF / WIDTH)


def test_motion_blur_off_gives_a_sharp_edge(drt, tmp_path):
    scene = sliding_edge_scene()
    scene.render.use_motion_blur = False
    profile = render_exr(scene, tmp_path / "sharp.exr")["ViewLayer.Combined.R"].mean(axis=0)
    assert ((profile < 1e-6) | (profile > 1 - 1e-6)).sum() >= WIDTH - 1  # at most the edge pixel is grey
