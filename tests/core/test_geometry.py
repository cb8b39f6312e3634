"""Geometry facts: mirrored instances, no self-intersection, far from the origin, cancel."""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import lit_plane_scene, look_at, plane, top_camera, translation, uv_sphere


def test_mirrored_instance_shades_like_its_twin():
    """A sphere scaled by -1 in x is the same sphere: same image."""
    cam = Camera(translation(0, 0, 5)[None], (-0.25, 0.25, -0.25, 0.25), (16, 16))
    mat = [Material("white", [Closure("PRINCIPLED", color=(0.8, 0.8, 0.8), roughness=0.4)])]
    light = [Light("SUN", look_at((1, 1, 2), (0, 0, 0)), irradiance=np.full(3, 2.0))]
    images = []
    for m in (np.eye(4), np.diag([-1.0, 1, 1, 1])):
        sc = SceneData(cam, [uv_sphere(1.0)], [Instance(0, m)], mat, light)
        images.append(Renderer(sc, RenderSettings(samples=4, threads=1)).render().passes["Combined"])
    assert np.abs(images[0] - images[1]).max() < 1e-3


@pytest.mark.parametrize("offset", [0.0, 1e3, 1e5])
def test_lit_plane_has_no_acne_anywhere(offset):
    """Every light sample of a plane facing a sun is unoccluded, also far from the origin."""
    light = Light("SUN", look_at((0.3, 0.2, 1), (0, 0, 0)), irradiance=np.full(3, 1.0))
    cam = Camera(translation(offset, offset, 1.0 + offset * 0)[None], (-2, 2, -2, 2), (16, 16))
    sc = lit_plane_scene(light, camera=cam)
    sc.instances = [Instance(0, translation(offset, offset, 0) @ np.diag([1e3, 1e3, 1, 1]))]
    img = Renderer(sc, RenderSettings(samples=4, threads=1)).render().passes["Combined"][..., 0]
    expected = 0.5 * 1.0 * (1 / np.linalg.norm([0.3, 0.2, 1])) / np.pi
    assert np.allclose(img, expected, rtol=1e-4)


def test_parallel_planes_do_not_leak_light():
    """A plane 1e-3 below an opaque one, lit from above, stays dark."""
    light = Light("SUN", np.eye(4), irradiance=np.full(3, 1.0))
    sc = lit_plane_scene(light, camera=top_camera(height=-1.0))
    sc.camera.matrices[0] = translation(0, 0, -1.0) @ np.diag([1.0, -1, -1, 1])  # looking up
    sc.meshes.append(plane(z=1e-3))
    sc.instances.append(Instance(1, np.eye(4)))
    img = Renderer(sc, RenderSettings(samples=4, threads=1)).render().passes["Combined"]
    assert img[..., :3].max() == 0.0


def test_cancel_returns_the_image_so_far():
    light = Light("SUN", np.eye(4), irradiance=np.full(3, 1.0))
    sc = lit_plane_scene(light, camera=top_camera(res=300))
    calls = []

    def stop(update):
        calls.append(update.fraction)
        return False

    result = Renderer(sc, RenderSettings(samples=16, threads=1)).render(progress=stop)
    assert result.cancelled and len(calls) == 1
    count = result.passes["Combined"]
    assert np.isfinite(count).all()
    assert 0 < result.stats["samples"] < 16
