"""Sheen lobe (core.bsdf.sheen): the transformed cosine is a density (its white furnace is its
albedo from the paper's table, at most 1), sampling draws from the density the evaluation gives, and both stay
finite at grazing views and at roughness 0 and 1."""
import numpy as np
import pytest

from drt_engine.core.bsdf import mixture, sheen
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.bsdf.tables import locate
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(8)
ROUGHNESS = [0.0, 0.05, 0.3, 0.5, 1.0]
VIEWS = [1.0, 0.7, 0.3, 0.05, 1e-4]


def _shader(rough, colour=(1.0, 1.0, 1.0)):
    return MaterialShader(Material("sheen", [Closure("SHEEN", color=colour, roughness=rough)]))


def _wo(cos_o, phi=0.7):
    s = np.sqrt(1.0 - cos_o * cos_o)
    return np.array([s * np.cos(phi), s * np.sin(phi), cos_o])


def _eval(shader, wo, wi):
    j, t = locate(shader.mu, wo[2])
    return sheen.sheen_eval(shader.lp, shader.lt, shader.hp, 0, j, t, 0, *wo, *wi)


def _hemisphere(n):
    """Midpoint directions over the upper hemisphere, cos theta = u^2 (dense near the horizon, where
    the lobe of a grazing view is sharp), and the solid angle of each: 2 u du dphi."""
    k = int(np.sqrt(n))
    u = (np.arange(k) + 0.5) / k
    uu, phi = np.meshgrid(u, 2 * np.pi * u, indexing="ij")
    z = uu * uu
    s = np.sqrt(1.0 - z * z)
    d_omega = (2.0 * uu / k) * (2 * np.pi / k)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], -1).reshape(-1, 3), d_omega.reshape(-1)


@pytest.mark.parametrize("rough", ROUGHNESS)
@pytest.mark.parametrize("cos_o", VIEWS)
def test_white_furnace_is_the_albedo(rough, cos_o):
    """The integral of f |cos| over the hemisphere (white colour) is the lobe's albedo within 3%
    (the transform's density integrates to one up to its part below the horizon), and at most 1."""
    shader = _shader(rough)
    wo = _wo(cos_o)
    dirs, d_omega = _hemisphere(300 * 300)
    total = sum(_eval(shader, wo, w)[0] * d for w, d in zip(dirs, d_omega))
    albedo = float(sheen.sheen_albedo(sheen.sheen_rows(rough), cos_o))
    assert np.isfinite(total) and total <= 1.0 + 1e-6
    assert total == pytest.approx(albedo, rel=0.03, abs=2e-4)


@pytest.mark.parametrize("rough", [0.05, 0.3, 1.0])
@pytest.mark.parametrize("cos_o", [0.9, 0.4, 0.05])
def test_samples_follow_the_density(rough, cos_o):
    """Sampled directions (through the mixture, as with diffuse bounces on) fall in cells of the
    hemisphere as often as the evaluated density says (chi-like check per cell), and each sample's
    pdf and weight are the evaluation's toward it."""
    shader = _shader(rough)
    wo = _wo(cos_o)
    n = 40000
    sel = np.empty((1, len(shader.lobes)))
    mixture.selection(shader.lp, shader.lt, shader.hp, 0, shader.mu, wo[2], sel, 0, True)
    u = RNG.random((n, 3))
    wi = np.zeros((n, 3))
    for i in range(n):
        s = mixture.sample_lobes(shader.lp, shader.lt, shader.hp, 0, shader.mu, *wo, *u[i], False, sel, 0,
                                 True, 0.0, 0.0, 1.0, 0, 0.0, 0.0, 1.0)
        wi[i] = s[0:3]
        if s[8]:
            f, _, _, p = _eval(shader, wo, wi[i])
            assert s[6] == pytest.approx(p, rel=1e-9)
            assert s[3] == pytest.approx(f / p, rel=1e-9)
            assert s[10] and not s[7]
    # histogram over (cos theta, phi) cells against the integrated density
    bins = 8
    z_edges = np.linspace(0, 1, bins + 1)
    phi_edges = np.linspace(-np.pi, np.pi, bins + 1)
    keep = wi[:, 2] > 0
    counts, _, _ = np.histogram2d(wi[keep, 2], np.arctan2(wi[keep, 1], wi[keep, 0]), [z_edges, phi_edges])
    dirs, d_omega = _hemisphere(240 * 240)
    dens = np.array([_eval(shader, wo, w)[3] for w in dirs]) * d_omega
    expected, _, _ = np.histogram2d(dirs[:, 2], np.arctan2(dirs[:, 1], dirs[:, 0]), [z_edges, phi_edges],
                                    weights=dens)
    expected *= n
    big = expected > 200
    assert np.all(np.abs(counts[big] - expected[big]) < 5 * np.sqrt(expected[big]) + 0.02 * expected[big])


