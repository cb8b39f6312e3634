"""Smooth shading normals that the outgoing direction lies below (a silhouette's rim), as Cycles
shades them: its diffuse closures take the normal as the mesh has it (sd->N, whatever wo), the
others a normal raised from it (ensure_valid_specular_reflection). DRT's hit frame is about the
raised normal and its diffuse lobes take the mesh's (core.bsdf.diffuse_normal). DRT used the
geometric normal for both: a smooth-shaded 8-sided cylinder's rim was 0.19 off Cycles in its worst
4x4 block, within the limit now (tests/blender/test_smooth_rims_cycles.py)."""
import numpy as np

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


def test_a_mixture_lights_its_diffuse_lobe_about_the_smooth_normal_wo_lies_below():
    """Diffuse and (black) Glossy, half and half: the glossy lobe's normal is raised, the diffuse
    lobe's is the mesh's all the same (Cycles' sd->N); one raised frame for both (DRT before this
    test) lit it by cos(raised normal, sun) < 1."""
    closures = [Closure("DIFFUSE", weight=np.full(3, 0.5), color=(ALBEDO,) * 3),
                Closure("GLOSSY", weight=np.full(3, 0.5), color=(0.0, 0.0, 0.0), roughness=0.2)]
    scene = _tilted_plane(Material("mixed", closures))
    value = Renderer(scene, RenderSettings(samples=4, threads=1)).render().passes["Combined"][..., :3]
    assert np.allclose(value, 0.5 * ALBEDO * SUN / np.pi * (NORMAL @ TO_SUN), rtol=1e-4)


def _hits(dirs, correction=True):
    scene = _tilted_plane(Material("glossy", [Closure("GLOSSY", roughness=0.2)], bump_correction=correction))
    geo = Geometry(scene, np.zeros(3))
    n = len(dirs)
    prim, u, v = np.zeros(n, np.int64), np.full(n, 0.25), np.full(n, 0.25)
    raises = np.array([m.bump_correction for m in scene.materials] + [True])
    return surface_records(geo, prim, u, v, None, np.arange(n), dirs, raises, mat=np.zeros(n, np.int64),
                           path=np.arange(n), throughput=np.ones((n, 3)), straight=np.ones(n, bool),
                           time=np.full(n, 0.5))


def test_the_hit_frame_raises_the_normal_and_the_diffuse_lobes_keep_it():
    n = 3
    dirs = np.tile(-WO, (n, 1))
    hits = _hits(dirs)
    normal = hits.frame.n
    assert np.allclose(normal, valid_specular_reflection(np.tile([0.0, 0.0, 1.0], (n, 1)), -dirs,
                                                         np.tile(NORMAL, (n, 1))), atol=1e-12)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-12)
    assert (hits.wo_l[:, 2] > 1e-6).all()
    mirror = 2.0 * (normal @ WO)[:, None] * normal - WO  # leaves at Cycles' threshold above the surface
    assert np.allclose(mirror[:, 2], min(0.9 * WO[2], 0.01), atol=1e-9)
    assert normal[0, 1] > 0  # turned toward the geometric normal in their plane, not replaced by it
    assert np.allclose(hits.ns, NORMAL, atol=1e-12)  # the diffuse lobes' normal: the mesh's, wo below it
    assert np.allclose(hits.frame.to_world(hits.dn), NORMAL, atol=1e-12)
    assert np.allclose(hits.dn[:, 2], NORMAL @ normal[0], atol=1e-12) and (hits.dn[:, 2] < 1.0 - 1e-3).all()


def test_where_wo_lies_above_the_smooth_normal_it_is_every_lobe_s():
    """Seen from above the smooth normal: one normal, and the diffuse lobes' is (0, 0, 1) to the
    bit, so that their arithmetic is the frame's (core.bsdf.diffuse_normal)."""
    hits = _hits(np.tile(-NORMAL, (2, 1)))
    assert np.allclose(hits.frame.n, NORMAL, atol=1e-12)
    assert np.array_equal(hits.ns, hits.frame.n) and np.array_equal(hits.dn, np.tile([0.0, 0.0, 1.0], (2, 1)))


def test_wo_above_the_smooth_normal_whose_mirror_image_leaves_below_raises_it_too():
    """Cycles raises a specular closure's normal wherever wo's mirror image would leave below the
    surface, wo above the normal or not: there too the frame is raised and the diffuse lobes keep
    the mesh's normal (a Principled cylinder's top cap under a soft sun: its worst block 0.0071
    off Cycles raising only where wo lay below, 0.0058 with this)."""
    wo = np.array([0.0, 0.3, np.sqrt(1.0 - 0.09)])
    assert wo @ NORMAL > 0.7 and (2.0 * (wo @ NORMAL) * NORMAL - wo)[2] < 0.0
    hits = _hits(np.tile(-wo, (2, 1)))
    raised = valid_specular_reflection(np.tile([0.0, 0.0, 1.0], (2, 1)), np.tile(wo, (2, 1)), np.tile(NORMAL, (2, 1)))
    assert np.allclose(hits.frame.n, raised, atol=1e-12) and not np.allclose(raised, NORMAL, atol=1e-3)
    assert np.allclose(hits.ns, NORMAL, atol=1e-12) and np.allclose(hits.frame.to_world(hits.dn), NORMAL, atol=1e-12)


def test_bump_map_correction_off_keeps_the_normal_for_every_lobe():
    """A material whose Bump Map Correction is off: Cycles' maybe_ensure_valid_specular_reflection
    returns the normal as it is, so the frame is the mesh's normal for every lobe, where wo's
    mirror image about it leaves below the surface too (a Principled cylinder's cap: raised there
    anyway, DRT was up to 0.05 off Cycles with the setting off, tests/blender/test_smooth_rims_cycles.py)."""
    wo = np.array([0.0, 0.3, np.sqrt(1.0 - 0.09)])
    hits = _hits(np.tile(-wo, (2, 1)), correction=False)
    assert np.allclose(hits.frame.n, NORMAL, atol=1e-7)
    assert np.array_equal(hits.ns, hits.frame.n) and np.array_equal(hits.dn, np.tile([0.0, 0.0, 1.0], (2, 1)))


def test_without_bump_map_correction_a_glossy_lobe_sees_nothing_from_below_the_normal():
    """Bump Map Correction off and wo below the smooth normal: Cycles' microfacet closures need
    cos(N, wi) > 0 and give nothing, the diffuse half its light about that normal. DRT evaluated
    GGX there with wo's cosine floored at 1e-30: pixels of 1e25 (a coated Principled with a bumped
    base, tests/blender/test_coat_normal_cycles.py)."""
    closures = [Closure("DIFFUSE", weight=np.full(3, 0.5), color=(ALBEDO,) * 3),
                Closure("GLOSSY", weight=np.full(3, 0.5), roughness=0.3)]
    scene = _tilted_plane(Material("uncorrected", closures, bump_correction=False))
    value = Renderer(scene, RenderSettings(samples=16, threads=1)).render().passes["Combined"][..., :3]
    assert np.allclose(value, 0.5 * ALBEDO * SUN / np.pi * (NORMAL @ TO_SUN), rtol=1e-4)


def test_raising_keeps_a_normal_whose_mirror_image_leaves_above():
    ng = np.array([[0.0, 0.0, 1.0]])
    n = np.array([[0.0, 0.1, 0.995]]) / np.linalg.norm([0.0, 0.1, 0.995])
    wo = np.array([[0.0, -0.6, 0.8]])
    assert np.array_equal(valid_specular_reflection(ng, wo, n), n)
