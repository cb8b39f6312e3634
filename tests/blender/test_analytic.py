"""Analytic radiometry through the whole Blender path: a scene built with bpy, exported, traced
by DRT inside ``bpy.ops.render.render`` and read back from the written EXR.

Each scene is a large Lambertian plane (albedo 0.5) seen straight down by an orthographic
camera through a 5 cm window at the origin, so every pixel sees (nearly) the same point and
its radiance is known in closed form from Blender's light units as Cycles converts them:

- point light of power P at height d, radius 0:  L = albedo·P / (4π² d²)
- point light with radius r (soft falloff):       L = albedo·P / (4π² (d² + r²))
- spot light on its axis:                         as a point light of the same power
- sun of strength S at elevation θ:               L = albedo·S·sin θ / π
- disk area light of power P, radius R, on axis:  L = albedo·(P / (π·A))·R² / (d² + R²), A = πR²
- rectangle a×b (half sizes) on axis, Le = P/(π·4ab):
  L = albedo/π · 2·Le·[a/√(a²+d²)·atan(b/√(a²+d²)) + b/√(b²+d²)·atan(a/√(b²+d²))]
- emitter of strength S and colour c seen:        L = S·c

A mistake in a unit conversion of the export, in the tracer's light sampling or in the film
shows up as a relative error of more than 1%.
"""
import math

import bpy
import numpy as np
import pytest

from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world

ALBEDO = 0.5
HEIGHT = 2.0  # light above the plane
TOLERANCE = 0.01
SIZE = 8  # pixels per side
WINDOW = 0.05  # metres seen by the orthographic camera


def lambert_scene(material: str) -> bpy.types.Scene:
    """Factory-empty scene: a 40 m plane of albedo 0.5 at z=0, black world, camera looking down."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rh.set_resolution(scene, SIZE, SIZE)
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    camera = bpy.data.cameras.new("Camera")
    camera.type = "ORTHO"
    camera.ortho_scale = WINDOW
    camera_object = bpy.data.objects.new("Camera", camera)
    camera_object.location = (0.0, 0.0, 1.0)  # below the lights: cameras are not geometry
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object

    if material == "DIFFUSE":
        shading = shader_material("Plane", "ShaderNodeBsdfDiffuse", {"Color": (ALBEDO,) * 3 + (1.0,)})
    else:
        shading = shader_material("Plane", "ShaderNodeBsdfPrincipled",
                                  {"Base Color": (ALBEDO,) * 3 + (1.0,), "Specular IOR Level": 0.0,
                                   "Roughness": 0.5})
    add_plane(scene, "Plane", 40.0, shading)
    return scene


def shader_material(name: str, node_type: str, inputs: dict) -> bpy.types.Material:
    material = new_material(name)
    tree = material.node_tree
    tree.nodes.clear()
    shader = tree.nodes.new(node_type)
    for socket, value in inputs.items():
        shader.inputs[socket].default_value = value
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(shader.outputs[0], output.inputs["Surface"])
    return material


def add_plane(scene, name: str, size: float, material, location=(0.0, 0.0, 0.0)):
    h = size / 2
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def add_light(scene, kind: str, rotation=(0.0, 0.0, 0.0), **props):
    light = bpy.data.lights.new("Light", kind)
    for key, value in props.items():
        setattr(light, key, value)
    obj = bpy.data.objects.new("Light", light)
    obj.location = (0.0, 0.0, HEIGHT)
    obj.rotation_euler = rotation  # unrotated, spot, sun and area lights shine down (-Z)
    scene.collection.objects.link(obj)
    return obj


def render_mean(scene, samples: int, tmp_path) -> np.ndarray:
    """DRT's mean RGB over the image, after checking the image is finite and uniform."""
    image = rh.render(scene, "DRT", samples, 0, tmp_path).rgb
    assert np.isfinite(image).all()
    mean = image.reshape(-1, 3).mean(axis=0)
    spread = np.abs(image - mean).max() / max(mean.max(), 1e-12)
    assert spread < 0.05, f"the {WINDOW} m patch should look uniform; pixels differ by {spread:.1%}"
    return mean


