"""Rebuild Mitsuba 3's motion-blur regression scenes (../shared/scenes/mitsuba-motion-blur,
test_{simple_motion,complex_motion,emitters}_path.xml) in Blender, for the per-pixel z-test
in tests/blender/test_mitsuba_motion.py.

Every object is built in Mitsuba's own (Y-up) coordinates and parented to one empty rotated
+90 degrees about X, which maps Mitsuba's +Y to Blender's +Z: the objects' local transforms and
animation keys are the XML's, and their world matrices are exactly the converted ones.

- Shutter [0, 1] = frames 1 to 2: frame 1, motion blur on, shutter 1 frame, position START; a
  key at Mitsuba time t is a LINEAR key at frame 1 + t. Mitsuba applies each key's
  ``scale, rotate, translate`` as T·R·S, as Blender composes location, rotation and scale;
  the rotations are about one axis, so a linear Euler angle is Mitsuba's slerp.
- Camera: Mitsuba's ``lookat`` frame has +X left and looks along +Z; a Blender camera has +X
  right and looks along -Z, so its local matrix is lookat·diag(-1, 1, -1). fov 45 on
  Mitsuba 3's default ``fov_axis`` ("x"), 48x48, box filter one pixel wide.
- Analytic shapes as fine meshes with smooth normals (the cube flat): sphere, cube
  [-1, 1]^3, open cylinder (no caps), rectangle [-1, 1]^2 facing +Z. Mitsuba's diffuse BSDF
  is one-sided (black seen from behind), Blender's two-sided; the open cylinders' insides are
  visible, so they get a black liner 0.1% inside the wall (DRT does not read the Geometry
  node's Backfacing, the Blender way to say it).
- Lights: directional irradiance E -> Sun of strength E, angle 0; point and spot intensity
  I W/sr -> power 4π·I (NOTES-bpy.md: on-axis intensity P/(4π) for both), radius 0. Mitsuba's
  spot falls off linearly in angle from ``beam_width`` (default 3/4 of ``cutoff_angle``) to
  ``cutoff_angle``; Blender's cone is a smoothstep in cosine over the outer ``spot_blend``
  fraction of (1 - cos half-angle), so the blend is set to cover the same angles.
- Black world, Diffuse BSDFs with the XML's reflectances.

Run ``.venv/bin/python sample_scenes/build_mitsuba_motion.py [OUT_DIR]`` to save the three
scenes as .blend files for inspection (default out/mitsuba_motion/); the test builds them in
memory with ``build(name)``.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # scene_helpers, also under `blender --python`
import scene_helpers as sh  # noqa: E402

import bmesh  # noqa: E402
import bpy  # noqa: E402
from mathutils import Matrix, Vector  # noqa: E402

RESOLUTION = 48
FOV = 45.0
FRAME = 1  # Mitsuba time t is frame FRAME + t
SPHERE_SEGMENTS = (192, 96)
CYLINDER_SEGMENTS = 256

RED, GREEN, BLUE = (0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8)

# Instances: (mesh, colour, keys); a key is (time, translate, rotate-about-Y degrees, scale).
SCENES = {
    "simple_motion": {
        "camera": ((0, 4, -8), (0, 1, 0), (0, 1, 0)),
        "sun": ((0, -0.1, 1), 5.0),
        "instances": (
            ("sphere", RED, ((0.0, (-2, 0.8, 0), 0, (1, 1, 1)), (1.0, (-2, 2.5, 0), 0, (1, 1, 1)))),
            ("cube", GREEN, tuple((t, (0, 0.7, 0), 10.0 * k, (0.7, 1.2, 0.7)) for k, t in enumerate(
                (0.0, 0.111111, 0.222222, 0.333333, 0.444444, 0.555556, 0.666667, 0.777778, 0.888889, 1.0)))),
            ("cylinder", BLUE, ((0.0, (2, -1, 0), 0, (1.5, 1, 1.5)), (1.0, (2, -1, 0), 0, (1.5, 3, 1.5)))),
        ),
    },
    "complex_motion": {
        "camera": ((0, 5, -8), (0, 1, 0), (0, 1, 0)),
        "sun": ((0, -0.1, 1), 5.0),
        "instances": (
            ("sphere", RED, ((0.0, (-2, 1.4, 0), 0, (1, 1, 1)), (0.5, (0, 3.5, 0), 0, (1.5, 1.5, 1.5)),
                             (1.0, (2, 1.4, 0), 0, (1, 1, 1)))),
            ("cube", GREEN, ((0.0, (2, 0.4, -2), 0, (0.7, 0.7, 0.7)), (0.5, (1, 0.3, -1), 0, (0.7, 0.7, 0.7)),
                             (1.0, (-2, -0.8, 2), 0, (0.7, 0.7, 0.7)))),
        ),
    },
    "emitters": {
        "camera": ((0, 8, -2), (0, 0, 0), (0, 0, 1)),
        "instances": (
            ("floor", (0.5, 0.5, 0.5), ((0.0, (0, 0, 0), None, (50, 50, 1)),)),
            ("tall_cylinder", (0.7, 0.7, 0.7), ((0.0, (0, 0, 0), 0, (1, 1, 1)),)),
        ),
        "point": ((30.0, 5.0, 5.0), ((0.0, (-3, 4, -2)), (1.0, (-1, 4, -2)))),
        "spot": ((5.0, 30.0, 5.0), 45.0, ((0.0, (3, 4, 2), (0, 1, 0), (0, 1, 0)),
                                          (1.0, (1, 3, 2), (0, 1, 0), (0, 1, 0)))),
    },
}


def lookat(origin, target, up) -> Matrix:
    """Mitsuba's lookat frame: columns left, up, forward (+Z towards the target), origin."""
    origin, target, up = Vector(origin), Vector(target), Vector(up)
    forward = (target - origin).normalized()
    left = up.cross(forward).normalized()
    frame = Matrix((left, forward.cross(left), forward)).transposed().to_4x4()
    frame.translation = origin
    return frame


