"""The Vector pass against Cycles: a camera moving sideways and rising over a floor, a cube moving and
turning, both faster between frames 2 and 3 than between 1 and 2 (so the previous-frame and
next-frame halves of the pass differ and a swap shows), rendered at frame 2.

The pass is a mean of nearly equal vectors over a pixel's hits, nearly noise-free: Cycles' own
seed-to-seed difference comes from the pixels on the cube's outline, where hits of the cube and of
the floor mix in different proportions, and from the vector's change across a pixel's filter
(a few thousandths of a pixel). DRT follows the node parity's rule (procedural_scenes.parity: worst
4x4-block difference at most 1.5x Cycles' seed-to-seed worst plus 0.002, in pixels) and the same
rule per pixel on the median and the 90th percentile of the pixels' differences. A pass of zeros,
one with its halves swapped and one of the wrong sign each fail both by far.

From Blender 5.2 (DRT: VECTOR_BACKGROUND_FROM) Cycles' camera rays that reach the background write
the camera's turning with weight 1, so an outline pixel's vector is a mean over all its samples, the
background's included; before, over its surface hits only. Every comparison here runs under both.
A turning camera (``turning_scene``) is the case where the background's vectors are not 0."""
from __future__ import annotations

import math

import bpy
import numpy as np
import pytest

from drt_engine.blender.export import export_scene
from drt_engine.blender.properties import VECTOR_BACKGROUND_FROM
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material
from tests.support.export_helpers import render_export

WIDTH, HEIGHT = 48, 32
SAMPLES = 16


def vector_scene(motion_blur=False):
    scene = ps._scene(WIDTH, HEIGHT)
    scene.render.use_motion_blur = motion_blur
    camera = scene.camera
    ps.aim(camera, (0.0, -9.0, 3.0))
    for frame, (x, z) in ((1, (-0.3, 2.9)), (2, (0.0, 3.0)), (3, (0.5, 3.3))):
        camera.location.x, camera.location.z = x, z
        camera.keyframe_insert("location", frame=frame)
    floor_mat, cube_mat = new_material("Floor"), new_material("Cube")
    bpy.ops.mesh.primitive_plane_add(size=40.0)
    bpy.context.active_object.data.materials.append(floor_mat)
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
    cube = bpy.context.active_object
    cube.data.materials.append(cube_mat)
    for frame, (x, turn) in ((1, (-0.3, 0.0)), (2, (0.0, 10.0)), (3, (0.8, 35.0))):
        cube.location.x, cube.rotation_euler.z = x, math.radians(turn)
        cube.keyframe_insert("location", frame=frame)
        cube.keyframe_insert("rotation_euler", frame=frame)
    for fcurve in _fcurves(camera) + _fcurves(cube):
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(sun)
    scene.frame_set(2)
    return scene


def turning_scene(lens="PERSP"):
    """A camera, its lens shifted, panning and tilting over a cube with most of the view on the
    background, faster between frames 2 and 3: the background's vectors are the camera's turning
    alone (written from Blender 5.2 on, VECTOR_BACKGROUND_FROM). ``lens`` "EQUIRECTANGULAR": a
    panoramic camera over half the turn (no seam, where a pixel's samples wrap round the image)."""
    scene = ps._scene(WIDTH, HEIGHT)
    camera = scene.camera
    ps.aim(camera, (0.0, -9.0, 1.0))
    camera.data.shift_x, camera.data.shift_y = 0.2, -0.1
    if lens != "PERSP":
        camera.data.type, camera.data.panorama_type = "PANO", lens
        camera.data.longitude_min, camera.data.longitude_max = -math.pi / 2, math.pi / 2
    base = camera.rotation_euler.copy()
    for frame, (pan, tilt) in ((1, (-4.0, -1.0)), (2, (0.0, 0.0)), (3, (7.0, 3.0))):
        camera.rotation_euler = (base.x + math.radians(tilt), base.y, base.z + math.radians(pan))
        camera.keyframe_insert("rotation_euler", frame=frame)
    for fcurve in _fcurves(camera):
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
    bpy.context.active_object.data.materials.append(new_material("Cube"))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    scene.frame_set(2)
    return scene


