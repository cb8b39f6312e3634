"""Anisotropic GGX (Cycles' alpha_x along the shading frame's tangent, alpha_y along its bitangent):
sampling agrees with evaluation and its pdf, the lobe's shape follows Cycles' mapping, and an
isotropic lobe is today's arithmetic."""
import numpy as np
import pytest

from drt_engine.core.base.vectors import Frame
from drt_engine.core.bsdf import layout
from drt_engine.core.bsdf.shader import MaterialShader, anisotropic_alphas
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(23)

CLOSURES = {
    "glossy+0.6": Closure("GLOSSY", color=(1, 1, 1), roughness=0.5, anisotropy=0.6, multiscatter=False),
    "glossy-0.8": Closure("GLOSSY", color=(1, 1, 1), roughness=0.6, anisotropy=-0.8, multiscatter=False),
    "metal+1": Closure("PRINCIPLED", color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.45, anisotropy=1.0),
}


def _view(mu, phi):
    s = np.sqrt(1 - mu * mu)
    return np.array([s * np.cos(phi), s * np.sin(phi), mu])


def _quadrature(n=500):
    """Midpoint rule over the upper hemisphere in (cos theta, phi): directions, solid angles."""
    z = (np.arange(n) + 0.5) / n
    phi = (np.arange(4 * n) + 0.5) * np.pi / (2 * n)
    z, phi = np.meshgrid(z, phi, indexing="ij")
    r = np.sqrt(1 - z * z)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).reshape(-1, 3)
    return wi, np.full(len(wi), 2 * np.pi / (4 * n * n))


@pytest.mark.parametrize("name", list(CLOSURES))
@pytest.mark.parametrize("mu, phi", [(0.9, 0.3), (0.4, 1.1), (0.15, 2.5)])
def test_sampling_agrees_with_evaluation_and_pdf(name, mu, phi):
    """The estimator mean(f |cos| / pdf) over sampled directions equals the quadrature of
    f |cos| that evaluate() gives; the pdf a sample reports is evaluate()'s pdf there; and the
    share of samples that stay above the surface is the quadrature of that pdf."""
    shader = MaterialShader(Material("m", [CLOSURES[name]]))
    assert shader.lp[0, layout.P_ANISO] == 1.0
    wo = _view(mu, phi)
    n = 200_000
    wos = np.tile(wo, (n, 1))
    wi, w, pdf, delta, ok, _ = shader.sample(wos, RNG.random(n), RNG.random((n, 2)), np.zeros(n, bool))
    estimate = (w * ok[:, None]).mean(axis=0)
    q, dw = _quadrature()
    m = len(q)
    f_d, f_nd, density = shader.evaluate(np.tile(wo, (m, 1)), q, np.ones(m, bool), np.zeros(m, bool))
    integral = ((f_d + f_nd) * dw[:, None]).sum(axis=0)
    assert estimate == pytest.approx(integral, rel=0.01)
    assert ok.mean() == pytest.approx((density * dw).sum(), abs=0.005)
    _, _, at_samples = shader.evaluate(wos[ok], wi[ok], np.ones(ok.sum(), bool), np.zeros(ok.sum(), bool))
    assert np.allclose(pdf[ok], at_samples, rtol=1e-9)


@pytest.mark.parametrize("kind, anisotropy", [("GLOSSY", 0.5), ("PRINCIPLED", 0.7), ("GLOSSY", -0.5)])
def test_highlight_is_narrow_along_the_smaller_alpha(kind, anisotropy):
    """Cycles' mapping: Glossy's positive anisotropy and Principled's Anisotropic make alpha_x
    (along the tangent) the smaller, so the highlight stretches across the tangent; Glossy's
    negative anisotropy the other way. Seen head-on: f a little off the mirror direction along
    the bitangent over f as far off along the tangent."""
    ax, ay = anisotropic_alphas(kind, 0.5, anisotropy)
    assert np.sqrt(ax * ay) == pytest.approx(0.25)
    shader = MaterialShader(Material("m", [Closure(kind, color=(1, 1, 1), roughness=0.5, metallic=1.0,
                                                   anisotropy=anisotropy, multiscatter=False)]))
    off = 0.3
    wi = np.array([[np.sin(off), 0, np.cos(off)], [0, np.sin(off), np.cos(off)]])
    f = shader.evaluate(np.tile([0.0, 0, 1], (2, 1)), wi, np.ones(2, bool), np.zeros(2, bool))[1][:, 0]
    assert (f[1] > 1.5 * f[0]) == (ax < ay)
    assert (f[0] > 1.5 * f[1]) == (ax > ay)


def test_isotropic_lobes_are_unchanged():
    """Below Cycles' threshold (|anisotropy| <= 1e-4) Glossy is isotropic and packs today's row,
    bit for bit; and the anisotropic arithmetic with alpha_x = alpha_y is the isotropic lobe's."""
    plain = MaterialShader(Material("m", [Closure("GLOSSY", roughness=0.4)]))
    tiny = MaterialShader(Material("m", [Closure("GLOSSY", roughness=0.4, anisotropy=1e-5)]))
    assert np.array_equal(plain.lp, tiny.lp) and plain.lp[0, layout.P_ANISO] == 0.0
    forced = MaterialShader(Material("m", [Closure("GLOSSY", roughness=0.4)]))
    forced.lp[0, layout.P_ANISO] = 1.0
    forced.lp[0, layout.P_ALPHA_X] = forced.lp[0, layout.P_ALPHA_Y] = forced.lp[0, layout.P_ALPHA]
    n = 2000
    wo = RNG.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = RNG.normal(size=(n, 3))
    wi[:, 2] = np.abs(wi[:, 2])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    up, out = np.ones(n, bool), np.zeros(n, bool)
    for a, b in zip(plain.evaluate(wo, wi, up, out), forced.evaluate(wo, wi, up, out)):
        assert np.allclose(a, b, rtol=1e-12, atol=0)
    u, u2 = RNG.random(n), RNG.random((n, 2))
    for a, b in zip(plain.sample(wo, u, u2, out), forced.sample(wo, u, u2, out)):
        assert np.allclose(a, b, rtol=1e-12, atol=0)


def test_frame_along_a_tangent():
    """Cycles' make_orthonormals_tangent: the tangent made perpendicular to the normal, a
    right-handed frame; a tangent along the normal (or zero) falls back to the plain frame."""
    n = np.array([[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [1.0, 0.0, 0.0]])
    t = np.array([[2.0, 0.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 0.0]])
    f = Frame.along(n, t)
    assert np.allclose(f.t[0], [1, 0, 0]) and np.allclose(f.b[0], [0, 1, 0])
    assert np.allclose(np.cross(f.t, f.b), n)
    assert np.allclose(np.einsum("ij,ij->i", f.t, n), 0)
    assert np.allclose(f.m[2], Frame.about(n[2:]).m[0])
