"""Lobe kernels: the table lookup, per-hit parameter rows, and the scalar per-ray functions."""
import numpy as np
import pytest

from drt_engine.core.bsdf import microfacet as mf
from drt_engine.core.bsdf import bump_shadowing, mixture, tables
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(5)


def test_table_lookup_is_linear_interpolation():
    """``locate`` finds the cell from MU_TABLE's spacings; with ``at`` it is np.interp, also at
    the table's own points, next to them and beyond its ends."""
    mu = mf.MU_TABLE
    xs = np.concatenate([mu, np.nextafter(mu, 0), np.nextafter(mu, 2), RNG.random(20_000),
                         np.geomspace(1e-7, 1, 2000), [0.0, 1.0, 1.5, -0.5]])
    values = np.sin(7 * mu) + mu
    lt = values[None, None, :]
    got = np.array([tables.at(lt, 0, 0, *tables.locate(mu, x)) for x in xs])
    assert np.allclose(got, np.interp(xs, mu, values), rtol=0, atol=1e-14)


def _rays(n):
    mu = RNG.uniform(0.05, 1, n)
    phi = RNG.uniform(0, 2 * np.pi, n)
    wo = np.stack([np.sqrt(1 - mu**2) * np.cos(phi), np.sqrt(1 - mu**2) * np.sin(phi), mu], 1)
    wi = RNG.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    return wo, wi


@pytest.mark.parametrize("kind", ["metal", "glossy", "plastic", "glass", "oren-nayar", "translucent"])
def test_bound_rows_equal_shaders_built_with_their_colour(kind):
    """A shader bound to per-hit colours and weights (one parameter row per hit) evaluates and
    samples each hit as a shader built with that hit's colour and weight does. (A per-hit metal
    or glossy colour forms its multiple-scattering factor from interpolated albedo parts, where a
    constant one interpolates the factor itself: they differ by up to 2e-4 between table points near grazing.)"""
    def closure(color, weight=np.ones(3)):
        if kind == "metal":
            return Closure("PRINCIPLED", color=color, weight=weight, metallic=1.0, roughness=0.4,
                           specular_tint=(0.9, 0.8, 1.0))
        if kind == "glossy":
            return Closure("GLOSSY", color=color, weight=weight, roughness=0.3)
        if kind == "glass":
            return Closure("PRINCIPLED", color=color, weight=weight, roughness=0.3, transmission=1.0)
        if kind == "oren-nayar":  # its multiple scattering is not linear in the colour
            return Closure("PRINCIPLED", color=color, weight=weight, roughness=0.5, diffuse_roughness=0.8)
        if kind == "translucent":
            return Closure("TRANSLUCENT", color=color, weight=weight)
        return Closure("PRINCIPLED", color=color, weight=weight, roughness=0.5, coat_weight=0.5)

    n = 3000
    colours = RNG.uniform(0.1, 1.0, (3, 3))
    weights = RNG.uniform(0.2, 1.0, (3, 3))
    which = RNG.integers(0, 3, n)
    varying = {0: ("weight", "color")}
    bound = MaterialShader(Material("m", [closure(np.ones(3))]), varying).bind(
        {0: {"weight": weights[which], "color": colours[which]}})
    wo, wi = _rays(n)
    above = RNG.random(n) < 0.8
    inside = np.zeros(n, bool)
    u_sel, u2 = RNG.random(n), RNG.random((n, 2))
    ev = bound.evaluate(wo, wi, above, inside)
    sa = bound.sample(wo, u_sel, u2, inside)
    for k in range(3):
        rows = np.flatnonzero(which == k)
        plain = MaterialShader(Material("m", [closure(colours[k], weights[k])]))
        ev_k = plain.evaluate(wo[rows], wi[rows], above[rows], inside[rows])
        sa_k = plain.sample(wo[rows], u_sel[rows], u2[rows], inside[rows])
        for a, b in zip(ev + sa, ev_k + sa_k):
            assert np.allclose(a[rows], b, rtol=1e-3, atol=1e-12)