def _fcurves(obj):
    action = obj.animation_data.action
    if hasattr(action, "fcurves"):
        return list(action.fcurves)
    return [fc for layer in action.layers for strip in layer.strips for bag in strip.channelbags
            for fc in bag.fcurves]  # Blender 5's layered actions


@pytest.fixture(scope="module")
def renders(drt, tmp_path_factory):
    """DRT seed 0, Cycles seeds 0 and 1: their Vector passes."""
    scene = vector_scene()
    out = tmp_path_factory.mktemp("vector")
    return [rh.render(scene, engine, SAMPLES, seed, out, passes=("Vector",), name="vector").passes["Vector"]
            for engine, seed in ps.RUNS]


QUANTILES = (0.5, 0.9)


def per_pixel(drt, c0, c1) -> dict:
    """The median and 90th percentile over pixels of the largest channel difference, DRT from Cycles
    seed 0 and Cycles' seeds 0 and 1, and whether DRT's are within 1.5x Cycles' own plus 0.002 px."""
    ours = np.quantile(np.abs(drt - c0).max(axis=-1), QUANTILES)
    own = np.quantile(np.abs(c0 - c1).max(axis=-1), QUANTILES)
    return {"ours": ours.tolist(), "cycles_seeds": own.tolist(), "ok": bool(np.all(ours <= 1.5 * own + 0.002))}


def test_vector_matches_cycles(renders):
    drt, c0, c1 = renders
    figures, pixels = ps.parity(drt, c0, c1), per_pixel(drt, c0, c1)
    print(f"Vector: blocks {figures}; per pixel {pixels}")
    assert figures["ok"], ps.message("Vector", figures)
    assert pixels["ok"], pixels
    # the scene is one the checks below can fail on: nearly everything moves, and the halves differ
    moving = float(np.mean(np.abs(c0).max(axis=-1) > 0.3))
    halves = float(np.abs(c0[..., [0, 1]] - c0[..., [2, 3]]).max())
    print(f"moving pixels {moving:.3f}, largest difference of the halves {halves:.2f} px")
    assert moving > 0.8 and halves > 1.0


@pytest.mark.parametrize("wrong", ["zero", "swapped", "negated"])
def test_a_wrong_pass_fails(renders, wrong):
    drt, c0, c1 = renders
    bad = {"zero": np.zeros_like(drt), "swapped": drt[..., [2, 3, 0, 1]], "negated": -drt}[wrong]
    figures, pixels = ps.parity(bad, c0, c1), per_pixel(bad, c0, c1)
    print(f"Vector {wrong}: blocks {figures}; per pixel {pixels}")
    assert not figures["ok"] and figures["worst"] > 5 * figures["limit"] and not pixels["ok"]


def _export(scene):
    return export_scene(bpy.context.evaluated_depsgraph_get(), frame_set=lambda f, s: scene.frame_set(f, subframe=s))


def test_export_reads_the_neighbouring_frames_only_for_the_pass(drt):
    """The camera's and the cube's transforms at frames 1 and 3 with the pass on (the floor stands
    still: none), nothing with it off or under motion blur (Cycles' pass is 0 then: see below)."""
    scene = vector_scene()
    view_layer = scene.view_layers[0]
    view_layer.use_pass_vector = True
    data = _export(scene)
    assert scene.frame_current == 2
    moving = sorted(inst.name for inst in data.instances if inst.motion_pass is not None)
    assert data.camera.motion_pass is not None and len(moving) == 1 and "Cube" in moving[0], moving
    cube = next(inst for inst in data.instances if inst.motion_pass is not None)
    assert np.allclose(cube.motion_pass[:, 0, 3], [-0.3, 0.8]) and np.allclose(data.camera.motion_pass[:, 0, 3],
                                                                                 [-0.3, 0.5])
    for off in ("pass", "blur"):
        view_layer.use_pass_vector = off != "pass"
        scene.render.use_motion_blur = off == "blur"
        data = _export(scene)
        assert data.camera.motion_pass is None and all(inst.motion_pass is None for inst in data.instances), off


