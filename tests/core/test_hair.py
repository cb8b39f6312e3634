"""Hair lobes in the mixture (core.bsdf.hair, hair_lobes): a bound shader takes each hit's strand into
its local frame, sampling and evaluation agree, samples land where the evaluated density says, the
Hair BSDF's value is Cycles' (bsdf_hair.h) and its colour the weight, each component on its side."""
import numpy as np
import pytest

from drt_engine.core.bsdf import layout
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(7)
COLOUR = np.array([0.9, 0.5, 0.2])
STRAND = np.array([0.6, 0.8, 0.0])  # in the surface's plane, as a triangle's edge is


def _bound(closure, n, cycles="GGX", wo=None):
    """The shader of one hair closure bound to n hits whose local frame is the world's, strand STRAND,
    seen from ``wo`` (n, 3; default the normal), in a material of this Cycles' bump shadowing ("GGX":
    5.x, "CHIANG": 4.x)."""
    shader = MaterialShader(Material("hair", [closure], bump_shadowing=cycles))
    bound = shader.bind({0: {"hair_tangent": np.tile(STRAND * 2.5, (n, 1))}})
    z = np.tile([0.0, 0.0, 1.0], (n, 1))
    return bound.turn_hair(lambda v: v, z, z, z if wo is None else wo)


def _hair(kind, u=0.4, v=1.0):
    return Closure(kind, color=COLOUR, roughness=u, hair_roughness_v=v)


def _uniform_sphere(n):
    z = RNG.uniform(-1, 1, n)
    phi = RNG.uniform(0, 2 * np.pi, n)
    s = np.sqrt(1 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], 1)


def _view(n):
    wo = _uniform_sphere(n)
    wo[:, 2] = np.abs(wo[:, 2]) + 0.05
    return wo / np.linalg.norm(wo, axis=1)[:, None]


def test_the_strand_is_unit_and_local_after_turning():
    bound = _bound(_hair("HAIR_REFLECTION"), 3)
    np.testing.assert_allclose(bound.hp[:, 0, layout.H_HAIR:layout.H_HAIR + 3], np.tile(STRAND, (3, 1)))


@pytest.mark.parametrize("kind", ["HAIR_REFLECTION", "HAIR_TRANSMISSION"])
@pytest.mark.parametrize("v", [1.0, 0.3])
def test_sampling_agrees_with_evaluation(kind, v):
    """Every sample weighs the colour (f |cos| is the density), on whichever side of the surface it
    leaves, as Cycles continues it; where evaluation sees it (the component's side, and for
    reflection the view's side of the strand) its density is the evaluated one."""
    n = 400
    shader = _bound(_hair(kind, 0.3, v), n)
    wo = _view(n)
    s = shader.sample(wo, RNG.random(n), RNG.random((n, 2)), np.zeros(n, bool))
    ok = s.valid
    assert ok.mean() > 0.9
    np.testing.assert_allclose(s.weight[ok], np.tile(COLOUR, (ok.sum(), 1)), rtol=1e-9)
    ev = shader.evaluate(wo[ok], s.wi_l[ok], s.wi_l[ok, 2] >= 0, np.zeros(ok.sum(), bool), rows=np.flatnonzero(ok))
    seen = ev.pdf > 0
    assert seen.mean() > 0.5
    np.testing.assert_allclose(ev.pdf[seen], s.pdf[ok][seen], rtol=1e-9)
    np.testing.assert_allclose(ev.glossy[seen], s.pdf[ok][seen, None] * COLOUR, rtol=1e-9)
    wrong_side = (s.wi_l[ok, 2] < 0) != (kind == "HAIR_TRANSMISSION")
    assert not np.any(seen & wrong_side)


@pytest.mark.parametrize("kind", ["HAIR_REFLECTION", "HAIR_TRANSMISSION"])
def test_samples_land_where_the_density_says(kind):
    """The share of samples falling in a region equals the evaluated density integrated over it
    (uniform sphere estimate): fails if sampling and evaluation describe different lobes."""
    wo = np.array([0.3, -0.2, 0.93])
    wo /= np.linalg.norm(wo)
    n = 40000
    shader = _bound(_hair(kind, 0.3, 0.3), n)  # RoughnessV 0.3: reflection stays on the view's side of the strand
    s = shader.sample(np.tile(wo, (n, 1)), RNG.random(n), RNG.random((n, 2)), np.zeros(n, bool))
    side = -1.0 if kind == "HAIR_TRANSMISSION" else 1.0
    region = lambda d: (d[:, 0] > 0.0) & (side * d[:, 2] > 0.2)  # noqa: E731
    share = np.mean(s.valid & region(s.wi_l))
    d = _uniform_sphere(n)
    ev = shader.evaluate(np.tile(wo, (n, 1)), d, d[:, 2] >= 0, np.zeros(n, bool))
    integral = np.mean(np.where(region(d), ev.pdf, 0.0)) * 4 * np.pi
    assert share > 0.05
    assert share == pytest.approx(integral, rel=0.06)


