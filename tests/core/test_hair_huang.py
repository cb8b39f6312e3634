"""Principled Hair BSDF, Huang model (core.bsdf.hair_huang): energy, sampling against evaluation,
the gains, finiteness at extreme inputs, and the closure's constants as Cycles' setup leaves them.

Cycles' eval and sample of this model are two estimators, not a density and its sampler: both
report pdf 1, sample's value is a path weight (one sampled path through the fiber), eval's a
Simpson quadrature over the fiber's width with one sampled microfacet normal per node. So they
are compared as integrals: E[F] over samples against 4 pi E[eval] over uniform directions."""
import functools
import math

import numpy as np
import pytest

from drt_engine.core.base.jit import kernel
from drt_engine.core.bsdf import hair_huang as hh
from drt_engine.core.bsdf.microfacet import fresnel_dielectric

TILT = math.radians(2.0)  # the node's default Offset
IOR = 1.55
EPS = 1e-9  # a TRT gain that keeps eval's TRRT+ (computed only with TRT on) but no TRT to speak of


@kernel
def _eval_rows(c, sg, fr, wo, wi, out):
    """huang_eval for each row of wi into out (f0, f1, f2, pdf)."""
    for k in range(wi.shape[0]):
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = hh.huang_eval(
            c[0], c[1], c[2], c[3], c[4], c[5], c[6], sg[0], sg[1], sg[2], fr[0], fr[1], fr[2], fr[3], fr[4], fr[5],
            wo[0], wo[1], wo[2], wi[k, 0], wi[k, 1], wi[k, 2])


@kernel
def _sample_rows(c, sg, fr, wo, u, out):
    """huang_sample for each row of u into out (wi, f0, f1, f2, pdf, reflect as 1 or 0)."""
    for k in range(u.shape[0]):
        x, y, z, f0, f1, f2, pdf, reflect = hh.huang_sample(
            c[0], c[1], c[2], c[3], c[4], c[5], c[6], sg[0], sg[1], sg[2], fr[0], fr[1], fr[2], fr[3], fr[4], fr[5],
            wo[0], wo[1], wo[2], u[k, 0], u[k, 1], u[k, 2])
        out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5], out[k, 6] = x, y, z, f0, f1, f2, pdf
        out[k, 7] = 1.0 if reflect else 0.0


@kernel
def _frame(d, n, wo):
    """huang_frame of one hit."""
    return hh.huang_frame(d[0], d[1], d[2], n[0], n[1], n[2], wo[0], wo[1], wo[2])


@kernel
def _albedo(eta, sigma, fr, wo):
    """huang_albedo of one hit."""
    return hh.huang_albedo(eta, sigma[0], sigma[1], sigma[2], fr[0], fr[1], fr[2], fr[3], fr[4], fr[5], fr[6],
                           wo[0], wo[1], wo[2])


def _unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


WO = _unit([0.3, -0.4, 0.866])  # 17.5 degrees off perpendicular to the strand
TANGENT = np.array([1.0, 0.0, 0.0])
NORMAL = np.array([0.0, 0.0, 1.0])
FRAME = np.array(_frame(TANGENT, NORMAL, WO))


def _sphere(n, seed):
    return _unit(np.random.default_rng(seed).normal(size=(n, 3)))


def _constants(rough, gains, ar=1.0, ior=IOR, tilt=TILT):
    return np.array(hh.huang_constants(rough, tilt, ior, ar, *gains), np.float64)


@functools.lru_cache(maxsize=None)
def _evaluated(rough, gains, sigma=0.0, n=200_000):
    """(uniform directions wi, eval's (f0, f1, f2, pdf) toward them) from WO."""
    wi = _sphere(n, 1)
    out = np.empty((n, 4))
    _eval_rows(_constants(rough, gains), np.full(3, sigma), FRAME[:6], WO, wi, out)
    return wi, out


@functools.lru_cache(maxsize=None)
def _sampled(rough, gains, sigma=0.0, n=500_000):
    """huang_sample's rows from WO for n uniform (u0, u1, u2) (the same for every call)."""
    out = np.empty((n, 8))
    u = np.random.default_rng(2).random((n, 3))
    _sample_rows(_constants(rough, gains), np.full(3, sigma), FRAME[:6], WO, u, out)
    return out


def _eval_integral(rough, gains, sigma=0.0, weight=None):
    """4 pi E[f0 weight(wi)] over uniform wi: the integral of eval's value (times weight)."""
    wi, out = _evaluated(rough, gains, sigma)
    return 4.0 * np.pi * np.mean(out[:, 0] * (1.0 if weight is None else weight(wi)))


def _sample_integral(rough, gains, sigma=0.0, weight=None):
    """E[F0 weight(wi)] over samples (pdf is 1): the same integral by importance sampling."""
    out = _sampled(rough, gains, sigma)
    return np.mean(out[:, 3] * (1.0 if weight is None else weight(out[:, :3])))