def test_scalar_functions_give_the_batch_results():
    """What a fused kernel calls per ray (``selection``, ``eval_lobes``, ``sample_lobes``) gives
    the very numbers of the shader's batch methods."""
    shader = MaterialShader(Material("m", [Closure("PRINCIPLED", color=(0.7, 0.4, 0.2), roughness=0.4,
                                                   coat_weight=0.6, coat_roughness=0.2)]))
    n = 50
    wo, wi = _rays(n)
    above, inside = wi[:, 2] > 0, np.zeros(n, bool)
    u_sel, u2 = RNG.random(n), RNG.random((n, 2))
    f_diff, f_nd, pdf = shader.evaluate(wo, wi, above, inside)
    sampled = shader.sample(wo, u_sel, u2, inside)
    sel = np.zeros((1, len(shader.sampled)))
    for i in range(n):
        mixture.selection(shader.lp, shader.lt, shader.hp, 0, shader.mu, wo[i, 2], sel, 0, False)
        e = mixture.eval_lobes(shader.lp, shader.lt, shader.hp, 0, shader.mu, *wo[i], *wi[i], above[i], inside[i],
                               sel, 0, False, 0, *NO_BUMP, -1)
        assert np.array_equal(e, [*f_diff[i], *f_nd[i], pdf[i]])
        s = mixture.sample_lobes(shader.lp, shader.lt, shader.hp, 0, shader.mu, *wo[i], u_sel[i], *u2[i], inside[i],
                                 sel, 0, False, *NO_BUMP)
        assert np.array_equal(s[:7], [*sampled[0][i], *sampled[1][i], sampled[2][i]])
        assert s[7:10] == tuple(bool(x[i]) for x in sampled[3:])
        assert not s[10]  # no diffuse lobe without the diffuse flag


GI_MATERIALS = {
    "principled": [Closure("PRINCIPLED", color=(0.7, 0.4, 0.2), roughness=0.4)],
    "diffuse and glossy": [Closure("DIFFUSE", weight=np.full(3, 0.5), color=(0.8, 0.8, 0.8)),
                           Closure("GLOSSY", weight=np.full(3, 0.5), color=(0.9, 0.9, 0.9), roughness=0.5)],
    "translucent and diffuse": [Closure("TRANSLUCENT", weight=np.full(3, 0.5), color=(0.6, 0.6, 0.6)),
                                Closure("DIFFUSE", weight=np.full(3, 0.5), color=(0.8, 0.8, 0.8))],
}


FRAME_NORMAL = (0.0, 0.0, 1.0)  # the diffuse lobes' normal where it is the frame's
NO_BUMP = (0.0, 0.0, 1.0, 0, *FRAME_NORMAL)
BUMPED = (-np.sin(0.5), 0.0, np.cos(0.5), bump_shadowing.GGX, *FRAME_NORMAL)  # smooth normal 0.5 rad off, Cycles 5's
# a silhouette's rim: the diffuse lobes' normal 1 rad off the frame's, wo (below) below it (core.bsdf.diffuse_normal)
RIM = (0.0, 0.0, 1.0, 0, -np.sin(1.0), 0.0, np.cos(1.0))
BUMPED_RIM = (-np.sin(0.5), 0.0, np.cos(0.5), bump_shadowing.GGX, -np.sin(1.0), 0.0, np.cos(1.0))


@pytest.mark.parametrize("bump", [NO_BUMP, BUMPED, RIM, BUMPED_RIM], ids=["smooth", "bumped", "rim", "bumped rim"])
@pytest.mark.parametrize("name", list(GI_MATERIALS))
def test_sampling_with_diffuse_lobes_integrates_the_whole_bsdf(name, bump):
    """With diffuse bounces (the mixture's diffuse flag), a ray continues through any lobe, the
    diffuse ones cosine-weighted, weighted by the whole mixture's f / pdf: its mean weight is
    the BSDF's albedo, the integral of f |cos| over the sphere that uniform directions give.
    A pdf that is not the sampler's density (a lobe's share or its cosine left out) fails; with a
    bump, sampling weighs by the same bump shadowing as evaluation; at a rim the diffuse lobes are
    sampled and evaluated about their own normal alike."""
    shader = MaterialShader(Material("m", GI_MATERIALS[name]))
    diffuse = True
    args = (shader.lp, shader.lt, shader.hp, 0, shader.mu)
    wo = np.array([np.sqrt(1 - 0.6 ** 2), 0.0, 0.6])
    sel = np.zeros((1, len(shader.lobes)))
    mixture.selection(*args, wo[2], sel, 0, diffuse)
    n = 40_000
    rng = np.random.default_rng(7)
    u = rng.random((n, 3))
    sampled = np.zeros(3)
    diffuse_taken = 0
    for i in range(n):
        s = mixture.sample_lobes(*args, *wo, u[i, 0], u[i, 1], u[i, 2], False, sel, 0, diffuse, *bump)
        if s[8]:
            sampled += s[3:6]
            e = mixture.eval_lobes(*args, *wo, *s[:3], s[2] > 0, False, sel, 0, diffuse, 0, *bump, -1)
            assert e[6] == pytest.approx(s[6], rel=1e-9) and not any(e[:3])  # every lobe is sampled
        diffuse_taken += s[10]
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    uniform = np.zeros(3)
    for i in range(n):
        e = mixture.eval_lobes(*args, *wo, *wi[i], wi[i, 2] > 0, False, sel, 0, diffuse, 0, *bump, -1)
        uniform += np.add(e[:3], e[3:6])
    assert diffuse_taken > 0 and (diffuse_taken < n or all(lobe.diffuse for lobe in shader.lobes))
    np.testing.assert_allclose(sampled / n, uniform * 4 * np.pi / n, rtol=0.03)
