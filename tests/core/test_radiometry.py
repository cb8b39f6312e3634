"""Analytic radiometry: a Lambertian plane under each light type, within 1%."""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import lit_plane_scene, plane, top_camera, translation, uv_sphere

ALBEDO = 0.5
D = 2.0


def render_mean(scene, samples=64, **kw):
    result = Renderer(scene, RenderSettings(samples=samples, threads=1, **kw)).render()
    return result.passes["Combined"][..., :3].mean()


def rect_irradiance(radiance, a, b, d):
    """Irradiance on axis under a uniform rectangle 2a x 2b at height d (sum of four corner patches)."""
    A, B = a / d, b / d
    f = (A / np.sqrt(1 + A * A) * np.arctan(B / np.sqrt(1 + A * A))
         + B / np.sqrt(1 + B * B) * np.arctan(A / np.sqrt(1 + B * B))) / (2 * np.pi)
    return radiance * np.pi * 4 * f


CASES = {
    # name: (light, expected radiance of the plane)
    "point": (Light("POINT", translation(0, 0, D), intensity=np.full(3, 100 / (4 * np.pi))),
              ALBEDO * 100 / (4 * np.pi**2 * D * D)),
    "sun": (Light("SUN", np.eye(4), irradiance=np.full(3, 3.0)), ALBEDO * 3.0 / np.pi),
    "sun with angle": (Light("SUN", np.eye(4), irradiance=np.full(3, 3.0), angle=0.3), ALBEDO * 3.0 / np.pi),
    "disk area": (Light("AREA", translation(0, 0, D), radiance=np.full(3, 5.0), shape="DISK", size_x=1.0),
                  ALBEDO * 5.0 * 0.25 / (D * D + 0.25)),
    "square area": (Light("AREA", translation(0, 0, D), radiance=np.full(3, 5.0), shape="SQUARE", size_x=1.0),
                    ALBEDO * rect_irradiance(5.0, 0.5, 0.5, D) / np.pi),
    "rectangle area": (Light("AREA", translation(0, 0, D), radiance=np.full(3, 5.0), shape="RECTANGLE",
                             size_x=2.0, size_y=0.5), ALBEDO * rect_irradiance(5.0, 1.0, 0.25, D) / np.pi),
    "soft point radius": (Light("POINT", translation(0, 0, D), intensity=np.full(3, 8.0), radius=1.0),
                          ALBEDO * 8.0 / (D * D + 1.0) / np.pi),
    "sphere point radius": (Light("POINT", translation(0, 0, D), intensity=np.full(3, 8.0), radius=1.0,
                                  soft_falloff=False), ALBEDO * 8.0 / (D * D) / np.pi),
    "spot on axis": (Light("SPOT", translation(0, 0, D), intensity=np.full(3, 8.0), spot_size=0.5),
                     ALBEDO * 8.0 / (D * D) / np.pi),
}


@pytest.mark.parametrize("name", list(CASES))
def test_lambertian_plane_under_light(name):
    light, expected = CASES[name]
    value = render_mean(lit_plane_scene(light, albedo=ALBEDO), samples=256)
    assert value == pytest.approx(expected, rel=0.01)


def test_area_light_is_one_sided():
    light = Light("AREA", translation(0, 0, D) @ np.diag([1, -1, -1, 1]), radiance=np.full(3, 5.0), size_x=1.0)
    assert render_mean(lit_plane_scene(light), samples=16) == 0.0


def test_spot_outside_cone_is_dark():
    tilted = translation(0, 0, D) @ np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1.0]])
    light = Light("SPOT", tilted, intensity=np.full(3, 8.0), spot_size=0.5)
    assert render_mean(lit_plane_scene(light), samples=16) == 0.0


def test_emitter_seen_directly_has_its_strength():
    strength = 3.7
    mat = Material("glow", [Closure("EMISSION", emission=(strength,) * 3)])
    scene = SceneData(top_camera(), [plane()], [Instance(0, np.eye(4))], [mat])
    assert render_mean(scene, samples=4) == pytest.approx(strength, rel=1e-6)


def test_emissive_mesh_lights_a_plane_like_an_area_light():
    """A 1x1 emissive quad 2 m above a plane gives the same irradiance as a square area light."""
    emit = Material("glow", [Closure("EMISSION", emission=(5.0,) * 3)])
    white = Material("white", [Closure("DIFFUSE", color=(ALBEDO,) * 3)])
    quad = plane(1.0, z=D, material=1)
    scene = SceneData(top_camera(), [plane(), quad], [Instance(0, np.eye(4)), Instance(1, np.eye(4))], [white, emit])
    expected = ALBEDO * rect_irradiance(5.0, 0.5, 0.5, D) / np.pi
    assert render_mean(scene, samples=256) == pytest.approx(expected, rel=0.01)


def test_white_furnace_diffuse_sphere_under_uniform_world():
    """A convex albedo-1 Lambertian sphere under a uniform world of radiance L shows L."""
    mat = Material("white", [Closure("DIFFUSE", color=(1, 1, 1))])
    cam = Camera(translation(0, 0, 5)[None], (-0.15, 0.15, -0.15, 0.15), (16, 16))
    scene = SceneData(cam, [uv_sphere(1.0)], [Instance(0, np.eye(4))], [mat], world=World(np.full(3, 0.7)))
    result = Renderer(scene, RenderSettings(samples=64, threads=1)).render()
    img = result.passes["Combined"][..., :3]
    assert np.abs(img.mean() - 0.7) < 0.007
    assert np.abs(img - 0.7).max() < 0.1


@pytest.mark.parametrize("spread_deg, view_deg", [(90, 0), (90, 30), (30, 10), (30, 20)])
def test_area_light_spread_narrows_emission_like_cycles(spread_deg, view_deg):
    """Seen in a mirror at angle a from its normal, a light of spread s has radiance
    L * max((tan(s/2) - tan a) / (tan(s/2) - s/2), 0) (Cycles' area.h, measured in Cycles)."""
    from tests.support.scenes import look_at
    from test_mis import glossy_plane_scene
    h, a = np.radians(spread_deg) / 2, np.radians(view_deg)
    eye = np.array([np.sin(a), 0.0, np.cos(a)]) * 2.0
    # a horizontal light shining down, where the mirrored view ray meets it at angle a
    light = Light("AREA", translation(-eye[0], 0.0, eye[2]), radiance=np.full(3, 5.0), size_x=0.5, size_y=0.5,
                  spread=2 * h)
    scene = glossy_plane_scene(0.0, [light])
    scene.camera = Camera(look_at(eye, (0, 0, 0), up=(0, 1, 0))[None], (-1e-4, 1e-4, -1e-4, 1e-4), (4, 4))
    value = Renderer(scene, RenderSettings(samples=1, threads=1)).render().passes["Combined"][..., 0].mean()
    expected = 5.0 * max((np.tan(h) - np.tan(a)) / (np.tan(h) - h), 0.0)
    assert value == pytest.approx(expected, rel=1e-3)