LOOK_ALONG_MINUS_Z = Matrix.Diagonal((-1.0, 1.0, -1.0, 1.0))
"""From a Mitsuba lookat frame (+X left, looking along +Z) to a Blender camera or spot light's
(+X right, looking along -Z)."""


def sphere(name, material):
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=SPHERE_SEGMENTS[0], v_segments=SPHERE_SEGMENTS[1], radius=0.8)
    return sh.mesh_from_bmesh(name, bm, [material], smooth=True)


def cube(name, material):
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=2.0)
    return sh.mesh_from_bmesh(name, bm, [material])


def cylinder(name, material, height):
    """Open cylinder of radius 0.5 from y = 0 to y = height, normals outwards, no caps, with
    a black liner (radius 0.4995, normals inwards) standing for the wall's black back side."""
    n = CYLINDER_SEGMENTS
    angles = [2 * math.pi * k / n for k in range(n)]
    vertices, faces = [], []
    for radius, inwards in ((0.5, False), (0.4995, True)):
        base = len(vertices)
        vertices += [(radius * math.cos(a), y, radius * math.sin(a)) for y in (0.0, height) for a in angles]
        for k in range(n):
            quad = (base + k, base + n + k, base + n + (k + 1) % n, base + (k + 1) % n)
            faces.append(quad[::-1] if inwards else quad)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.materials.append(material)
    mesh.materials.append(sh.diffuse("BackSide", (0.0, 0.0, 0.0)))
    for polygon in mesh.polygons[n:]:
        polygon.material_index = 1
    mesh.shade_smooth()
    return mesh