def _lobes(rough, integral, weight=None):
    """(R, TT, TRT, TRRT+) integrals picked apart by the gains: eval has TRRT+ only with TRT on and
    does not scale it by any gain; sample has it always (unscaled), so lobes are differences."""
    if integral is _eval_integral:
        trrt = integral(rough, (0, 0, EPS), weight=weight)
        return (integral(rough, (1, 0, 0), weight=weight), integral(rough, (0, 1, 0), weight=weight),
                integral(rough, (0, 0, 1), weight=weight) - trrt, trrt)
    full = integral(rough, (1, 1, 1), weight=weight)
    return (full - integral(rough, (0, 1, 1), weight=weight), full - integral(rough, (1, 0, 1), weight=weight),
            full - integral(rough, (1, 1, 0), weight=weight), integral(rough, (0, 0, EPS), weight=weight))


def test_white_furnace():
    """Without absorption, sampled paths carry all the energy (1 within 3%), and eval agrees with
    sample lobe by lobe for R, TT and TRT (within the few percent its Simpson rule over the fiber's
    width, at 0.7 or 0.8 x roughness spacing, leaves). Eval's TRRT+ is Cycles' own and larger: it
    integrates a term without the cosine the other lobes carry against the Jacobian d gamma / d h =
    1 / cos gamma, which grows to 22 at the ends of h in [-0.999, 0.999], and Simpson's rule with
    ~10 nodes overweights those ends (its weights sum to 1.7 x the exact integral at roughness 0.3);
    total internal reflection on the way out, where that term is all of T1, is commonest there. So
    eval's furnace is 1.64 at roughness 0.3 and 1.2 at 0.1, sample's 1.01 and 1.00."""
    for rough in (0.1, 0.3, 0.6):
        assert _sample_integral(rough, (1, 1, 1)) == pytest.approx(1.0, abs=0.03)
    e_lobes = _lobes(0.3, _eval_integral)
    s_lobes = _lobes(0.3, _sample_integral)
    for e, s, tol in zip(e_lobes[:3], s_lobes[:3], (0.03, 0.02, 0.05)):
        assert e == pytest.approx(s, rel=tol)
    # TT alone draws no TRT microfacet normals, so its quadrature takes other random numbers
    assert sum(e_lobes) == pytest.approx(_eval_integral(0.3, (1, 1, 1)), rel=0.01)
    assert sum(e_lobes) - sum(s_lobes) == pytest.approx(e_lobes[3] - s_lobes[3], abs=0.02)
    assert e_lobes[3] > 3.0 * s_lobes[3]
    assert 1.55 < _eval_integral(0.3, (1, 1, 1)) < 1.75


def test_sampling_matches_evaluation():
    """Both report pdf 1 (eval at a sampled direction gives the pdf sample returned). Their values
    are not pointwise equal (sample's is one path's weight, eval's the quadrature), so sampled
    directions are checked in distribution: per bin of the hair frame's (theta, phi), the energy
    sample sends there equals eval's integral over it, for the primary reflection alone (absorption
    1e4 leaves nothing through the fiber) and for TT (a difference of gains, as in the furnace test)."""
    out = _sampled(0.3, (1, 1, 1))
    ok = out[:, 7] == 1.0
    assert ok.mean() > 0.98 and np.all(out[ok, 6] == 1.0) and np.all(out[~ok, 3:7] == 0.0)
    check = np.empty((1000, 4))
    _eval_rows(_constants(0.3, (1, 1, 1)), np.zeros(3), FRAME[:6], WO, out[ok][:1000, :3], check)
    assert np.all(check[:, 3] == 1.0) and np.all(np.isfinite(check))

    y, x = FRAME[:3], FRAME[3:6]
    z = np.cross(x, y)

    def angles(w):
        return np.arcsin(np.clip(w @ y, -1, 1)), np.arctan2(w @ x, w @ z)

    def bin_weight(t0, t1, p0, p1):
        def weight(w):
            theta, phi = angles(w)
            return ((theta >= t0) & (theta < t1) & (phi >= p0) & (phi < p1)).astype(float)
        return weight

    thetas = (-np.pi / 2, -0.6, -0.3, 0.0, np.pi / 2)
    phis = np.linspace(-np.pi, np.pi, 7)
    total = _sample_integral(0.3, (1, 0, 0), sigma=1e4)
    assert total == pytest.approx(_eval_integral(0.3, (1, 0, 0), sigma=1e4), rel=0.03)
    for t0, t1 in zip(thetas[:-1], thetas[1:]):
        for p0, p1 in zip(phis[:-1], phis[1:]):
            w = bin_weight(t0, t1, p0, p1)
            s = _sample_integral(0.3, (1, 0, 0), sigma=1e4, weight=w)
            e = _eval_integral(0.3, (1, 0, 0), sigma=1e4, weight=w)
            assert s == pytest.approx(e, abs=0.06 * max(s, e) + 0.002 * total)
    for t0, t1 in ((-np.pi / 2, 0.0), (0.0, np.pi / 2)):
        for p0, p1 in ((-np.pi, -np.pi / 2), (-np.pi / 2, 0.0), (0.0, np.pi / 2), (np.pi / 2, np.pi)):
            w = bin_weight(t0, t1, p0, p1)
            s = _lobes(0.3, _sample_integral, w)[1]
            e = _lobes(0.3, _eval_integral, w)[1]
            assert s == pytest.approx(e, abs=0.05 * max(s, e) + 0.005)


