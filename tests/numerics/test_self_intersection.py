"""Self-intersection: rays leaving a surface never hit it again, shadows have no acne, planes do not leak.

New rays start at the float64 hit point pushed along the geometric normal by a bound on
the float32 error of the triangle (``accel.spawn``, ``Geometry.offset_scale``).
"""
import numpy as np
import pytest

from drt_engine.core.geometry.accel import Geometry, spawn
from drt_engine.core.scene import Camera, Instance, Light, Mesh, SceneData

from tests.support.core_cases import diffuse, render
from tests.support.scenes import look_at, plane, translation

TRIANGLES = 4000
DIRECTIONS = 16


def random_triangles(seed=1):
    """Triangles of size 10^U(-8, 8), each 0 to 30 times its size from the camera (origin)."""
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-8, 8, TRIANGLES)
    centre = rng.normal(size=(TRIANGLES, 3)) * (scale * rng.uniform(0, 30, TRIANGLES))[:, None]
    v = centre[:, None, :] + rng.normal(size=(TRIANGLES, 3, 3)) * scale[:, None, None]
    return rng, scale, v


def test_random_triangles_are_never_hit_again_from_their_own_hits():
    """Hit each triangle from both sides, then leave the hit in 16 directions (a quarter within
    1e-3 rad of the surface plane): no ray may hit the triangle it started on."""
    rng, scale, v = random_triangles()
    mesh = Mesh("random", v.reshape(-1, 3), np.arange(3 * TRIANGLES).reshape(-1, 3), np.zeros(TRIANGLES))
    cam = Camera(np.eye(4)[None], (-1, 1, -1, 1), (1, 1))
    geo = Geometry(SceneData(cam, [mesh], [Instance(0, np.eye(4))]), np.zeros(3))
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    target = np.einsum("ti,tij->tj", rng.dirichlet([1, 1, 1], TRIANGLES), v)
    self_hits = shots = 0
    for side in (1.0, -1.0):
        hits = geo.intersect(target + side * n * scale[:, None], -side * n, np.full(TRIANGLES, np.inf))
        own = np.flatnonzero(hits.prim == np.arange(TRIANGLES))
        assert len(own) > TRIANGLES // 4  # the rest are hidden behind other random triangles
        pos, ng, _ = geo.surface(hits, own)
        offset = geo.offset_scale(hits.prim[own], pos)
        for k in range(DIRECTIONS):
            d = rng.normal(size=(len(own), 3))
            if k % 4 == 0:  # grazing: within 1e-3 rad of the triangle's plane
                d -= np.einsum("ij,ij->i", d, ng)[:, None] * ng * (1 - 1e-3)
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            again = geo.intersect(spawn(pos, ng, d, offset), d, np.full(len(own), np.inf))
            self_hits += int((again.prim == own).sum())
            shots += len(own)
    assert shots > 50000
    assert self_hits == 0


@pytest.mark.parametrize("scale", [1e-4, 1.0, 1e4])
@pytest.mark.parametrize("offset", [0.0, 1e5, 1e7])
def test_lit_plane_has_zero_shadowed_light_samples(scale, offset, monkeypatch):
    """A tilted plane under a sun and an area light, seen from a grazing 80°: no shadow ray is
    blocked (the image is bit-identical to one rendered with nothing to block shadow rays)."""
    tilt = look_at((0.3, -0.2, 1.0), (0, 0, 0))
    tilt[:3, 3] = offset
    normal = tilt[:3, 2]
    to_eye = normal * np.cos(np.radians(80)) + tilt[:3, 0] * np.sin(np.radians(80))
    eye = tilt[:3, 3] + to_eye * 3 * scale
    cam = Camera(look_at(eye, tilt[:3, 3], up=normal)[None], (-0.1, 0.1, -0.1, 0.1), (16, 16),
                 clip_start=1e-3 * scale, clip_end=1e3 * scale)
    area_at = tilt[:3, 3] + (normal + 0.5 * tilt[:3, 1]) * 2 * scale
    lights = [Light("SUN", look_at(normal + tilt[:3, 0], (0, 0, 0)), irradiance=np.full(3, 1.0)),
              Light("AREA", look_at(area_at, tilt[:3, 3]), radiance=np.full(3, 1.0), size_x=scale, size_y=scale)]
    mesh = plane(size=100 * scale)
    scene = SceneData(cam, [mesh], [Instance(0, tilt)], [diffuse()], lights)
    passes, result = render(scene, samples=4, determinism=False)
    assert result.stats["rays"]["shadow"] == 2 * 16 * 16 * 4  # every camera sample hits the plane, both lights face it
    monkeypatch.setattr(Geometry, "handle", property(lambda geo: 0))  # shadow rays find nothing at all
    unblocked, _ = render(scene, samples=4, determinism=False)
    assert np.array_equal(passes["Combined"], unblocked["Combined"])


@pytest.mark.parametrize("offset", [0.0, 1e5, 1e7])
def test_parallel_planes_one_millimetre_apart_do_not_leak(offset):
    """Camera between two planes 1e-3 apart, looking down at the lower one; sun, point and area
    light above the upper one: the lower plane stays exactly black."""
    base = translation(offset, -offset, offset)
    cam = Camera((base @ translation(0, 0, 5e-4))[None], (-2, 2, -2, 2), (16, 16), clip_start=1e-6)
    lights = [Light("SUN", look_at((0.2, 0.1, 1), (0, 0, 0)), irradiance=np.full(3, 1.0), angle=0.2),
              Light("POINT", base @ translation(0.1, 0, 0.5), intensity=np.full(3, 1.0), radius=0.05),
              Light("AREA", base @ translation(0, 0.1, 0.2), radiance=np.full(3, 1.0), size_x=0.3)]
    scene = SceneData(cam, [plane(size=10.0), plane(size=10.0, z=1e-3)],
                      [Instance(0, base), Instance(1, base)], [diffuse(0.8)], lights)
    passes, _ = render(scene, samples=4, determinism=offset == 0.0)
    assert passes["Combined"][..., :3].max() == 0.0
    depth = passes["Depth"][..., 0]
    assert np.all(depth > 0) and np.all(depth < 5e-4 * 30)  # the lower plane is what the camera sees
