"""Fresnel: glass of IOR 1 is invisible, R + T = 1, total internal reflection, IOR below 1 and 10.

Before the fix, rough glass of IOR 1.0 and 1.0001 (roughness 0.5) in front of an emissive
checkerboard came out 4.4% darker than the checkerboard alone and blurred (mean absolute
error 2.6% of the image, worst pixel 0.17 on a 0.6 mean): the Walter half vector
wi·eta + wo vanishes as eta -> 1. A glass lobe now becomes a delta when its refracted
spread alpha·|eta - 1| is below the delta threshold, masked at that spread.
"""
import numpy as np
import pytest

from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.scene import Mesh

from tests.support.core_cases import Camera, Closure, Instance, Material, SceneData, World, render
from tests.support.scenes import look_at, uv_sphere


def checkerboard(n=8, size=4.0, z=-2.0):
    """Emissive squares of radiance 1 and 0.2 (materials 1 and 2), a background with structure."""
    x0, y0 = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    x0, y0 = (x0.ravel() * size / n - size / 2), (y0.ravel() * size / n - size / 2)
    d = size / n
    corners = np.stack([np.stack([x0, y0], 1), np.stack([x0 + d, y0], 1), np.stack([x0 + d, y0 + d], 1),
                        np.stack([x0, y0 + d], 1)], 1)
    v = np.concatenate([corners, np.full((n * n, 4, 1), z)], axis=2).reshape(-1, 3)
    b = 4 * np.arange(n * n)[:, None]
    tris = np.concatenate([b + [0, 1, 2], b + [0, 2, 3]], axis=1).reshape(-1, 3)
    mat = np.repeat(1 + (np.arange(n * n) // n + np.arange(n * n) % n) % 2, 2)
    return Mesh("checker", v, tris, mat)


def glass_scene(ior=None, roughness=0.0):
    cam = Camera(look_at((0, 0, 4), (0, 0, 0), up=(0, 1, 0))[None], (-0.3, 0.3, -0.3, 0.3), (16, 16))
    mats = [Material("glass", [Closure("GLASS", roughness=roughness, ior=ior or 1.5, color=(1, 1, 1))]),
            Material("bright", [Closure("EMISSION", emission=(1, 1, 1))]),
            Material("dim", [Closure("EMISSION", emission=(0.2, 0.2, 0.2))])]
    meshes, instances = [checkerboard()], [Instance(0, np.eye(4))]
    if ior is not None:
        meshes.append(uv_sphere(1.0, material=0))
        instances.append(Instance(1, np.eye(4)))
    return SceneData(cam, meshes, instances, mats, [], World(np.full(3, 0.3)))


@pytest.fixture(scope="module")
def background():
    return render(glass_scene(), samples=16, determinism=False)[0]["Combined"][..., :3]


@pytest.mark.parametrize("ior", [1.0, 1.0001])
@pytest.mark.parametrize("roughness", [0.0, 0.5])
def test_glass_of_ior_one_is_invisible(ior, roughness, background):
    image = render(glass_scene(ior, roughness), samples=16)[0]["Combined"][..., :3]
    assert abs(image.mean() / background.mean() - 1) < 3e-3
    # IOR 1.0001 still reflects within about a degree of grazing: the sphere's rim, a few pixels
    assert np.abs(image - background).mean() < 5e-3 * background.mean()


def fresnel_reference(cos_i, eta):
    """Unpolarised Fresnel reflectance from the s and p amplitudes (eta = n_t / n_i)."""
    sin_t2 = (1 - cos_i**2) / eta**2
    if sin_t2 >= 1:
        return 1.0
    cos_t = np.sqrt(1 - sin_t2)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def lobe_split(ior, angle, inside, roughness=0.0, n=20000):
    """(reflected energy, transmitted energy) of a white glass lobe for a ray at ``angle`` from the normal.

    Transmitted radiance is scaled by 1/eta² on crossing; the energy (flux) multiplies it back.
    """
    shader = MaterialShader(Material("g", [Closure("GLASS", roughness=roughness, ior=ior, color=(1, 1, 1))]))
    th = np.radians(angle)
    wo = np.tile([np.sin(th), 0.0, np.cos(th)], (n, 1))
    rng = np.random.default_rng(3)
    wi, weight, _, _, valid, _ = shader.sample(wo, rng.random(n), rng.random((n, 2)), np.full(n, inside))
    assert np.isfinite(weight).all()
    eta = 1.0 / ior if inside else ior  # n on wi's side over n on wo's side, for transmission
    w = np.where(valid, weight[:, 0], 0.0)
    reflected = wi[:, 2] > 0
    return float(w[reflected].sum() / n), float((w[~reflected] * eta**2).sum() / n)


ANGLES = [0.0, 30.0, 60.0, 85.0, 89.0, 89.99]


@pytest.mark.parametrize("ior", [1.5, 0.7, 10.0])
@pytest.mark.parametrize("inside", [False, True])
def test_smooth_glass_reflects_fresnel_and_transmits_the_rest(ior, inside):
    for angle in ANGLES:
        r, t = lobe_split(ior, angle, inside)
        eta = 1.0 / ior if inside else ior
        f = fresnel_reference(np.cos(np.radians(angle)), eta)
        assert abs(r + t - 1.0) < 1e-9, (angle, r, t)
        assert abs(r - f) < 4 * np.sqrt(f * (1 - f) / 20000) + 1e-9, (angle, r, f)


@pytest.mark.parametrize("ior", [1.5, 0.7, 10.0])
def test_rough_glass_loses_energy_never_gains_it(ior):
    for inside in (False, True):
        for angle in ANGLES:
            r, t = lobe_split(ior, angle, inside, roughness=0.5)
            assert 0.0 <= r + t <= 1.0 + 0.02, (inside, angle, r, t)


@pytest.mark.parametrize("ior, critical", [(1.5, np.degrees(np.arcsin(1 / 1.5))), (0.7, np.degrees(np.arcsin(0.7)))])
def test_total_internal_reflection_past_the_critical_angle(ior, critical):
    """From inside glass of IOR 1.5 (or from outside a medium of IOR 0.7) nothing leaves past the critical angle."""
    inside = ior > 1
    r, t = lobe_split(ior, critical - 0.5, inside)
    assert t > 0.1
    for angle in (critical + 0.01, critical + 1.0, 89.99):
        r, t = lobe_split(ior, angle, inside)
        assert t == 0.0 and abs(r - 1.0) < 1e-12


@pytest.mark.parametrize("ior", [0.7, 10.0])
@pytest.mark.parametrize("roughness", [0.0, 0.3])
def test_sphere_of_extreme_ior_under_a_white_world_is_finite_and_not_brighter(ior, roughness):
    cam = Camera(look_at((0, 0, 4), (0, 0, 0), up=(0, 1, 0))[None], (-0.3, 0.3, -0.3, 0.3), (12, 12))
    mat = Material("glass", [Closure("GLASS", roughness=roughness, ior=ior, color=(1, 1, 1))])
    scene = SceneData(cam, [uv_sphere(1.0)], [Instance(0, np.eye(4))], [mat], [], World(np.ones(3)))
    image = render(scene, samples=16)[0]["Combined"][..., :3]
    # energy: nothing brighter than the world it shows (smooth glass is noiseless here)
    assert (image.max() if roughness == 0 else image.mean()) <= 1.0 + 1e-6
    assert image.mean() > (0.9 if roughness == 0 else 0.6)  # only paths cut at max depth are lost