def test_reflection_matches_cycles_formula():
    """bsdf_hair_reflection_eval at one direction pair, written out from the source."""
    u, v = 0.35, 0.7
    wo = np.array([0.2, 0.1, 0.97])
    wo /= np.linalg.norm(wo)
    wi = np.array([0.5, 0.3, 0.81])
    wi /= np.linalg.norm(wi)
    shader = _bound(_hair("HAIR_REFLECTION", u, v), 1)
    got = shader.evaluate(wo[None], wi[None], np.array([True]), np.array([False])).pdf[0]

    t = STRAND
    iz = t @ wo
    locy = (wo - t * iz) / np.linalg.norm(wo - t * iz)
    theta_r = np.pi / 2 - np.arccos(iz)
    oz = t @ wi
    oy = (wi - t * oz) / np.linalg.norm(wi - t * oz)
    theta_i = np.pi / 2 - np.arccos(oz)
    phi_i = min(np.arccos(oy @ locy) / v, np.pi)
    a = np.arctan(((np.pi / 2 + theta_r) * 0.5) / u)
    b = np.arctan(((-np.pi / 2 + theta_r) * 0.5) / u)
    h = (theta_i + theta_r) * 0.5
    want = np.cos(phi_i * 0.5) * 0.25 / v * u / (2 * (h * h + u * u) * (a - b) * np.cos(theta_i))
    assert got == pytest.approx(want, rel=1e-9)


def test_each_component_lights_its_own_side_only():
    wo = np.array([[0.0, 0.3, 0.95]])
    below = np.array([[0.1, -0.2, -0.97]])
    above = np.array([[0.1, 0.4, 0.91]])
    refl, trans = _bound(_hair("HAIR_REFLECTION"), 1), _bound(_hair("HAIR_TRANSMISSION"), 1)
    inside = np.array([False])
    assert refl.evaluate(wo, below, np.array([False]), inside).pdf[0] == 0.0
    assert trans.evaluate(wo, above, np.array([True]), inside).pdf[0] == 0.0
    assert refl.evaluate(wo, above, np.array([True]), inside).pdf[0] > 0.0
    assert trans.evaluate(wo, below, np.array([False]), inside).pdf[0] > 0.0


def test_degenerate_strands_give_nothing_finite():
    """A zero edge (a degenerate triangle) or a view along the strand: no NaN, no light."""
    shader = MaterialShader(Material("hair", [_hair("HAIR_REFLECTION")]))
    z = np.array([[0.0, 0.0, 1.0]])
    bound = shader.bind({0: {"hair_tangent": np.zeros((1, 3))}}).turn_hair(lambda v: v, z, z, z)
    ev = bound.evaluate(z, np.array([[0.3, 0.0, 0.95]]), np.array([True]), np.array([False]))
    assert np.all(np.isfinite(ev.glossy)) and np.all(np.isfinite(ev.pdf))
    along = _bound(_hair("HAIR_REFLECTION"), 1)
    ev = along.evaluate(np.array([STRAND]), np.array([[0.3, 0.0, 0.95]]), np.array([True]), np.array([False]))
    assert np.all(np.isfinite(ev.glossy)) and ev.pdf[0] == 0.0


def _principled(model, wo, cycles="GGX"):
    """A Principled Hair shader bound to hits seen from each row of ``wo``: strand STRAND, geometric and
    shading normal z."""
    closure = Closure("PRINCIPLED_HAIR", hair_model=model, hair_parametrization="MELANIN", melanin=0.4,
                      roughness=0.3, radial_roughness=0.4)
    return _bound(closure, len(wo), cycles, wo)