def assert_radiance(measured, expected):
    expected = np.broadcast_to(np.asarray(expected, float), (3,))
    error = np.abs(measured / expected - 1.0).max()
    assert error < TOLERANCE, f"DRT radiance {measured} vs analytic {expected}: {error:.2%} off"


MATERIALS = ("DIFFUSE", "PRINCIPLED")


@pytest.mark.parametrize("material", MATERIALS)
def test_point_light(drt, tmp_path, material):
    scene = lambert_scene(material)
    power = 1000.0
    add_light(scene, "POINT", energy=power, shadow_soft_size=0.0)
    expected = ALBEDO * power / (4 * math.pi**2 * HEIGHT**2)
    assert_radiance(render_mean(scene, 16, tmp_path), expected)


def test_point_light_with_radius(drt, tmp_path):
    scene = lambert_scene("DIFFUSE")
    power, radius = 1000.0, 0.5
    add_light(scene, "POINT", energy=power, shadow_soft_size=radius)
    assert bpy.data.lights["Light"].use_soft_falloff
    expected = ALBEDO * power / (4 * math.pi**2 * (HEIGHT**2 + radius**2))
    assert_radiance(render_mean(scene, 256, tmp_path), expected)


def test_spot_light_on_axis(drt, tmp_path):
    scene = lambert_scene("DIFFUSE")
    power = 1000.0
    add_light(scene, "SPOT", energy=power, shadow_soft_size=0.0, spot_size=math.radians(60.0), spot_blend=0.5)
    expected = ALBEDO * power / (4 * math.pi**2 * HEIGHT**2)
    assert_radiance(render_mean(scene, 16, tmp_path), expected)


@pytest.mark.parametrize("material", MATERIALS)
@pytest.mark.parametrize("elevation", (90.0, 30.0))
def test_sun(drt, tmp_path, material, elevation):
    scene = lambert_scene(material)
    strength = 3.0
    add_light(scene, "SUN", rotation=(math.radians(90.0 - elevation), 0.0, 0.0), energy=strength,
              angle=math.radians(1.0))
    expected = ALBEDO * strength * math.sin(math.radians(elevation)) / math.pi
    assert_radiance(render_mean(scene, 64, tmp_path), expected)


@pytest.mark.parametrize("material", MATERIALS)
def test_disk_area_light_on_axis(drt, tmp_path, material):
    scene = lambert_scene(material)
    power, diameter = 500.0, 1.5
    add_light(scene, "AREA", energy=power, shape="DISK", size=diameter)
    radius = diameter / 2
    area = math.pi * radius**2
    expected = ALBEDO * power / (math.pi * area) * radius**2 / (HEIGHT**2 + radius**2)
    assert_radiance(render_mean(scene, 1024, tmp_path), expected)


def test_rectangle_area_light_on_axis(drt, tmp_path):
    scene = lambert_scene("DIFFUSE")
    power, size_x, size_y = 500.0, 2.0, 0.8
    add_light(scene, "AREA", energy=power, shape="RECTANGLE", size=size_x, size_y=size_y)
    a, b = size_x / 2, size_y / 2
    radiance = power / (math.pi * size_x * size_y)
    ra, rb = math.hypot(a, HEIGHT), math.hypot(b, HEIGHT)
    irradiance = 2 * radiance * (a / ra * math.atan(b / ra) + b / rb * math.atan(a / rb))
    assert_radiance(render_mean(scene, 1024, tmp_path), ALBEDO * irradiance / math.pi)


def test_emitter_seen_directly(drt, tmp_path):
    scene = lambert_scene("DIFFUSE")
    strength, color = 2.5, (1.0, 0.5, 0.25)
    emitter = shader_material("Emitter", "ShaderNodeEmission", {"Color": color + (1.0,), "Strength": strength})
    add_plane(scene, "Emitter", 1.0, emitter, location=(0.0, 0.0, 0.5))
    assert_radiance(render_mean(scene, 16, tmp_path), strength * np.array(color))