def rectangle(name, material):
    """Mitsuba's rectangle: [-1, 1]^2 in XY, facing +Z."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    return mesh


def make_mesh(kind, material):
    if kind == "sphere":
        return sphere(kind, material)
    if kind == "cube":
        return cube(kind, material)
    if kind == "cylinder":
        return cylinder(kind, material, 1.5)
    if kind == "tall_cylinder":
        return cylinder(kind, material, 2.0)
    # floor: rectangle rotated -90 degrees about X (its normal to +Y) by the instance's key
    return rectangle(kind, material)


def linear_keys(obj) -> None:
    for fcurve in sh.fcurves(obj):
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"


def add_object(scene, parent, name, data, matrix=Matrix()):
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    obj.parent = parent
    obj.matrix_parent_inverse = Matrix()
    obj.matrix_basis = matrix
    return obj


def add_instance(scene, parent, kind, color, keys):
    obj = add_object(scene, parent, kind, make_mesh(kind, sh.diffuse(kind, color)))
    for time, translate, degrees, scale in keys:
        obj.location = translate
        obj.rotation_euler = (-math.pi / 2, 0, 0) if degrees is None else (0, math.radians(degrees), 0)
        obj.scale = scale
        if len(keys) > 1:
            for path in ("location", "rotation_euler", "scale"):
                obj.keyframe_insert(path, frame=FRAME + time)
    if len(keys) > 1:
        linear_keys(obj)
    return obj


def add_point(scene, parent, intensity, keys):
    light = bpy.data.lights.new("Point", "POINT")
    set_intensity(light, intensity)
    obj = add_object(scene, parent, "Point", light)
    for time, location in keys:
        obj.location = location
        obj.keyframe_insert("location", frame=FRAME + time)
    linear_keys(obj)


def add_spot(scene, parent, intensity, cutoff, keys):
    light = bpy.data.lights.new("Spot", "SPOT")
    set_intensity(light, intensity)
    beam = 0.75 * cutoff  # Mitsuba's default beam_width
    light.spot_size = math.radians(2 * cutoff)
    light.spot_blend = (math.cos(math.radians(beam)) - math.cos(math.radians(cutoff))) / (
        1 - math.cos(math.radians(cutoff)))
    obj = add_object(scene, parent, "Spot", light)
    obj.rotation_mode = "QUATERNION"
    for time, origin, target, up in keys:
        obj.matrix_basis = lookat(origin, target, up) @ LOOK_ALONG_MINUS_Z
        obj.keyframe_insert("location", frame=FRAME + time)
        obj.keyframe_insert("rotation_quaternion", frame=FRAME + time)
    linear_keys(obj)


def set_intensity(light, intensity) -> None:
    """Radiant intensity I (W/sr, RGB) as power 4π·max(I) and a colour of max 1; radius 0."""
    peak = max(intensity)
    light.energy = 4 * math.pi * peak
    light.color = tuple(i / peak for i in intensity)
    light.shadow_soft_size = 0.0


def add_sun(scene, parent, direction, irradiance):
    light = bpy.data.lights.new("Sun", "SUN")
    light.energy = irradiance
    light.angle = 0.0
    rotation = Vector(direction).normalized().to_track_quat("-Z", "Y").to_matrix().to_4x4()
    add_object(scene, parent, "Sun", light, rotation)


def build(name: str) -> bpy.types.Scene:
    spec = SCENES[name]
    scene = sh.new_scene((RESOLUTION, RESOLUTION))
    scene.name = name
    render = scene.render
    render.filter_size = 1.0
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    if hasattr(scene, "drt"):
        scene.drt.filter_type = "BOX"
    render.use_motion_blur = True
    render.motion_blur_shutter = 1.0
    render.motion_blur_position = "START"
    sh.set_world(scene, (0.0, 0.0, 0.0), 0.0)

    y_up = bpy.data.objects.new("MitsubaYUp", None)
    scene.collection.objects.link(y_up)
    y_up.rotation_euler = (math.pi / 2, 0.0, 0.0)

    camera = bpy.data.cameras.new("Camera")
    camera.sensor_fit = "HORIZONTAL"
    camera.angle = math.radians(FOV)
    camera.clip_start = 0.01
    scene.camera = add_object(scene, y_up, "Camera", camera, lookat(*spec["camera"]) @ LOOK_ALONG_MINUS_Z)

    for kind, color, keys in spec["instances"]:
        add_instance(scene, y_up, kind, color, keys)
    if "sun" in spec:
        add_sun(scene, y_up, *spec["sun"])
    if "point" in spec:
        add_point(scene, y_up, *spec["point"])
    if "spot" in spec:
        add_spot(scene, y_up, *spec["spot"])
    scene.frame_start = scene.frame_end = FRAME
    scene.frame_set(FRAME)
    return scene


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    out = Path(args[0]) if args else sh.REPO / "out" / "mitsuba_motion"
    for scene_name in SCENES:
        build(scene_name)
        sh.save(out / f"{scene_name}.blend")
    sh.done()