@pytest.mark.parametrize("model", ["CHIANG", "HUANG"])
def test_principled_hair_frames_are_its_models(model):
    """turn_hair fills each model's per-hit frame: Chiang's Y and h, Huang's tangent, X and h, then the
    shading normal."""
    from drt_engine.core.bsdf import hair_chiang, hair_huang
    wo = _view(1)
    shader = _principled(model, wo)
    got = shader.hp[0, 0, layout.H_HAIR:layout.H_HAIR + 10]
    z = (0.0, 0.0, 1.0)
    if model == "CHIANG":
        want = (*STRAND, *hair_chiang.chiang_frame(*STRAND, *z, *wo[0]), *z)
    else:
        want = (*hair_huang.huang_frame(*STRAND, *z, *wo[0]), *z)
    np.testing.assert_allclose(got, want, atol=1e-12)


@pytest.mark.parametrize("cycles", ["CHIANG", "GGX"])
def test_chiang_samples_weigh_as_it_evaluates_but_where_cycles_5_cuts_its_light(cycles):
    """Through the mixture a Chiang sample's weight is its F / pdf, which evaluation repeats, but
    Cycles 5 evaluates nothing where the light lies across the surface from the closure's normal Y
    (bump_shadowing_term; its samples keep their weight); Cycles 4 cuts none."""
    n = 400
    wo = _view(n)
    shader = _principled("CHIANG", wo, cycles)
    s = shader.sample(wo, RNG.random(n), RNG.random((n, 2)), np.zeros(n, bool))
    ok = s.valid
    assert ok.mean() > 0.9
    ev = shader.evaluate(wo[ok], s.wi_l[ok], s.wi_l[ok, 2] >= 0, np.zeros(ok.sum(), bool), rows=np.flatnonzero(ok))
    kept = ev.pdf > 0
    assert (kept.mean() == 1.0) if cycles == "CHIANG" else (0.05 < kept.mean() < 0.95)
    np.testing.assert_allclose(ev.pdf[kept], s.pdf[ok][kept], rtol=1e-9)
    np.testing.assert_allclose(ev.glossy[kept] / ev.pdf[kept, None], s.weight[ok][kept], rtol=1e-9)
    assert np.all(s.weight[ok][~kept].max(axis=1) > 0)


def test_huang_samples_keep_their_own_path_weight():
    """Cycles weighs a sampled Huang path by the sample's own estimate (its eval is a quadrature
    that differs pointwise): the mixture's weight is huang_sample's with the same numbers."""
    from drt_engine.core.bsdf import hair_huang
    n = 200
    wo = _view(n)
    shader = _principled("HUANG", wo)
    u_select, u2 = RNG.random(n), RNG.random((n, 2))
    s = shader.sample(wo, u_select, u2, np.zeros(n, bool))
    lp, hp = shader.lp[0], shader.hp
    c = lp[layout.P_HAIR:layout.P_HAIR + 7]
    checked = 0
    for i in range(n):
        frame = hp[i, 0, layout.H_HAIR:layout.H_HAIR + 6]
        sigma = hp[i, 0, layout.H_SIGMA:layout.H_SIGMA + 3]
        wix, wiy, wiz, f0, f1, f2, pdf, _ = hair_huang.huang_sample(*c, *sigma, *frame, *wo[i], *u2[i], u_select[i])
        if not s.valid[i]:
            continue
        np.testing.assert_allclose(s.wi_l[i], (wix, wiy, wiz), atol=1e-12)
        np.testing.assert_allclose(s.weight[i], (f0, f1, f2), rtol=1e-9)
        checked += 1
    assert checked > n // 2


@pytest.mark.parametrize("model", ["CHIANG", "HUANG"])
def test_principled_hair_passes_show_cycles_albedo_estimate(model):
    """GlossCol and the denoising albedo of Principled Hair are its weight times Cycles' bsdf_albedo
    estimate at the hit (Chiang's exp(-sqrt(sigma) scale(v)) + Fresnel, Huang's series), not the
    weight alone; the Hair BSDF's are its colour."""
    from drt_engine.core.bsdf import hair_chiang, hair_huang
    n = 5
    wo = _view(n)
    shader = _principled(model, wo)
    lp, hp = shader.lp[0], shader.hp
    want = np.empty((n, 3))
    for i in range(n):
        sigma, frame = hp[i, 0, layout.H_SIGMA:layout.H_SIGMA + 3], hp[i, 0, layout.H_HAIR:layout.H_HAIR + 7]
        if model == "CHIANG":
            want[i] = hair_chiang.chiang_albedo(lp[layout.P_HAIR], lp[layout.P_HAIR + 4], *sigma, frame[6], *STRAND,
                                                *wo[i])
        else:
            want[i] = hair_huang.huang_albedo(lp[layout.P_HAIR + 2], *sigma, *frame, *wo[i])
    assert np.all((want > 0.01) & (want < 0.99))
    diffuse, glossy = shader.colors(wo[:, 2])
    np.testing.assert_allclose(glossy, want, rtol=1e-12)
    assert np.all(diffuse == 0.0)
    d, s, take = shader.denoising_albedos(wo[:, 2], np.zeros(n, bool))
    np.testing.assert_allclose(d, want, rtol=1e-12)  # hair counts as rough: the diffuse-like side
    assert np.all(s == 0.0) and np.all(take)
    _, glossy = _bound(_hair("HAIR_REFLECTION"), n, wo=wo).colors(wo[:, 2])
    np.testing.assert_allclose(glossy, np.tile(COLOUR, (n, 1)))


