"""Toon lobes (core.bsdf.toon): sampling and evaluation agree, directions stay in their cone, the
density integrates to one over it, and the intensity is Cycles' (bsdf_toon.h)."""
import numpy as np
import pytest

from drt_engine.core.bsdf import mixture
from drt_engine.core.bsdf.shader import MaterialShader, toon_angles
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(23)
COLOUR = np.array([0.9, 0.5, 0.2])


def _shader(kind, size, smooth):
    return MaterialShader(Material("toon", [Closure(kind, color=COLOUR, toon_size=size, toon_smooth=smooth)]))


def _intensity(angle, size, smooth):
    """Cycles' bsdf_toon_get_intensity over angles (radians), size and smooth as the node's 0..1."""
    a, s = toon_angles(size, smooth)
    fall = np.clip(1.0 - (angle - a) / max(s, 1e-300), 0.0, 1.0) if s > 0 else 0.0
    return np.where(angle < a, 1.0, fall)


def _cone(size, smooth):
    a, s = toon_angles(size, smooth)
    return min(a + s, np.pi / 2)


def _cone_pdf(size, smooth):
    """The cone's uniform density 1 / (2 pi (1 - cos)), without 1 - cos's cancellation at small angles."""
    return 1.0 / (4 * np.pi * np.sin(_cone(size, smooth) / 2) ** 2)


def _view(n, max_angle=1.2):
    t = RNG.uniform(0.0, max_angle, n)
    phi = RNG.uniform(0, 2 * np.pi, n)
    return np.stack([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)], 1)


def _axis(kind, wo):
    """The cone's axis: the normal (diffuse) or wo mirrored in it (glossy)."""
    if kind == "DIFFUSE_TOON":
        return np.broadcast_to([0.0, 0.0, 1.0], wo.shape)
    return wo * [-1.0, -1.0, 1.0]


def _sample(shader, kind, wo):
    """Sample through the mixture (the diffuse toon as with diffuse bounces on): (wi, weight, pdf, valid)."""
    n = len(wo)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n), np.zeros(n, bool)
    diffuse = kind == "DIFFUSE_TOON"
    sel = np.empty((1, len(shader.lobes) if diffuse else len(shader.sampled)))
    u = RNG.random((n, 3))
    for i in range(n):
        mixture.selection(shader.lp, shader.lt, shader.hp, 0, shader.mu, wo[i, 2], sel, 0, diffuse)
        s = mixture.sample_lobes(shader.lp, shader.lt, shader.hp, 0, shader.mu, *wo[i], *u[i], False, sel, 0, diffuse,
                                 0.0, 0.0, 1.0, 0, 0.0, 0.0, 1.0)
        out[0][i], out[1][i], out[2][i], out[3][i] = s[0:3], s[3:6], s[6], s[8]
        assert not s[7] and s[10] == (kind == "DIFFUSE_TOON")  # neither is a delta; the diffuse one is diffuse
    return out


