"""Smooth shading normals that the outgoing direction lies below (a silhouette's rim), as Cycles
shades them: a Lambert-only material keeps the normal as the mesh has it (Cycles' diffuse closure
takes sd->N whatever wo), any other material's is raised as Cycles raises a specular closure's
(ensure_valid_specular_reflection). DRT used the geometric normal for both: a smooth-shaded
8-sided cylinder's rim was 0.19 off Cycles in its worst 4x4 block, within the limit now
(tests/blender/test_smooth_rims_cycles.py)."""
import numpy as np
import pytest

from drt_engine.core.bsdf.specular_normal import valid_specular_reflection
from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.integrator.hits import surface_records
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Mesh, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import look_at, plane

ALBEDO, SUN = 0.5, 3.0
TILT = np.radians(60.0)
NORMAL = np.array([0.0, np.sin(TILT), np.cos(TILT)])  # the plane's smooth normal, tilted away from the camera
WO = np.array([0.0, -np.cos(np.radians(20.0)), np.sin(np.radians(20.0))])  # toward the camera, 20 deg up
TO_SUN = np.array([0.0, np.sin(TILT), np.cos(TILT)])  # along the smooth normal, 30 degrees above the plane


def _tilted_plane(material: Material) -> SceneData:
    """A plane whose every corner normal is ``NORMAL`` (wo lies below it), seen along ``WO`` on a
    narrow camera, lit by a sun along ``TO_SUN``."""
    mesh = plane()
    mesh = Mesh("tilted", mesh.vertices, mesh.triangles, mesh.material_indices,
                corner_normals=np.tile(NORMAL, (2, 3, 1)))
    camera = Camera(look_at(4.0 * WO, (0.0, 0.0, 0.0))[None], (-0.01, 0.01, -0.01, 0.01), (4, 4))
    sun = np.eye(4)
    sun[:3, 2] = TO_SUN  # a sun shines along its -Z
    sun[:3, 1] = np.cross(TO_SUN, [1.0, 0.0, 0.0])
    sun[:3, 0] = np.cross(sun[:3, 1], TO_SUN)
    return SceneData(camera, [mesh], [Instance(0, np.eye(4))], [material],
                     [Light("SUN", sun, irradiance=np.full(3, SUN))])


def test_wo_lies_below_the_smooth_normal():
    assert WO @ NORMAL < -0.5


def test_a_lambert_material_is_lit_about_the_smooth_normal_wo_lies_below():
    """Lambert about the kept normal: albedo E cos(n, l) / pi with cos 1; about the geometric
    normal (DRT before) cos 0.5, half as bright."""
    scene = _tilted_plane(Material("diffuse", [Closure("DIFFUSE", color=(ALBEDO,) * 3)]))
    value = Renderer(scene, RenderSettings(samples=4, threads=1)).render().passes["Combined"][..., :3]
    assert np.allclose(value, ALBEDO * SUN / np.pi * (NORMAL @ TO_SUN), rtol=1e-4)


@pytest.mark.parametrize("keeps, expected", [([True, False], "kept"), ([False, False], "raised")])
def test_the_hit_frame_keeps_or_raises_the_normal(keeps, expected):
    scene = _tilted_plane(Material("glossy", [Closure("GLOSSY", roughness=0.2)]))
    geo = Geometry(scene, np.zeros(3))
    n = 3
    prim, u, v = np.zeros(n, np.int64), np.full(n, 0.25), np.full(n, 0.25)
    dirs = np.tile(-WO, (n, 1))
    hits = surface_records(geo, prim, u, v, None, np.arange(n), dirs, np.array(keeps), mat=np.zeros(n, np.int64),
                           path=np.arange(n), throughput=np.ones((n, 3)), straight=np.ones(n, bool),
                           time=np.full(n, 0.5))
    normal = hits.frame.n
    if expected == "kept":
        assert np.allclose(normal, NORMAL, atol=1e-12)
        assert np.allclose(hits.wo_l[:, 2], WO @ NORMAL, atol=1e-12)
        return
    assert np.allclose(normal, valid_specular_reflection(np.tile([0.0, 0.0, 1.0], (n, 1)), -dirs,
                                                         np.tile(NORMAL, (n, 1))), atol=1e-12)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-12)
    assert (hits.wo_l[:, 2] > 1e-6).all()
    mirror = 2.0 * (normal @ WO)[:, None] * normal - WO  # leaves at Cycles' threshold above the surface
    assert np.allclose(mirror[:, 2], min(0.9 * WO[2], 0.01), atol=1e-9)
    assert normal[0, 1] > 0  # turned toward the geometric normal in their plane, not replaced by it


def test_raising_keeps_a_normal_whose_mirror_image_leaves_above():
    ng = np.array([[0.0, 0.0, 1.0]])
    n = np.array([[0.0, 0.1, 0.995]]) / np.linalg.norm([0.0, 0.1, 0.995])
    wo = np.array([[0.0, -0.6, 0.8]])
    assert np.array_equal(valid_specular_reflection(ng, wo, n), n)
