"""Lights at their limits, through Blender: zero and tiny sizes, huge powers, invalid powers,
spot and sun angles at their ends, a light shut inside a closed mesh.

Scene: a diffuse plane (albedo 0.8) at z = 0, the camera 5 m above looking down, black world.
"""
import math

import numpy as np
import pytest

from tests.support import blender_scenes as bs
from tests.support import render_helpers as rh

ALBEDO = 0.8


@pytest.fixture
def floor(drt):
    scene = bs.new_scene(width=8, height=8, samples=4)
    scene.camera.location = (0, 0, 5)
    scene.render.filter_size = 0.0  # every sample at its pixel's centre: images exact, comparable pixel by pixel
    bs.add_plane(scene, half=20, mat=bs.material("DIFFUSE", color=(ALBEDO,) * 3))
    return scene


def test_area_light_of_size_zero_contributes_nothing_like_cycles(floor, tmp_path):
    bs.add_light(floor, "AREA", (0, 0, 2), energy=100.0, size=0.0)
    drt = bs.render(floor, tmp_path, "drt")
    cycles = rh.render(floor, "CYCLES", 1, 0, tmp_path, name="cycles")
    assert drt["Combined"][..., :3].max() == 0.0
    assert cycles.rgb.max() == 0.0


def test_tiny_area_light_is_a_lambertian_point_source(floor, tmp_path):
    """Size 1e-6 m, 100 W: intensity P/π·cosθ, so the floor shows 4·cosθ times a 100 W point light."""
    area = bs.add_light(floor, "AREA", (0, 0, 2), energy=100.0, size=1e-6)
    tiny = bs.render(floor, tmp_path, "area")
    area.hide_render = True
    bs.add_light(floor, "POINT", (0, 0, 2), energy=100.0, shadow_soft_size=0.0)
    point = bs.render(floor, tmp_path, "point")
    p = tiny["Position"]
    cos_l = 2.0 / np.linalg.norm(p - [0, 0, 2], axis=2)
    ratio = tiny["Combined"][..., 0] / point["Combined"][..., 0]
    np.testing.assert_allclose(ratio, 4 * cos_l, rtol=2e-3)
    expected_centre = ALBEDO / math.pi * (100 / math.pi) * cos_l ** 4 / 4.0
    np.testing.assert_allclose(tiny["Combined"][..., 0], expected_centre, rtol=2e-3)


@pytest.mark.parametrize("clamp", [0.0, 10.0])
def test_gigawatt_from_a_tiny_light_is_finite_and_bounded_by_clamp(floor, tmp_path, clamp):
    """1e9 W from a point light of radius 1e-6 m, 1 mm above a glossy sphere and 1 cm above the floor."""
    bs.add_light(floor, "POINT", (0.3, 0, 0.01), energy=1e9, shadow_soft_size=1e-6)
    sphere = bpy_sphere(floor, (0, 0, 0.3), 0.2, bs.material("GLOSSY", Roughness=0.2))
    floor.drt.sample_clamp_direct = floor.drt.sample_clamp_indirect = clamp
    floor.drt.samples = 8
    image = bs.render(floor, tmp_path, f"gw{clamp}")["Combined"][..., :3]
    assert image.max() > 0
    if clamp:
        assert image.max() <= clamp * (1 + 1e-6)
    del sphere


def bpy_sphere(scene, location, radius, mat):
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location, segments=24, ring_count=12)
    obj = bpy.context.active_object
    obj.data.materials.append(mat)
    obj.data.shade_smooth()
    return obj


@pytest.mark.parametrize("power", [-10.0, float("nan")])
@pytest.mark.parametrize("kind", ["POINT", "SPOT", "AREA", "SUN"])
def test_negative_or_nan_power_is_rejected_with_a_message(floor, kind, power, capfd):
    bs.add_light(floor, kind, (0, 0, 2), energy=power, name="BadLamp")
    message = bs.render_error(floor)
    unit = "W/m²" if kind == "SUN" else "W"
    assert "BadLamp" in message and f"{power:g} {unit}" in message, message  # in the units the user typed
    captured = capfd.readouterr()
    assert "Traceback" not in captured.out + captured.err


@pytest.mark.parametrize("size_deg, inside_only", [(180.0, False), (45.0, True)])
def test_spot_with_blend_zero_is_a_point_light_cut_sharply(floor, tmp_path, size_deg, inside_only):
    spot = bs.add_light(floor, "SPOT", (0, 0, 2), energy=100.0, spot_size=math.radians(size_deg), spot_blend=0.0,
                        shadow_soft_size=0.0)
    floor.render.resolution_x = floor.render.resolution_y = 16
    cone = bs.render(floor, tmp_path, "spot")
    spot.hide_render = True
    bs.add_light(floor, "POINT", (0, 0, 2), energy=100.0, shadow_soft_size=0.0)
    point = bs.render(floor, tmp_path, "point")
    p = cone["Position"]
    axis_angle = np.degrees(np.arccos(2.0 / np.linalg.norm(p - [0, 0, 2], axis=2)))
    inside = axis_angle < size_deg / 2 - 1.0
    outside = axis_angle > size_deg / 2 + 1.0
    np.testing.assert_allclose(cone["Combined"][inside][:, 0], point["Combined"][inside][:, 0], rtol=1e-5)
    assert np.all(cone["Combined"][outside][:, :3] == 0.0)
    assert inside.sum() > 4 and (outside.sum() > 4) == inside_only


@pytest.mark.parametrize("angle_deg", [0.0, 179.0])
def test_sun_of_angle_zero_and_almost_a_hemisphere_gives_its_irradiance(floor, tmp_path, angle_deg):
    """Strength 3 W/m² is the irradiance on a facing surface, however big the sun's disk."""
    bs.add_light(floor, "SUN", (0, 0, 10), energy=3.0, angle=math.radians(angle_deg))
    floor.drt.samples = 64
    image = bs.render(floor, tmp_path, "sun")["Combined"][..., 0]
    np.testing.assert_allclose(image.mean(), ALBEDO * 3.0 / math.pi, rtol=0.02 if angle_deg else 1e-5)


def test_light_inside_a_closed_mesh_lights_nothing_outside(floor, tmp_path):
    bs.cube(floor, half=0.5, location=(0, 0, 1), mat=bs.material("DIFFUSE"))
    bs.add_light(floor, "POINT", (0, 0, 1), energy=1000.0, shadow_soft_size=0.1)
    bs.add_light(floor, "AREA", (0.1, 0, 1.2), energy=1000.0, size=0.2)
    floor.render.resolution_x = floor.render.resolution_y = 16
    image = bs.render(floor, tmp_path, "boxed")["Combined"][..., :3]
    assert image.max() == 0.0