def test_pdf_is_cycles_constant_one():
    """Cycles' pdf is the constant 1 for eval and sample alike ("the importance sampling pdf is
    already factored in the value so this value is only used for MIS"): no density, so it
    integrates to 4 pi over the sphere, not 1; what MIS needs is that eval and sample agree on it."""
    wi, out = _evaluated(0.3, (1, 1, 1))
    assert np.all(out[:, 3] == 1.0)
    assert 4.0 * np.pi * np.mean(out[:, 3]) == pytest.approx(4.0 * np.pi)


def test_gains():
    """R = 0 takes exactly the primary reflection out of eval (direction by direction), which holds
    about the Fresnel share of a smooth fiber's energy (less at roughness 0.1: rough facets mask
    some grazing reflection); sample loses as much. All gains 0 is no closure: nothing at all."""
    wi, full = _evaluated(0.3, (1, 1, 1))
    _, no_r = _evaluated(0.3, (0, 1, 1))
    _, r_only = _evaluated(0.3, (1, 0, 0))
    assert np.allclose(full[:, :3] - no_r[:, :3], r_only[:, :3], rtol=1e-12, atol=1e-14)
    drop = _sample_integral(0.3, (1, 1, 1)) - _sample_integral(0.3, (0, 1, 1))
    assert drop == pytest.approx(_eval_integral(0.3, (1, 0, 0)), rel=0.03)

    cos_i = math.sqrt(1.0 - (WO @ TANGENT) ** 2)
    h = np.linspace(-1.0, 1.0, 20001)
    f = fresnel_dielectric(cos_i * np.sqrt(1.0 - h * h), IOR)
    smooth = 0.5 * np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(h))  # trapezoids (np.trapz is gone in NumPy 2)
    assert _eval_integral(0.1, (1, 0, 0)) == pytest.approx(smooth, rel=0.12)

    assert not hh.huang_present(0.0, 0.0, -1.0) and hh.huang_present(0.0, 0.5, 0.0)
    wi = _sphere(100, 3)
    out = np.empty((100, 4))
    _eval_rows(_constants(0.3, (0, 0, 0)), np.zeros(3), FRAME[:6], WO, wi, out)
    assert np.all(out == 0.0)
    sampled = np.empty((100, 8))
    _sample_rows(_constants(0.3, (0, -1, 0)), np.zeros(3), FRAME[:6], WO, np.random.default_rng(4).random((100, 3)),
                 sampled)
    assert np.all(sampled == 0.0)


def test_frame():
    """The mesh case of the setup: Y along dPdu, X across dPdu and wo, h = -X . N; |h| = 1 only with
    the normal along X. Degenerate dPdu, normal and wo give unit frames."""
    y, x, h = FRAME[:3], FRAME[3:6], FRAME[6]
    assert np.allclose(y, TANGENT) and np.allclose(x, _unit(np.cross(TANGENT, WO)))
    assert h == pytest.approx(-x @ NORMAL)
    edge = np.array(_frame(TANGENT, x, WO))
    assert abs(edge[6]) == pytest.approx(1.0)
    for d, n, wo in ((np.zeros(3), NORMAL, WO), (WO, NORMAL, WO), (np.full(3, np.nan), NORMAL, WO),
                     (TANGENT, np.zeros(3), WO), (np.zeros(3), np.zeros(3), WO), (TANGENT, NORMAL, np.full(3, np.inf))):
        fr = np.array(_frame(d, n, wo))
        assert np.all(np.isfinite(fr))
        assert np.linalg.norm(fr[:3]) == pytest.approx(1.0) and np.linalg.norm(fr[3:6]) == pytest.approx(1.0)
        assert fr[:3] @ fr[3:6] == pytest.approx(0.0, abs=1e-12)


def _fresnel(cos_i, eta):
    """Unpolarised dielectric reflectance (textbook form) and the refracted ray's cosine."""
    sin_t2 = (1.0 - cos_i**2) / eta**2
    if sin_t2 >= 1.0:
        return 1.0, 0.0
    cos_t = np.sqrt(1.0 - sin_t2)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2), cos_t