@pytest.mark.parametrize("kind", ["DIFFUSE_TOON", "GLOSSY_TOON"])
@pytest.mark.parametrize("size, smooth", [(0.5, 0.0), (0.2, 0.3), (0.8, 0.6), (0.0, 0.0)])
def test_sampling_and_evaluation_agree(kind, size, smooth):
    """Sampled directions lie in the cone of half-angle min(size + smooth, 90 degrees) about the
    lobe's axis; each sample's weight is the colour times Cycles' intensity at its angle, and its
    pdf and value are the evaluation's toward it (weight = f |cos| / pdf)."""
    shader = _shader(kind, size, smooth)
    wo = _view(2000, 0.3 if kind == "GLOSSY_TOON" else 1.2)
    wi, weight, pdf, valid = _sample(shader, kind, wo)
    angle = np.arccos(np.clip(np.sum(wi * _axis(kind, wo), 1), -1, 1))
    assert valid.mean() > 0.95
    assert np.all(angle[valid] <= _cone(size, smooth) + 1e-9)
    np.testing.assert_allclose(pdf[valid], _cone_pdf(size, smooth), rtol=1e-9)
    expected = COLOUR * _intensity(angle, size, smooth)[:, None]
    np.testing.assert_allclose(weight[valid], expected[valid], rtol=1e-6, atol=1e-9)
    ev = shader.evaluate(wo[valid], wi[valid], np.ones(valid.sum(), bool), np.zeros(valid.sum(), bool),
                         sel=np.ones((valid.sum(), len(shader.sampled))))
    value = ev.diffuse if kind == "DIFFUSE_TOON" else ev.glossy
    np.testing.assert_allclose(value, weight[valid] * pdf[valid, None], rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("kind", ["DIFFUSE_TOON", "GLOSSY_TOON"])
@pytest.mark.parametrize("size, smooth", [(0.5, 0.0), (0.2, 0.3), (0.9, 0.4)])
def test_density_integrates_to_one_and_the_value_to_the_mean_intensity(kind, size, smooth):
    """Over the hemisphere (quadrature in theta and phi about the normal, wo at the normal so the
    glossy cone is the diffuse one) the density integrates to 1 and f |cos| to the colour times
    the intensity's mean over the cone: the lobe is the cone's uniform density times the intensity."""
    shader = _shader(kind, size, smooth)
    nt, nphi = 4000, 16
    theta = (np.arange(nt) + 0.5) * (np.pi / 2) / nt
    phi = (np.arange(nphi) + 0.5) * 2 * np.pi / nphi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    wi = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    d_omega = (np.sin(t) * (np.pi / 2 / nt) * (2 * np.pi / nphi)).reshape(-1)
    wo = np.broadcast_to([0.0, 0.0, 1.0], wi.shape).copy()
    n = len(wi)
    ev = shader.evaluate(wo, wi, np.ones(n, bool), np.zeros(n, bool), sel=np.ones((n, len(shader.sampled))))
    value = ev.diffuse if kind == "DIFFUSE_TOON" else ev.glossy
    cone = _cone(size, smooth)
    pdf = np.where(t.reshape(-1) < cone, _cone_pdf(size, smooth), 0.0)
    if kind == "GLOSSY_TOON":  # the mixture's density is the glossy lobe's
        np.testing.assert_allclose(ev.pdf, pdf, rtol=1e-9, atol=1e-12)
    assert np.sum(pdf * d_omega) == pytest.approx(1.0, abs=2e-3)
    inside = np.sin(theta) * (theta < cone)
    mean = np.sum(_intensity(theta, size, smooth) * inside) / np.sum(inside)
    np.testing.assert_allclose(np.sum(value * d_omega[:, None], 0), COLOUR * mean, rtol=3e-3)


def test_glossy_toon_reflects_nothing_below_the_surface_and_the_diffuse_one_nothing_behind():
    """No value toward directions under the shading normal (Cycles' cosNI, cosNO > 0)."""
    for kind in ("DIFFUSE_TOON", "GLOSSY_TOON"):
        shader = _shader(kind, 1.0, 1.0)
        wo = _view(500)
        wi = _view(500) * [1.0, 1.0, -1.0]
        ev = shader.evaluate(wo, wi, np.ones(500, bool), np.zeros(500, bool))
        assert not np.any(ev.diffuse) and not np.any(ev.glossy)


def test_size_and_smooth_are_clamped_as_cycles_sets_them():
    """Size to [1e-5, 1] and Smooth to [0, 1], times pi / 2 (bsdf_toon_setup_common)."""
    assert toon_angles(0.0, -1.0) == pytest.approx((1e-5 * np.pi / 2, 0.0))
    assert toon_angles(3.0, 2.0) == pytest.approx((np.pi / 2, np.pi / 2))
    assert toon_angles(0.5, 0.25) == pytest.approx((np.pi / 4, np.pi / 8))


def test_pass_colours_take_the_toon_colour_on_its_side():
    """DiffCol takes the diffuse toon's colour and GlossCol the glossy toon's (Cycles' albedo of a
    closure without tables is its weight); both count as diffuse-like for the denoising albedo
    (roughness 1 for a closure that is not microfacet)."""
    mu = np.array([0.2, 0.7, 1.0])
    for kind, side in (("DIFFUSE_TOON", 0), ("GLOSSY_TOON", 1)):
        shader = _shader(kind, 0.4, 0.2)
        colours = shader.colors(mu)
        np.testing.assert_allclose(colours[side], np.broadcast_to(COLOUR, (3, 3)))
        assert not np.any(colours[1 - side])
        diffuse_like, specular_like, take = shader.denoising_albedos(mu, np.zeros(3, bool))
        np.testing.assert_allclose(diffuse_like, np.broadcast_to(COLOUR, (3, 3)))
        assert not np.any(specular_like) and np.all(take)