def test_cycles_pass_is_zero_under_motion_blur(drt, tmp_path):
    """What DRT matches by exporting no motion for the pass under motion blur."""
    vector = rh.render(vector_scene(motion_blur=True), "CYCLES", 4, 0, tmp_path, passes=("Vector",),
                       name="blur").passes["Vector"]
    assert np.all(vector == 0.0)


def deforming_scene():
    """A still camera over a grid whose shape key shears and bends it, its value 0, 0.3 and 1 at
    frames 1 to 3: only the vertices move (the pass would be 0 without them)."""
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, (0.0, -6.0, 4.0))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=12, size=5.0)
    grid = bpy.context.active_object
    grid.data.materials.append(new_material("Grid"))
    grid.shape_key_add(name="Basis")
    key = grid.shape_key_add(name="Shear")
    for point in key.data:
        x, y, _ = point.co
        point.co = (x + 0.4 * y, y, 0.3 * x * x)
    for frame, value in ((1, 0.0), (2, 0.3), (3, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    scene.frame_set(2)
    return scene


def test_deforming_mesh_matches_cycles(drt, tmp_path):
    scene = deforming_scene()
    scene.view_layers[0].use_pass_vector = True
    data = _export(scene)
    assert sum(mesh.motion_pass_vertices is not None for mesh in data.meshes) == 1
    assert all(inst.motion_pass is None for inst in data.instances) and data.camera.motion_pass is None
    drt_v, c0, c1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, passes=("Vector",), name="deform")
                     .passes["Vector"] for engine, seed in ps.RUNS]
    figures, pixels = ps.parity(drt_v, c0, c1), per_pixel(drt_v, c0, c1)
    still = ps.parity(np.zeros_like(drt_v), c0, c1)
    print(f"Vector deforming: blocks {figures}; per pixel {pixels}; without the vertices' motion {still}")
    assert figures["ok"], ps.message("Vector deforming", figures)
    assert pixels["ok"], pixels
    assert not still["ok"] and still["worst"] > 5 * still["limit"]


@pytest.mark.parametrize("lens", ["PERSP", "EQUIRECTANGULAR"])
def test_background_vector_matches_cycles(drt, tmp_path, lens):
    """Through a turning camera (``turning_scene``): from VECTOR_BACKGROUND_FROM on the background's
    samples carry the camera's turning and the cube's outline mixes both; before, they carry none."""
    scene = turning_scene(lens)
    drt_v, c0, c1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, passes=("Vector",), name="turning")
                     .passes["Vector"] for engine, seed in ps.RUNS]
    figures, pixels = ps.parity(drt_v, c0, c1), per_pixel(drt_v, c0, c1)
    moving = float(np.mean(np.abs(c0).max(axis=-1) > 0.5))
    print(f"Vector turning camera ({lens}): blocks {figures}; per pixel {pixels}; moving pixels {moving:.3f}")
    assert figures["ok"], ps.message(f"Vector turning camera ({lens})", figures)
    assert pixels["ok"], pixels
    assert (moving > 0.9) == (bpy.app.version >= VECTOR_BACKGROUND_FROM), moving


def test_no_warning_names_the_vector_pass(drt):
    """DRT writes the pass as this Blender's Cycles does (4.2 to 5.0, and 5.2's background vectors
    from VECTOR_BACKGROUND_FROM on): no gap for the render's warning to name."""
    scene = vector_scene()
    scene.view_layers[0].use_pass_vector = True
    assert not any("Vector" in w for w in render_export(scene).warnings)
