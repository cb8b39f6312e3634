"""Light sampling routines against their densities."""
import numpy as np
import pytest

from drt_engine.core.lights.area import spherical_rectangle
from drt_engine.core.lights.table import light_table
from drt_engine.core.lights.collection import _sample_batch
from drt_engine.core.lights.triangles import unoccluded_triangles_batch
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera

RNG = np.random.default_rng(3)


def rectangle(sx=2.0, sy=1.0, c=(0.3, -0.2, 1.0)):
    """A light table of one rectangle in the plane z = c_z, facing down (toward the origin)."""
    m = np.eye(4)
    m[:3, 3] = c
    return light_table([Light("AREA", m, radiance=np.ones(3), size_x=sx, size_y=sy)])


def solid_angle(table, origin):
    return spherical_rectangle(table, 0, *origin)[9]


def sample(table, origins, u):
    """Points the light kernel samples on the rectangle, and their densities."""
    wi, dist, _, pdf = _sample_batch(table, 0, origins, u)
    return origins + wi * dist[:, None], pdf


def test_solid_angle_of_a_square_on_axis():
    a, d = 0.5, 2.0
    table = rectangle(2 * a, 2 * a, c=(0, 0, d))
    assert solid_angle(table, (0.0, 0.0, 0.0)) == pytest.approx(4 * np.arcsin(a * a / (a * a + d * d)), rel=1e-10)


def test_samples_lie_on_the_rectangle_and_are_uniform_in_solid_angle():
    n = 200_000
    origin = np.array([[0.1, 0.2, 0.0]])
    table = rectangle()
    q, pdf = sample(table, np.repeat(origin, n, 0), RNG.random((n, 2)))
    c = np.array([0.3, -0.2, 1.0])
    total = solid_angle(table, origin[0])
    assert np.allclose(pdf, 1.0 / total, rtol=1e-12)  # the density is the one of uniform solid angle
    assert np.allclose(q[:, 2], 1.0)
    assert (np.abs(q[:, 0] - c[0]) <= 1.0 + 1e-9).all() and (np.abs(q[:, 1] - c[1]) <= 0.5 + 1e-9).all()
    # the share of samples in the left half is that half's share of the solid angle
    left = solid_angle(rectangle(1.0, 1.0, c=(c[0] - 0.5, c[1], c[2])), origin[0])
    assert np.mean(q[:, 0] < c[0]) == pytest.approx(left / total, abs=0.005)
    right = solid_angle(rectangle(1.0, 1.0, c=(c[0] + 0.5, c[1], c[2])), origin[0])
    assert left + right == pytest.approx(total, rel=1e-9)


def test_solid_angle_sampling_is_less_noisy_than_area_sampling_near_a_large_light():
    """Irradiance under a 4x4 light 0.3 above: per-sample variance of both estimators."""
    n = 20_000
    o = np.zeros((n, 3))
    u = RNG.random((n, 2))
    q, pdf = sample(rectangle(4.0, 4.0, c=(0, 0, 0.3)), o, u)
    wi = q / np.linalg.norm(q, axis=1, keepdims=True)
    solid = wi[:, 2] / pdf  # cos(theta) / pdf
    qa = np.stack([(u[:, 0] - 0.5) * 4, (u[:, 1] - 0.5) * 4, np.full(n, 0.3)], 1)
    d2 = (qa * qa).sum(1)
    area = (0.3 / np.sqrt(d2)) ** 2 / d2 * 16.0  # cos_i cos_l A / d²
    a = 2.0 / 0.3  # closed form: four corner patches of a rectangle centred above
    exact = 4 * np.pi * (2 * a / np.sqrt(1 + a * a) * np.arctan(a / np.sqrt(1 + a * a))) / (2 * np.pi)
    assert solid.mean() == pytest.approx(exact, rel=0.01)
    assert area.mean() == pytest.approx(exact, rel=0.15)
    assert solid.var() < 0.2 * area.var()


@pytest.mark.parametrize("x", [0.0, 2.0, 4.0])
def test_a_floor_lit_by_a_mesh_light_at_grazing_angles_gets_all_its_light(x):
    """A 1 m emissive panel 1 m above a white floor, straight above and off to the side: the
    floor's radiance is albedo / pi times the panel's closed-form irradiance. Shadow rays toward
    the panel start offset from the floor; aimed parallel to the sample's direction they met the
    panel short of the sampled point and every grazing sample was blocked (black at x = 2)."""
    floor = Material("floor", [Closure("DIFFUSE", color=(0.5,) * 3)])
    glow = Material("glow", [Closure("EMISSION", emission=(1.0, 1.0, 1.0))])
    panel = plane(size=1.0, z=1.0, material=1)
    panel.vertices = panel.vertices + [x, 0.0, 0.0]
    panel.triangles = panel.triangles[:, ::-1].copy()  # facing the floor
    scene = SceneData(camera=top_camera(height=0.5), meshes=[plane(), panel],
                      instances=[Instance(0, np.eye(4)), Instance(1, np.eye(4))], materials=[floor, glow], lights=[])
    irradiance = np.zeros((1, 3))
    unoccluded_triangles_batch(panel.vertices, panel.triangles.astype(np.int64), np.ones((2, 3)),
                               np.array([0, 1], np.int64), np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), irradiance)
    image = Renderer(scene, RenderSettings(samples=64, threads=1)).render().passes["Combined"][..., 0]
    assert image.mean() == pytest.approx(0.5 / np.pi * irradiance[0, 0], rel=0.03)
