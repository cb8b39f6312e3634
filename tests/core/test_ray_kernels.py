"""The per-ray kernels of camera rays, shutter transforms and hit reconstruction against
closed forms, and the same numbers from them as plain Python (NUMBA_DISABLE_JIT=1)."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drt_engine.core.geometry import camera as camera_rays
from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.geometry.motion import Motion, invert_frame
from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, SceneData
from tests.support.scenes import plane, translation, uv_sphere

ROOT = Path(__file__).resolve().parents[2]


def _turn(angle, scale=1.0):
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    m[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) * scale
    return m


def _steps():
    """Three shutter steps: a turn about z, a growing scale and a translation."""
    return np.array([translation(0.2 * k, 0, 0.1 * k) @ _turn(0.4 * k, 1 + 0.25 * k) for k in range(3)])


def test_motion_passes_through_its_steps_and_inverts():
    mats = _steps()
    linear, shift = Motion(mats).at(np.array([0.0, 0.5, 1.0]))
    assert np.allclose(linear, mats[:, :3, :3], atol=1e-12)
    assert np.allclose(shift, mats[:, :3, 3], atol=1e-12)
    # halfway between steps: the rotation is halfway (slerp) and the scale is the mean
    linear, _ = Motion(mats).at(np.array([0.25]))
    assert np.allclose(linear[0], _turn(0.2, 1.125)[:3, :3], atol=1e-12)
    for m in mats:
        inv = np.zeros((3, 4))
        invert_frame(np.ascontiguousarray(m[:3]), inv)
        full = np.eye(4)
        full[:3] = inv
        assert np.allclose(full @ m, np.eye(4), atol=1e-12)


def test_rigid_hits_lie_on_the_triangle_where_it_was_at_the_rays_time():
    """A plane turning and growing over the shutter: each hit's position is on the plane's
    world triangle at the ray's own time, with that triangle's normal."""
    mats = _steps()
    scene = SceneData(camera=None, meshes=[plane(2.0)], instances=[Instance(0, mats)],
                      materials=[Material("m", [Closure("DIFFUSE")])])
    geo = Geometry(scene, np.zeros(3))
    rng = np.random.default_rng(2)
    n = 2000
    time = rng.random(n)
    target = np.concatenate([rng.uniform(-0.6, 0.6, (n, 2)), np.zeros((n, 1))], axis=1)
    linear, shift = Motion(mats).at(time)
    target = np.einsum("nij,nj->ni", linear, target) + shift
    origins = target + np.array([0.1, -0.2, 3.0])
    dirs = target - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hits = geo.intersect(origins, dirs, np.full(n, np.inf), time)
    assert hits.hit.all()
    index = np.arange(n)
    pos, ng, ns = geo.surface(hits, index, geo.ray_times(time))
    assert np.allclose(pos, target, atol=1e-5)
    assert np.allclose(ng, [0, 0, 1], atol=1e-12) and np.allclose(ns, ng)
    # the offset clears the float32 error of the hit, and spawned origins leave on the ray's side
    scale = geo.offset_scale(hits.prim, pos)
    assert (scale > 1e-7).all() and (scale < 1e-3).all()
    from drt_engine.core.geometry.accel import spawn
    up = spawn(pos, ng, -dirs, scale)
    assert np.allclose(up - pos, ng * scale[:, None])


def test_deforming_hits_lie_on_the_mesh_where_it_was_at_the_rays_time():
    """A plane whose vertices rise to z = 1 and come back over the shutter (three vertex steps,
    interpolated linearly between them at each ray's own time, not in buckets)."""
    flat = plane(2.0)
    steps = np.stack([flat.vertices + [0, 0, z] for z in (0.0, 1.0, 0.0)])
    deforming = Mesh("rising", flat.vertices, flat.triangles, flat.material_indices, motion_vertices=steps)
    geo = Geometry(SceneData(camera=None, meshes=[deforming], instances=[Instance(0, translation(0.3, 0, 0))],
                             materials=[Material("m", [Closure("DIFFUSE")])]), np.zeros(3))
    rng = np.random.default_rng(6)
    n = 2000
    time = rng.random(n)
    origins = np.concatenate([rng.uniform(-0.6, 0.6, (n, 2)) + [0.3, 0], np.full((n, 1), 3.0)], axis=1)
    dirs = np.tile([0.0, 0.0, -1.0], (n, 1))
    hits = geo.intersect(origins, dirs, np.full(n, np.inf), time)
    assert geo.moving and hits.hit.all()
    pos, ng, _ = geo.surface(hits, np.arange(n), geo.ray_times(time))
    height = np.where(time < 0.5, 2 * time, 2 - 2 * time)
    np.testing.assert_allclose(pos[:, 2], height, atol=1e-9)
    np.testing.assert_allclose(pos[:, :2], origins[:, :2], atol=1e-9)
    np.testing.assert_allclose(hits.t, 3 - height, atol=1e-9)
    assert np.allclose(ng, [0, 0, 1], atol=1e-12)


def test_an_instanced_mesh_is_one_embree_scene_and_each_instance_numbers_its_own_triangles():
    from drt_engine.core.geometry.embree import TriangleScene

    ball, floor = uv_sphere(0.4, segments=8, rings=6), plane(8.0, z=-1.0)
    places = [translation(x, 0, 0) for x in (-1.0, 0.0, 1.0)]
    scene = SceneData(camera=None, meshes=[ball, floor], instances=[Instance(0, m) for m in places] + [
        Instance(1, np.eye(4))], materials=[Material("m", [Closure("DIFFUSE")])])
    before = TriangleScene.builds
    geo = Geometry(scene, np.array([0.0, 0.0, 5.0]))
    assert TriangleScene.builds - before == 2
    t = len(ball.triangles)
    assert geo.triangle_count == 3 * t + len(floor.triangles)
    origins = np.array([[-1.0, 0, 5], [0.0, 0, 5], [1.0, 0, 5], [3.0, 0, 5]])
    hits = geo.intersect(origins, np.tile([0.0, 0, -1], (4, 1)), np.full(4, np.inf))
    np.testing.assert_array_equal(geo.source_of(hits.prim)[:, 0], [0, 1, 2, 3])  # which object each ray hit
    np.testing.assert_array_equal(hits.prim[:3] // t, [0, 1, 2])
    np.testing.assert_allclose(hits.t, [4.6, 4.6, 4.6, 6.0], atol=2e-2)


def test_lift_moves_hits_toward_the_smooth_sphere():
    """On a coarse sphere with corner normals, the terminator lift brings each facet point
    closer to the sphere those normals describe, never farther."""
    scene = SceneData(camera=None, meshes=[uv_sphere(1.0, segments=8, rings=6)], instances=[Instance(0, np.eye(4))],
                      materials=[Material("m", [Closure("DIFFUSE")])])
    geo = Geometry(scene, np.zeros(3))
    rng = np.random.default_rng(3)
    n = 4000
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hits = geo.intersect(np.zeros((n, 3)), dirs, np.full(n, np.inf))
    index = np.flatnonzero(hits.hit)
    pos, _, _ = geo.surface(hits, index)
    lifted = pos + geo.smooth_offset(hits, index)
    before = 1.0 - np.linalg.norm(pos, axis=1)
    after = np.abs(1.0 - np.linalg.norm(lifted, axis=1))
    assert (after <= before + 1e-12).all()
    assert after.mean() < before.mean()


def test_lens_rays_of_one_image_point_meet_on_the_plane_in_focus():
    cam = Camera(translation(0, 0, 5)[None], (-0.4, 0.4, -0.3, 0.3), (40, 30), aperture_radius=0.2,
                 focus_distance=3.0, blades=6, clip_start=0.5)
    rng = np.random.default_rng(4)
    n = 1000
    px, py = np.full(n, 12.3), np.full(n, 20.7)
    rays = camera_rays.generate(cam, px, py, rng.random((n, 2)))
    eye = rays.origins - rays.directions * rays.t_start[:, None]  # the lens points
    assert np.allclose(eye[:, 2], 5.0) and np.ptp(eye[:, 0]) > 0.2
    focus = eye + rays.directions * (3.0 / rays.depth_per_t)[:, None]
    assert np.allclose(focus, focus[0], atol=1e-12)
    sx, sy = -0.4 + 12.3 / 40 * 0.8, -0.3 + 20.7 / 30 * 0.6
    assert np.allclose(focus[0], [3.0 * sx, 3.0 * sy, 2.0], atol=1e-12)
    assert np.allclose(rays.t_start * rays.depth_per_t, 0.5)


_SCRIPT = """
import numpy as np
from drt_engine.core.geometry import camera as camera_rays
from drt_engine.core.film.film import PixelFilter
from drt_engine.core.sampling.sampler import Sampler
from drt_engine.core.scene import Camera
rng = np.random.default_rng(5)
px, sm = rng.integers(0, 1 << 20, 300), rng.integers(0, 64, 300)
out = {}
for pattern in ("SOBOL", "JITTERED", "GRID"):
    s = Sampler(pattern, 64, 9)
    out[pattern] = np.concatenate([s.get2d(px, sm, d).ravel() for d in (0, 2, 4, 10)] + [s.get(px, sm, 7)])
out["filter"] = PixelFilter("BLACKMAN_HARRIS", 1.5).offset(out["SOBOL"])
m = np.array([np.eye(4), np.eye(4)]); m[1, :3, 3] = (1, 0, 0)
cam = Camera(m, (-0.4, 0.4, -0.3, 0.3), (40, 30), aperture_radius=0.1, blades=5)
r = camera_rays.generate(cam, rng.random(300) * 40, rng.random(300) * 30, rng.random((300, 2)), rng.random(300))
out["camera"] = np.concatenate([r.origins.ravel(), r.directions.ravel(), r.tmax])
from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.scene import Closure, Instance, Material, SceneData
from tests.support.scenes import plane, uv_sphere
scene = SceneData(camera=None, meshes=[uv_sphere(1.0, segments=8, rings=6), plane(4.0, z=-1.0)],
                  instances=[Instance(0, m), Instance(1, np.eye(4))], materials=[Material("m", [Closure("DIFFUSE")])])
geo = Geometry(scene, np.array([0.0, 0.0, 5.0]))
o, d, t = np.tile([0.5, 0.0, 5.0], (300, 1)), rng.normal(size=(300, 3)) * 0.3 + [0, 0, -1], rng.random(300)
d /= np.linalg.norm(d, axis=1, keepdims=True)
hits = geo.intersect(o, d, np.full(300, np.inf), t)
i = np.flatnonzero(hits.hit)
pos, ng, ns = geo.surface(hits, i, t)
out["hits"] = np.concatenate([pos.ravel(), ng.ravel(), ns.ravel(), geo.smooth_offset(hits, i, t).ravel(),
                              geo.offset_scale(hits.prim[i], pos)])
np.savez(OUT, **out)
"""


def test_plain_python_gives_the_kernels_numbers(tmp_path):
    """NUMBA_DISABLE_JIT=1 runs the same code: integer sample values bit for bit, floats to rounding."""
    results = []
    for disable in ("0", "1"):
        out = tmp_path / f"jit{disable}.npz"
        path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))  # keep the caller's
        env = dict(os.environ, NUMBA_DISABLE_JIT=disable, PYTHONPATH=path)
        subprocess.run([sys.executable, "-c", f"OUT = {str(out)!r}\n" + _SCRIPT], env=env, check=True, cwd=ROOT)
        results.append(np.load(out))
    compiled, plain = results
    for name in ("SOBOL", "JITTERED", "GRID", "filter"):
        assert np.array_equal(compiled[name], plain[name]), name
    for name in ("camera", "hits"):
        assert len(compiled[name]) > 1000
        assert compiled[name] == pytest.approx(plain[name], rel=1e-12, abs=1e-12), name