@pytest.mark.parametrize("rough", [0.0, 1.0])
def test_finite_at_grazing_and_extremes(rough):
    """Finite, non-negative values and densities at grazing views and directions, roughness 0 and 1."""
    shader = _shader(rough)
    for cos_o in (1e-6, 1e-3, 1.0):
        wo = _wo(cos_o)
        for wi in (_wo(1e-6, 2.0), _wo(0.5, 3.0), _wo(1.0), -_wo(0.5)):
            f0, f1, f2, p = _eval(shader, wo, wi)
            assert np.all(np.isfinite([f0, f1, f2, p])) and min(f0, p) >= 0.0
        x, y, z = sheen.sheen_sample(shader.lp, 0, *wo, 0.3, 0.9)
        assert np.all(np.isfinite([x, y, z])) and abs(x * x + y * y + z * z - 1.0) < 1e-9


def test_colour_and_albedo_in_the_passes():
    """DiffCol is the colour times the albedo at the view (the sheen counts as diffuse, as in Cycles)."""
    shader = _shader(0.5, colour=(0.8, 0.4, 0.2))
    diff, gloss = shader.colors(np.array([0.6]))
    albedo = float(sheen.sheen_albedo(sheen.sheen_rows(0.5), 0.6))
    assert diff[0] == pytest.approx(np.array([0.8, 0.4, 0.2]) * albedo, rel=5e-3)  # the table interpolates
    assert np.all(gloss == 0.0)


@pytest.mark.parametrize("coat", [0.0, 1.0])
def test_principled_sheen_layers_over_the_rest(coat):
    """Principled's sheen is the top layer (Cycles' closure.h): its weight Sheen Weight x tint, and
    every lobe below (the coat too) weighed by 1 - Sheen Weight x max(tint) x albedo(mu) on top of
    what it had without the sheen; with Sheen Weight 0 nothing changes."""
    tint = np.array([1.0, 0.6, 0.8])
    base = dict(color=(0.05, 0.03, 0.02), roughness=0.5, coat_weight=coat, coat_roughness=0.2)
    plain = MaterialShader(Material("plain", [Closure("PRINCIPLED", **base)]))
    none = MaterialShader(Material("none", [Closure("PRINCIPLED", sheen_weight=0.0, **base)]))
    sheened = MaterialShader(Material("sheen", [Closure("PRINCIPLED", sheen_weight=0.7, sheen_roughness=0.4,
                                                        sheen_tint=tint, **base)]))
    mu = np.array([0.9, 0.5, 0.1])
    assert np.array_equal(none.lp, plain.lp) and np.array_equal(none.lt, plain.lt)
    assert sheened.lobes[0].kind == "sheen"
    w_plain, w_sheen = plain.lobe_weights(mu), sheened.lobe_weights(mu)
    np.testing.assert_allclose(w_sheen[:, 0], 0.7 * tint * np.ones((3, 1)))
    albedo = sheen.sheen_albedo(sheen.sheen_rows(0.4), mu)
    under = 1.0 - 0.7 * tint.max() * albedo
    np.testing.assert_allclose(w_sheen[:, 1:], w_plain * under[:, None, None], rtol=5e-3)