@pytest.mark.parametrize("model", ["CHIANG", "HUANG"])
def test_filter_glossy_raises_principled_hair_roughness(model):
    """After a blurry bounce Cycles raises Chiang's v, s and m0 and Huang's roughness to the blur
    (bsdf_hair_*_blur): the blurred shader evaluates as its model with those raised; no blur leaves it
    as it was; the Hair BSDF is not blurred."""
    from drt_engine.core.bsdf import hair_chiang, hair_huang
    n = 64
    wo, wi = _view(n), _uniform_sphere(n)
    shader = _principled(model, wo)
    assert shader.blurs and not _bound(_hair("HAIR_REFLECTION"), 1).blurs
    above, inside = wi[:, 2] >= 0, np.zeros(n, bool)
    plain = shader.evaluate(wo, wi, above, inside)
    same = shader.blurred(np.zeros(n)).evaluate(wo, wi, above, inside)
    np.testing.assert_array_equal(same.glossy, plain.glossy)
    blur = 0.45
    blurred = shader.blurred(np.full(n, blur)).evaluate(wo, wi, above, inside)
    lp, hp = shader.lp[0], shader.hp
    c = lp[layout.P_HAIR:layout.P_HAIR + 7]
    want = np.zeros((n, 3))
    for i in range(n):
        sigma, frame = hp[i, 0, layout.H_SIGMA:layout.H_SIGMA + 3], hp[i, 0, layout.H_HAIR:layout.H_HAIR + 7]
        if model == "CHIANG":
            v, s, m0 = hair_chiang.chiang_blur(c[0], c[1], c[2], blur)
            f = hair_chiang.chiang_eval(v, s, m0, c[3], c[4], *sigma, frame[6], *frame[:6], *wo[i], *wi[i])
        else:
            f = hair_huang.huang_eval(max(c[0], blur), *c[1:7], *sigma, *frame[:6], *wo[i], *wi[i])
        want[i] = f[:3]
    shade = blurred.pdf > 0  # Cycles 5 cuts by the closure's own normal: nothing there, blurred or not
    np.testing.assert_allclose(blurred.glossy[shade], want[shade], rtol=1e-9, atol=1e-15)
    assert np.abs(blurred.glossy - plain.glossy).max() > 1e-3


def test_a_hair_sample_is_labelled_by_its_lobe_not_its_side():
    """Cycles labels a Chiang sample reflect for its R lobe and transmit otherwise, whatever side of the
    surface it leaves by; Light Path and the bounce depths read the label (sample_lobes' last value),
    which differs from the side (``crosses``) for some samples."""
    from drt_engine.core.bsdf import hair_chiang, mixture
    n = 300
    wo = _view(n)
    shader = _principled("CHIANG", wo)
    lp, hp = shader.lp, shader.hp
    c = lp[0, layout.P_HAIR:layout.P_HAIR + 5]
    sel = np.ones((1, 1))
    u = RNG.random((n, 3))
    differs = 0
    for i in range(n):
        s = mixture.sample_lobes(lp, shader.lt, hp, i, shader.mu, *wo[i], u[i, 0], u[i, 1], u[i, 2], False, sel, 0, False,
                                 0.0, 0.0, 1.0, 0, 0.0, 0.0, 1.0)
        sigma, frame = hp[i, 0, layout.H_SIGMA:layout.H_SIGMA + 3], hp[i, 0, layout.H_HAIR:layout.H_HAIR + 7]
        *_, reflect = hair_chiang.chiang_sample(*c, *sigma, frame[6], *frame[:6], *wo[i], u[i, 1], u[i, 2], u[i, 0])
        if not s[8]:
            continue
        assert s[16] == (not reflect) and s[12] == 0
        differs += s[16] != s[11]
    assert differs > 0
