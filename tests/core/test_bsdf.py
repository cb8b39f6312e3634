"""BSDF facts: energy conservation, Fresnel, continuity of near-mirror lobes."""
import numpy as np
import pytest

from drt_engine.core import microfacet as mf
from drt_engine.core.bsdf import MaterialShader
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(7)


def sampled_albedo(closure, mu, n=100_000, inside=False):
    shader = MaterialShader(Material("m", [closure]))
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (n, 1))
    wi, w, pdf, delta, ok, _ = shader.sample(wo, RNG.random(n), RNG.random((n, 2)), np.full(n, inside))
    assert np.isfinite(w).all() and np.isfinite(wi).all()
    return (w * ok[:, None]).mean(axis=0)


def evaluated_albedo(closure, mu, n=200_000):
    """Uniform-sphere estimate of the integral of f |cos|, for lobes broad enough."""
    shader = MaterialShader(Material("m", [closure]))
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (n, 1))
    z = 2 * RNG.random(n) - 1
    phi = 2 * np.pi * RNG.random(n)
    r = np.sqrt(1 - z * z)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    f_d, f_nd, _ = shader.evaluate(wo, wi, wi[:, 2] > 0, np.zeros(n, bool))
    return ((f_d + f_nd) * 4 * np.pi).mean(axis=0)


@pytest.mark.parametrize("roughness", [0.0, 0.05, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("mu", [1.0, 0.5, 0.1])
def test_white_glossy_conserves_energy(roughness, mu):
    """Multiscatter GGX with a white tint reflects everything (as Cycles' multiscatter GGX)."""
    assert sampled_albedo(Closure("GLOSSY", color=(1, 1, 1), roughness=roughness), mu)[0] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("roughness", [0.6, 0.9])
def test_sampling_and_evaluation_agree(roughness):
    """Importance-sampled albedo equals the albedo integrated from evaluate() (uniform sphere)."""
    c = Closure("PRINCIPLED", color=(0.9, 0.6, 0.3), metallic=1.0, roughness=roughness)
    assert evaluated_albedo(c, 0.7) == pytest.approx(sampled_albedo(c, 0.7), rel=0.02)


@pytest.mark.parametrize("mu", [1.0, 0.6, 0.2])
def test_smooth_glass_reflects_plus_transmits_everything(mu):
    """R + T = 1: sampled weights are R + T/eta² in radiance units (T scaled by 1/eta² entering)."""
    eta = 1.5
    a = sampled_albedo(Closure("GLASS", color=(1, 1, 1), roughness=0.0, ior=eta), mu)[0]
    r = mf.fresnel_dielectric(np.array([mu]), eta)[0]
    assert a == pytest.approx(r + (1 - r) / eta**2, rel=0.01)


def test_fresnel_at_normal_incidence_and_total_internal_reflection():
    assert mf.fresnel_dielectric(np.array([1.0]), 1.5)[0] == pytest.approx(0.04)
    critical = np.sqrt(1 - (1 / 1.5) ** 2)
    assert mf.fresnel_dielectric(np.array([-(critical - 1e-3)]), 1.5)[0] == 1.0
    assert mf.fresnel_dielectric(np.array([-(critical + 1e-3)]), 1.5)[0] < 1.0


@pytest.mark.parametrize("mu", [0.9, 0.2])
def test_brightness_is_continuous_across_the_mirror_threshold(mu):
    """Roughness just below and just above the delta switch reflect the same energy."""
    below = np.sqrt(mf.DELTA_ALPHA) * 0.99
    above = np.sqrt(mf.DELTA_ALPHA) * 1.01
    tint = (0.9, 0.5, 0.2)
    a = sampled_albedo(Closure("PRINCIPLED", color=tint, metallic=1.0, roughness=below), mu)
    b = sampled_albedo(Closure("PRINCIPLED", color=tint, metallic=1.0, roughness=above), mu)
    assert a == pytest.approx(b, rel=0.01)


def test_principled_dielectric_diffuse_is_reduced_by_specular_albedo():
    shader = MaterialShader(Material("m", [Closure("PRINCIPLED", color=(0.8, 0.8, 0.8), roughness=0.5)]))
    diff, gloss = shader.colors(np.array([1.0]))
    assert gloss[0, 0] == pytest.approx(0.04, abs=0.01)
    assert diff[0, 0] == pytest.approx(0.8 * (1 - gloss[0, 0]), rel=1e-6)
