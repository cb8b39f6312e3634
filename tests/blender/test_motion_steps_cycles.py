"""Objects' Motion Blur panel as Cycles reads it: Steps, the Motion Blur switch and Deformation.

Cycles samples each object at 2^Steps + 1 times over the shutter (3 by default) and moves it
piecewise between them (blender/object.cpp object_motion_steps). An object whose motion eases in
and out (Bezier keys) is then blurred along a polyline, not along its curve, and DRT must do the
same: an emissive half-plane sliding under an orthographic camera with eased keys, its edge's ramp
compared as the node parity compares (procedural_scenes.parity): Steps 1 0.0039 and Steps 3 0.0034
against Cycles' seeds' 0.0034. With DRT's former 5 times for every object the Steps 1 case fails
(0.0193 against a limit of 0.0071), and with 3 times but uniform shutter times 0.0078 (the flat
shutter curve's table, export.camera).
"""
from __future__ import annotations

import bpy
import numpy as np
import pytest
from conftest import emission_material

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export

SAMPLES = 256


def eased_edge_scene(steps: int = 1):
    """A glowing half-plane x < X(t) under an orthographic camera 2 m wide (64 x 32 px), keyed at
    x = -1.5 on frame 0 and +1.5 on frame 2 with Blender's default (eased) interpolation, blurred
    over one frame at frame 1 with the object's motion Steps ``steps``."""
    scene, edge = ps.glowing_half_plane(lambda: emission_material(1.0))
    for frame in (0, 2):
        edge.location.x = 1.5 * (frame - 1)
        edge.keyframe_insert("location", index=0, frame=frame)
    edge.cycles.motion_steps = steps
    cam = scene.camera
    cam.location, cam.rotation_euler = (0.0, 0.0, 5.0), (0.0, 0.0, 0.0)
    cam.data.type, cam.data.ortho_scale = "ORTHO", 2.0
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    scene.frame_set(1)
    return scene, edge


@pytest.mark.parametrize("steps", [1, 3])
def test_eased_motion_is_sampled_at_the_objects_steps_as_in_cycles(drt, tmp_path, steps):
    scene, _ = eased_edge_scene(steps)
    renders = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name=f"steps-{steps}") for engine, seed in ps.RUNS]
    combined = [r.passes["Combined"] for r in renders]
    figures = ps.parity(*combined)
    print(f"Steps {steps}: DRT {figures['worst']:.4f}, Cycles' seeds {figures['cycles_seeds']:.4f}")
    assert figures["ok"], ps.message(f"motion steps {steps}", figures)


def test_steps_switch_and_deformation_reach_the_export(drt):
    scene, edge = eased_edge_scene(3)
    moving = render_export(scene, motion=True).instances[0].matrices
    assert len(moving) == 9 and np.ptp(moving[:, 0, 3]) > 1.0  # 2^3 + 1 times, the edge moves
    edge.cycles.use_motion_blur = False
    assert len(render_export(scene, motion=True).instances[0].matrices) == 1  # still: its motion blur is off


def _deforming_edge(steps: int = 1):
    """The eased edge's scene with the half-plane still and its vertices keyed to slide instead."""
    scene, edge = eased_edge_scene(steps)
    edge.animation_data_clear()
    edge.shape_key_add(name="Basis")
    moved = edge.shape_key_add(name="moved")
    for point in moved.data:
        point.co.x += 1.0
    for frame, value in ((0, 0.0), (2, 1.0)):
        moved.value = value
        moved.keyframe_insert("value", frame=frame)
    scene.frame_set(1)
    return scene, edge


def test_deformation_switch_keeps_vertices_still(drt):
    scene, edge = _deforming_edge()
    key = edge.data.shape_keys
    assert render_export(scene, motion=True).meshes[0].motion_vertices is not None and key is not None
    edge.cycles.use_deform_motion = False
    assert render_export(scene, motion=True).meshes[0].motion_vertices is None


def test_instances_of_a_deforming_mesh_deform_with_it(drt):
    """The deforming half-plane and two collection instances of it share one mesh: its vertices'
    motion is read once for all of them, over the shutter and for the Vector pass (Cycles syncs a
    shared geometry's motion once; DRT read it only for a mesh one object used)."""
    scene, edge = _deforming_edge()
    source = bpy.data.collections.new("Source")
    source.objects.link(edge)
    for i in range(2):
        instancer = bpy.data.objects.new(f"Instancer{i}", None)
        instancer.instance_type, instancer.instance_collection = "COLLECTION", source
        instancer.location.y = 3.0 * (i + 1)
        scene.collection.objects.link(instancer)
    data = render_export(scene, motion=True)
    assert len(data.meshes) == 1 and len(data.instances) == 3
    assert data.meshes[0].motion_vertices is not None and np.ptp(data.meshes[0].motion_vertices[:, :, 0]) > 0.5
    scene.render.use_motion_blur = False
    scene.view_layers[0].use_pass_vector = True
    assert render_export(scene, motion=True).meshes[0].motion_pass_vertices is not None
