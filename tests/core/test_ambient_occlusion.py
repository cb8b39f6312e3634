"""The Ambient Occlusion node's rays (core.shading.occlusion) against closed forms.

On a floor under a ceiling h above, a cosine-distributed ray at angle theta from the normal meets
the ceiling at h / cos(theta), so within Distance D > h a share (h / D)^2 of the rays gets out (the
cosine-weighted probability of cos(theta) < h / D). The ceiling another object: Only Local sees
none of it (AO 1); the floor and the ceiling one object, placed by a transform that doubles its
height: Only Local gives the closed form of the doubled height. Inside turns the rays down, where
nothing is: AO 1."""
import numpy as np

from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.sampling import dims as D
from drt_engine.core.sampling.sampler import Sampler
from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, SceneData
from drt_engine.core.shading.occlusion import OcclusionRays
from tests.support.scenes import look_at, plane, translation

N = 4096  # points (pixels), 16 rays each: the share's standard error about 0.002


def _rays(instances, meshes, point, prim=0):
    cam = Camera(look_at((0, -8, 3), (0, 0, 0))[None], (-0.5, 0.5, -0.5, 0.5), (8, 8))
    scene = SceneData(cam, meshes, instances, [Material("m", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])], [])
    geo = Geometry(scene, np.zeros(3))
    pos = np.tile(point, (N, 1)).astype(float)
    prims = np.full(N, prim, np.int64)
    up = np.tile([0.0, 0.0, 1.0], (N, 1))
    return OcclusionRays(geo, Sampler("SOBOL", 1), np.arange(N), np.zeros(N, np.int64), 0, pos, up,
                         geo.offset_scale(prims, pos), prims, None, up)


def test_the_share_of_rays_out_under_a_ceiling_is_the_closed_form():
    rays = _rays([Instance(0, translation()), Instance(0, translation(z=0.5))], [plane(10.0)], (0.2, -0.2, 0.0))
    ao = rays.unoccluded(None, 1.0, 16, False, False)
    assert abs(ao.mean() - 0.25) < 0.01, ao.mean()
    assert abs(rays.unoccluded(None, 0.7, 16, False, False).mean() - (0.5 / 0.7) ** 2) < 0.01
    assert (rays.unoccluded(None, 0.4, 16, False, False) == 1.0).all()  # the ceiling beyond Distance
    assert (rays.unoccluded(None, 1.0, 16, True, False) == 1.0).all()  # Inside: down, into nothing
    assert (rays.unoccluded(None, 1.0, 16, False, True) == 1.0).all()  # Only Local: the ceiling is another object
    assert (rays.unoccluded(None, 0.0, 16, False, False) == 1.0).all()  # no distance, as Cycles
    assert (rays.unoccluded(None, 1.0, 0, False, False) == 1.0).all()  # no samples
    # a linked Normal tilted away from the ceiling lets more rays out
    tilted = np.tile([np.sin(1.0), 0.0, np.cos(1.0)], (N, 1)) * 3.0  # not unit: normalised as Cycles
    assert rays.unoccluded(tilted, 1.0, 16, False, False).mean() > 0.3


def test_only_local_sees_the_object_itself_through_its_transform():
    floor, ceiling = plane(10.0), plane(10.0, z=0.25)
    both = Mesh("both", np.concatenate([floor.vertices, ceiling.vertices]),
                np.concatenate([floor.triangles, ceiling.triangles + 4]), np.zeros(4, np.int32))
    place = translation(3.0, 1.0, 2.0) @ np.diag([1.0, 1.0, 2.0, 1.0])  # the ceiling 0.5 above in the world
    rays = _rays([Instance(0, place)], [both], (3.2, 0.8, 2.0))
    ao = rays.unoccluded(None, 1.0, 16, False, True)
    assert abs(ao.mean() - 0.25) < 0.01, ao.mean()
    assert np.array_equal(ao, rays.unoccluded(None, 1.0, 16, False, False))  # the same rays, the same hits


def test_each_ray_draws_its_own_dimension_above_the_others():
    assert D.ao(0, 0) > D.LightDims(["world"], 64).point(64, 0)
    assert D.ao(1, 0) - D.ao(0, 0) >= 2 * 128 and D.ao(0, 1) == D.ao(0, 0) + 2