def test_albedo_is_cycles_series():
    """bsdf_hair_huang_albedo: 1 without absorption, the surface's Fresnel with an opaque fibre, and in
    between the series (A - 2fA + f) / (1 - fA) with A = exp(-2 sigma cos_t / (1 - wt_y^2)), wt the
    ray refracted at the micro normal (h, 0, sqrt(1 - h^2)); finite at grazing views and infinite sigma."""
    h = FRAME[6]
    ix, iy, iz = FRAME[3:6] @ WO, FRAME[:3] @ WO, np.cross(FRAME[3:6], FRAME[:3]) @ WO
    m = np.array([h, 0.0, np.sqrt(1 - h * h)])
    f, cos_t = _fresnel(m @ (ix, iy, iz), IOR)
    wt = (-(m @ (ix, iy, iz)) / IOR + cos_t) * m - np.array([ix, iy, iz]) / IOR  # refracted, into the fibre
    sigma = np.array([0.0, 0.7, np.inf])
    a = np.exp(-2.0 * sigma * cos_t / (1.0 - wt[1] ** 2))
    want = (a - 2 * f * a + f) / (1 - f * a)
    got = np.array(_albedo(IOR, sigma, FRAME, WO))
    np.testing.assert_allclose(got, want, rtol=1e-9)
    assert got[0] == pytest.approx(1.0) and got[2] == pytest.approx(f) and 0 < f < got[1] < 1
    for wo in (_unit([0.0, 1.0, 1e-12]), TANGENT, _unit([1.0, 0.0, 1e-9])):
        fr = np.array(_frame(TANGENT, NORMAL, wo))
        assert np.all(np.isfinite(_albedo(IOR, sigma, fr, wo)))


def test_finite_at_extreme_inputs():
    """Grazing and tangent views, h = +-1, IOR at and near 1 and far off, roughness at its clamps,
    absorption 0, huge and infinite, aspect ratios far from 1, steep tilts: values and weights are
    finite and not negative, sampled directions unit."""
    rng = np.random.default_rng(6)
    views = [WO, _unit([1.0, 0.0, 1e-9]), TANGENT, _unit([0.0, 0.0, 1.0]), _unit([0.0, 1.0, 1e-12]),
             _unit([-0.99, 0.1, 0.05])]
    count = 0
    for rough in (0.0, 0.3, 1.0):
        for ior in (0.5, 1.0, 1.0001, IOR, 10.0):
            for ar in (0.02, 1.0, 30.0):
                for sigma in ((0.0, 0.0, 0.0), (0.01, 1.0, 50.0), (1e6, np.inf, 0.0)):
                    for tilt in (0.0, 0.3, -1.4):
                        c = _constants(rough, (1, 1, 1), ar=ar, ior=ior, tilt=tilt)
                        wo = views[rng.integers(len(views))]
                        fr = np.array(_frame(TANGENT, NORMAL, wo))
                        side = rng.integers(3)
                        if side:  # the normal along +-X: h = -+1
                            fr = np.array(_frame(TANGENT, (1.5 - side) * 2.0 * fr[3:6], wo))
                        wi = np.concatenate([_sphere(3, count), [wo, -wo, TANGENT]])
                        out = np.empty((len(wi), 4))
                        _eval_rows(c, np.array(sigma), fr[:6], wo, wi, out)
                        assert np.all(np.isfinite(out)) and np.all(out >= 0.0)
                        sampled = np.empty((8, 8))
                        u = np.concatenate([rng.random((6, 3)), [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]])
                        _sample_rows(c, np.array(sigma), fr[:6], wo, u, sampled)
                        assert np.all(np.isfinite(sampled)) and np.all(sampled[:, 3:7] >= 0.0)
                        ok = sampled[:, 7] == 1.0
                        assert np.allclose(np.linalg.norm(sampled[ok, :3], axis=1), 1.0)
                        count += 1
    assert count == 405


def test_constants_as_cycles_sets_them():
    """huang_constants against hand values: bsdf_principled_hair_huang.h:247 clamps the roughness to
    [0.001, 1], :250 negates the tilt; svm/closure.h:1011-1013 keep the gains at least 0."""
    rough, tilt, eta, ar, r, tt, trt = hh.huang_constants(0.0, 0.1, 1.55, 2.0, -1.0, 0.5, 2.0)
    assert (rough, tilt, eta, ar, r, tt, trt) == (0.001, -0.1, 1.55, 2.0, 0.0, 0.5, 2.0)
    rough, *_ = hh.huang_constants(np.array([0.5, 3.0]), 0.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    assert np.array_equal(rough, [0.5, 1.0])
