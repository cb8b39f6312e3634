"""The Bevel node's normals (core.shading.bevel) against what the geometry says they must be.

On a cube's top face farther than Radius from every edge every disk ray finds the top alone: the
normal is the top's exactly. At the middle of an edge the two faces lie symmetrically about the
point: the normal is their bisector. Between the two it turns steadily from the top towards the
side. A mirroring transform keeps the normals outward; a point seen from the back gets the normal
turned to face the ray, as Cycles; no radius, no samples or a blurry path (least bounce density
below 8) leave the shading normal."""
import numpy as np

from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.sampling import dims as D
from drt_engine.core.sampling.sampler import Sampler
from drt_engine.core.scene import Camera, Closure, Instance, Material, SceneData
from drt_engine.core.shading.occlusion import OcclusionRays
from tests.support.scenes import cube, look_at

N = 256  # points (pixels), 32 disk samples each
TOP = 10  # the cube's top triangle over x >= y


def _rays(point, matrix=np.eye(4), facing=(0.0, 0.0, 1.0), min_pdf=None):
    cam = Camera(look_at((0, -8, 3), (0, 0, 0))[None], (-0.5, 0.5, -0.5, 0.5), (8, 8))
    scene = SceneData(cam, [cube((0.0, 0.0, 0.0), 1.0, 0)], [Instance(0, matrix)],
                      [Material("m", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])], [])
    geo = Geometry(scene, np.zeros(3))
    pos = np.tile(point, (N, 1)).astype(float)
    prims = np.full(N, TOP, np.int64)
    n = np.tile(facing, (N, 1))
    return OcclusionRays(geo, Sampler("SOBOL", 1), np.arange(N), np.zeros(N, np.int64), 0, pos, n,
                         geo.offset_scale(prims, pos), prims, None, n,
                         min_pdf=None if min_pdf is None else np.full(N, min_pdf))


def _mean(normals):
    m = normals.mean(axis=0)
    return m / np.linalg.norm(m)


def test_a_point_farther_than_radius_from_edges_keeps_its_normal():
    n = _rays((0.3, -0.2, 1.0)).bevel(0.2, 32)
    assert np.allclose(n, [0.0, 0.0, 1.0], atol=1e-9)


def test_at_an_edge_the_normal_is_the_faces_bisector_and_turns_on_the_way():
    at_edge = _mean(_rays((1.0 - 1e-6, 0.0, 1.0)).bevel(0.2, 32))
    assert np.allclose(at_edge, [np.sqrt(0.5), 0.0, np.sqrt(0.5)], atol=0.03), at_edge
    tilt = [np.degrees(np.arctan2(*_mean(_rays((1.0 - d, 0.0, 1.0)).bevel(0.2, 32))[[0, 2]]))
            for d in (0.0, 0.05, 0.1, 0.15, 0.25)]
    assert all(a > b for a, b in zip(tilt, tilt[1:])), tilt
    assert tilt[-1] == 0.0 and tilt[-2] > 0.1, tilt


def test_a_mirrored_object_keeps_its_normals_outward():
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])  # the edge at x = 1 now at x = -1
    n = _mean(_rays((-1.0 + 1e-6, 0.0, 1.0), mirror).bevel(0.2, 32))
    assert np.allclose(n, [-np.sqrt(0.5), 0.0, np.sqrt(0.5)], atol=0.03), n


def test_seen_from_the_back_the_normal_faces_the_ray():
    front = _mean(_rays((1.0 - 0.05, 0.0, 1.0)).bevel(0.2, 32))
    back = _mean(_rays((1.0 - 0.05, 0.0, 1.0), facing=(0.0, 0.0, -1.0)).bevel(0.2, 32))
    assert front[0] > 0.1 and np.allclose(back, -front, atol=0.03), (front, back)  # its disk mirrored


def test_no_radius_no_samples_or_a_blurry_path_keep_the_shading_normal():
    rays = _rays((1.0 - 0.05, 0.0, 1.0))
    up = np.tile([0.0, 0.0, 1.0], (N, 1))
    assert np.array_equal(rays.bevel(0.0, 32), up)
    assert np.array_equal(rays.bevel(0.2, 0), up)
    assert np.array_equal(_rays((1.0 - 0.05, 0.0, 1.0), min_pdf=7.9).bevel(0.2, 32), up)
    assert not np.allclose(_rays((1.0 - 0.05, 0.0, 1.0), min_pdf=8.0).bevel(0.2, 32), up)


def test_the_disk_samples_draw_a_dimension_above_the_others():
    assert D.bevel(0) > D.ao(1024, 127) and D.bevel(1) == D.bevel(0) + 2
