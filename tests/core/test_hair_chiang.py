"""Chiang hair (core/bsdf/hair_chiang.py, Cycles' bsdf_principled_hair_chiang.h): energy, sampling
against evaluation, the pdf's normalisation, absorption, finiteness at the extremes, the setup's
constants."""
import math

import numpy as np
import pytest

from drt_engine.core.base.jit import kernel
from drt_engine.core.bsdf import hair_chiang as hc
from drt_engine.core.bsdf.hair_absorption import albedo_roughness_scale

N_PARAMS = 18
"""A parameter row: v, s, m0, alpha, eta, sigma RGB, h, X (3), Y (3), wo (3)."""


@kernel
def _eval_rows(params, wi, out):
    """chiang_eval for each wi row (params row k, or the only one): out rows F RGB, pdf."""
    for k in range(wi.shape[0]):
        p = params[k % params.shape[0]]
        f0, f1, f2, pdf = hc.chiang_eval(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8],
                                         p[9], p[10], p[11], p[12], p[13], p[14], p[15], p[16], p[17],
                                         wi[k, 0], wi[k, 1], wi[k, 2])
        out[k, 0] = f0
        out[k, 1] = f1
        out[k, 2] = f2
        out[k, 3] = pdf


@kernel
def _sample_rows(params, u, out):
    """chiang_sample for each u row: out rows wi, F RGB, pdf, reflect (1 or 0)."""
    for k in range(u.shape[0]):
        p = params[k % params.shape[0]]
        wx, wy, wz, f0, f1, f2, pdf, reflect = hc.chiang_sample(
            p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12], p[13], p[14],
            p[15], p[16], p[17], u[k, 0], u[k, 1], u[k, 2])
        out[k, 0] = wx
        out[k, 1] = wy
        out[k, 2] = wz
        out[k, 3] = f0
        out[k, 4] = f1
        out[k, 5] = f2
        out[k, 6] = pdf
        out[k, 7] = 1.0 if reflect else 0.0


TANGENT = np.array([0.36, -0.48, 0.8])
"""A unit hair tangent off the axes: the kernels work in any frame."""
ACROSS = np.cross(TANGENT, [1.0, 0.0, 0.0]) / np.linalg.norm(np.cross(TANGENT, [1.0, 0.0, 0.0]))


def view(sin_o):
    """wo at elevation asin(sin_o) from the plane normal to the tangent."""
    return sin_o * TANGENT + math.sqrt(max(1.0 - sin_o * sin_o, 0.0)) * ACROSS


def hair(roughness=0.3, radial=0.3, coat=0.0, offset=0.035, ior=1.55, sigma=(0.0, 0.0, 0.0), h=0.0, sin_o=0.5):
    """A (1, N_PARAMS) parameter row: the setup's constants, and the frame and h that chiang_frame
    gives for the geometric normal of a cylinder hit at offset h."""
    wo = view(sin_o)
    yx, yy, yz, _ = hc.chiang_frame(*TANGENT, 1.0, 0.0, 0.0, *wo)
    y = np.array([yx, yy, yz])
    ng = -h * y - math.sqrt(max(1.0 - h * h, 0.0)) * np.cross(TANGENT, y)
    yx, yy, yz, h_frame = hc.chiang_frame(*TANGENT, *ng, *wo)
    consts = [float(c) for c in hc.chiang_constants(roughness, radial, coat, offset, ior)]
    return np.array([consts + list(sigma) + [h_frame, *TANGENT, yx, yy, yz, *wo]])


def stratified_sphere(rng, m):
    """m * m directions, one uniform in each cell of an (z, phi) grid over the sphere."""
    i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    z = -1.0 + 2.0 * (i + rng.random(i.shape)) / m
    phi = 2.0 * np.pi * (j + rng.random(j.shape)) / m
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).reshape(-1, 3)


def uniform_integral(params, rng, m=768):
    """Uniform-sphere estimates of the integrals of F RGB and of the pdf."""
    wi = stratified_sphere(rng, m)
    out = np.empty((len(wi), 4))
    _eval_rows(params, wi, out)
    return out.mean(axis=0) * 4.0 * np.pi


def sample(params, rng, n=200_000):
    u = rng.random((n, 3))
    out = np.empty((n, 8))
    _sample_rows(params, u, out)
    return out


def fresnel(cos_i, eta):
    """Cycles' fresnel_dielectric_cos, written out."""
    g2 = eta * eta - 1.0 + cos_i * cos_i
    if g2 <= 0.0:
        return 1.0
    g = math.sqrt(g2)
    a, b = (g - cos_i) / (g + cos_i), (cos_i * (g + cos_i) - 1.0) / (cos_i * (g - cos_i) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


def mp_integrals(params):
    """The ported Mp of R, TT, TRT and TRRT+ integrated over the sphere's elevations (trapezoids)."""
    v, _, m0, alpha = params[0, :4]
    sin_o = float(params[0, 15:18] @ TANGENT)
    cos_o = math.sqrt(1.0 - sin_o * sin_o)
    a = hc._alpha_angles(sin_o, cos_o, alpha)
    lobes = ((a[0], a[1], m0), (a[2], a[3], 0.25 * v), (a[4], a[5], 4.0 * v), (sin_o, cos_o, 4.0 * v))
    theta = np.linspace(-0.5 * np.pi, 0.5 * np.pi, 6001)
    integrals = []
    for s, c, lv in lobes:
        y = np.array([hc.longitudinal(math.sin(t), math.cos(t), s, c, lv) * math.cos(t) for t in theta])
        integrals.append(0.5 * np.sum((y[1:] + y[:-1]) * np.diff(theta)))
    return integrals


def white_expectation(params):
    """The integral of F with no absorption: sum over lobes of Ap times Mp's integral (Np's is 1)."""
    sin_o = float(params[0, 15:18] @ TANGENT)
    f = fresnel(math.sqrt(1.0 - sin_o**2) * math.sqrt(1.0 - params[0, 8] ** 2), params[0, 4])
    ap = (f, (1 - f) ** 2, (1 - f) ** 2 * f, (1 - f) * f * f)  # hair_attenuation with T = 1
    assert sum(ap) == pytest.approx(1.0, abs=1e-12)
    return sum(a * m for a, m in zip(ap, mp_integrals(params)))


FURNACE = [  # roughness, radial roughness, coat, offset, ior, h, sin theta_o
    (0.3, 0.3, 0.0, 0.035, 1.55, 0.0, 0.5),
    (0.5, 0.8, 0.0, 0.035, 1.55, -0.3, -0.2),
    (0.2, 0.5, 0.3, 0.1, 1.3, 0.7, 0.3),
    (0.8, 1.0, 0.0, 0.0, 2.0, 0.9, 0.0),
    (0.4, 0.5, 0.0, 0.035, 1.55, 0.95, 0.9999),  # near grazing
    (0.4, 0.5, 0.0, -0.05, 1.0001, 0.3, 0.3),  # eta near 1
]


@pytest.mark.parametrize("roughness, radial, coat, offset, ior, h, sin_o", FURNACE)
def test_white_furnace(roughness, radial, coat, offset, ior, h, sin_o):
    """No absorption: the Ap sum to 1, so F integrates to 1 up to Cycles' Mp normalisation.

    Cycles' Mp does not integrate to exactly 1: below v = 0.1 its log I0 is the log of a 10-term
    series up to x = 12 (about 2% short just below 12) and an asymptotic form with half the 1/(8x)
    term above; above 0.1 the series is short for x near 10. Measured: 0.989 to 1.000 (0.991 for the
    second case, whose TT lobe has v = 0.08). The uniform estimate must therefore match the ported
    Mp's own integrals (the closed expectation), and be within 1.5% of 1. The importance-sampled
    E[F / pdf] is exactly 1 with no absorption whatever the sampling: every lobe's Ap is grey and
    the pdf is the same sum with Ap normalised by their total, which is 1 (F / pdf = 1 per sample);
    that the samples follow the pdf is test_sampling_follows_the_pdf's.
    """
    rng = np.random.default_rng(11)
    params = hair(roughness, radial, coat, offset, ior, (0.0, 0.0, 0.0), h, sin_o)
    integral = uniform_integral(params, rng)
    assert integral[0] == integral[1] == integral[2]
    expected = white_expectation(params)
    assert integral[0] == pytest.approx(expected, rel=3e-3)
    assert integral[0] == pytest.approx(1.0, abs=0.015) and expected == pytest.approx(1.0, abs=0.015)
    s = sample(params, rng, 20_000)
    assert np.all(s[:, 6] > 0.0)
    np.testing.assert_allclose(s[:, 3:6] / s[:, 6:7], 1.0, rtol=1e-12)


@pytest.mark.parametrize("roughness, radial, coat, offset, ior, h, sin_o", FURNACE)
def test_the_pdf_integrates_to_one(roughness, radial, coat, offset, ior, h, sin_o):
    """The pdf (F_energy) over the sphere, with absorption: within 2% of 1 (Mp's normalisation above)."""
    params = hair(roughness, radial, coat, offset, ior, (0.3, 1.0, 3.0), h, sin_o)
    assert uniform_integral(params, np.random.default_rng(12))[3] == pytest.approx(1.0, abs=0.02)


@pytest.mark.parametrize("roughness, radial, coat, offset, ior, h, sin_o", [c for c in FURNACE if c[2] == 0.0])
def test_sampling_follows_the_pdf(roughness, radial, coat, offset, ior, h, sin_o):
    """The share of samples in each of 6 x 8 (sin theta, phi) cells is the pdf's mass there.

    Without Coat only: Cycles samples R's elevation with the variance v but evaluates it with m0
    (m0 = v without Coat), so with Coat the samples do not follow the pdf there, as in Cycles.
    """
    rng = np.random.default_rng(13)
    params = hair(roughness, radial, coat, offset, ior, (0.2, 0.5, 1.0), h, sin_o)
    y = params[0, 12:15]
    z = np.cross(TANGENT, y)

    def cells(w, weights=None):
        hist, _, _ = np.histogram2d(w @ TANGENT, np.arctan2(w @ z, w @ y), bins=(6, 8),
                                    range=((-1.0, 1.0), (-np.pi, np.pi)), weights=weights)
        return hist

    wi = stratified_sphere(rng, 768)
    out = np.empty((len(wi), 4))
    _eval_rows(params, wi, out)
    mass = cells(wi, out[:, 3])
    s = sample(params, rng)
    assert np.abs(cells(s[:, :3]) / len(s) - mass / mass.sum()).max() < 0.003


@pytest.mark.parametrize("roughness, radial, coat, sin_o", [(0.3, 0.3, 0.0, 0.4), (0.1, 0.2, 0.5, 0.95),
                                                             (0.001, 0.001, 0.0, -0.6), (0.7, 0.9, 1.0, 0.0)])
def test_sampling_agrees_with_evaluation(roughness, radial, coat, sin_o):
    """chiang_eval at each sampled wi gives the F and pdf chiang_sample returned."""
    rng = np.random.default_rng(14)
    params = hair(roughness, radial, coat, 0.05, 1.55, (0.5, 1.0, 2.0), 0.4, sin_o)
    s = sample(params, rng, 20_000)
    assert np.all(s[:, 6] > 0.0)
    np.testing.assert_allclose(np.linalg.norm(s[:, :3], axis=1), 1.0, rtol=1e-12)
    out = np.empty((len(s), 4))
    _eval_rows(params, s[:, :3].copy(), out)
    np.testing.assert_allclose(out[:, :3], s[:, 3:6], rtol=1e-6, atol=1e-300)
    np.testing.assert_allclose(out[:, 3], s[:, 6], rtol=1e-6, atol=1e-300)
    assert 0.0 < s[:, 7].mean() < 1.0  # R and the transmitted lobes are both picked


def test_absorption_darkens():
    """With sigma > 0 the furnace integral is below 1 and falls as sigma grows; importance sampling
    (unbiased without Coat) agrees with the uniform estimate; huge sigma leaves R alone."""
    rng = np.random.default_rng(15)
    base = np.array([0.2, 0.5, 1.0])
    previous = np.ones(3)
    for k in (0.25, 1.0, 4.0):
        params = hair(0.4, 0.5, 0.0, 0.035, 1.55, tuple(k * base), 0.2, 0.3)
        integral = uniform_integral(params, rng)[:3]
        s = sample(params, rng)
        np.testing.assert_allclose((s[:, 3:6] / s[:, 6:7]).mean(axis=0), integral, rtol=0.02)
        assert np.all(integral < previous) and integral[0] > integral[1] > integral[2]
        previous = integral
    params = hair(0.4, 0.5, 0.0, 0.035, 1.55, (1e6, 1e6, 1e6), 0.2, 0.3)
    f = fresnel(math.sqrt(1.0 - 0.3**2) * math.sqrt(1.0 - 0.2**2), 1.55)
    integral = uniform_integral(params, rng)[:3]
    np.testing.assert_allclose(integral, f * mp_integrals(params)[0], rtol=0.01)


def test_finite_everywhere():
    """Grazing wo (along the tangent too) and wi, h = +-1, the smallest roughnesses, sigma 0, 1e6
    and infinite, eta at and near 1: evaluation, sampling, albedo and frame stay finite."""
    rng = np.random.default_rng(16)
    rows, along = [], []
    for sin_o in (1.0, -1.0, 1.0 - 1e-12, 0.9999999, 0.0, 0.5):
        wo = view(sin_o)
        y = hc.chiang_frame(*TANGENT, 0.0, 0.0, 1.0, *wo)[:3]
        for h in (-1.0, 0.0, 1.0, 0.999999):
            for roughness, radial, coat in ((0.0, 0.0, 0.0), (0.0, 1.0, 1.0), (1.0, 0.0, 0.5), (1.0, 1.0, 0.0)):
                for sigma in ((0.0, 0.0, 0.0), (1e6, 1e6, 1e6), (0.0, 1e6, np.inf)):
                    for ior in (1.0001, 1.0, 1.55):
                        consts = [float(c) for c in hc.chiang_constants(roughness, radial, coat, 0.035, ior)]
                        rows.append(consts + list(sigma) + [h, *TANGENT, *y, *wo])
                        along.append(abs(sin_o) == 1.0)
                        assert np.all(np.isfinite(hc.chiang_albedo(consts[0], ior, *sigma, h, *TANGENT, *wo)))
    params, along = np.array(rows), np.array(along)
    for w in (TANGENT, -TANGENT, view(1.0 - 1e-12), view(-0.9999999), ACROSS, -ACROSS, rng.normal(size=3)):
        out = np.empty((len(params), 4))
        _eval_rows(params, np.tile(w / np.linalg.norm(w), (len(params), 1)), out)
        assert np.all(np.isfinite(out)) and np.all(out >= 0.0)
        assert np.all(out[along] == 0.0)  # wo along the tangent: no frame, nothing scattered
    last = 1.0 - 2**-53
    for u in ((0.0, 0.0, 0.0), (0.5, 0.5, 0.5), (last, last, last), (0.0, last, 0.999)):
        s = np.empty((len(params), 8))
        _sample_rows(params, np.tile(u, (len(params), 1)), s)
        assert np.all(np.isfinite(s)) and np.all(s[:, 3:7] >= 0.0)
        ok = s[:, 6] > 0.0
        np.testing.assert_allclose(np.linalg.norm(s[ok, :3], axis=1), 1.0, rtol=1e-9)
        assert not np.any(ok[along])
    assert hc.chiang_frame(*TANGENT, *ACROSS, *TANGENT) == (0.0, 0.0, 0.0, 0.0)


def test_frame():
    """Y is normal to the tangent and wo; h is the hit's offset across the fibre as seen from wo."""
    wo = view(0.3)
    y = np.array(hc.chiang_frame(*TANGENT, 1.0, 0.0, 0.0, *wo)[:3])
    assert np.linalg.norm(y) == pytest.approx(1.0) and abs(y @ TANGENT) < 1e-15 and abs(y @ wo) < 1e-15
    z = np.cross(TANGENT, y)
    for h in (-0.7, 0.0, 0.4):
        ng = -h * y - math.sqrt(1.0 - h * h) * z  # a cylinder's normal at offset h, facing wo
        assert ng @ wo > 0.0
        assert hc.chiang_frame(*TANGENT, *ng, *wo)[3] == pytest.approx(h, abs=1e-14)
    assert hc.chiang_frame(*TANGENT, *(-y * 3.0), *wo)[3] == 1.0  # clamped


def test_albedo_and_blur():
    """Albedo: exp(-sqrt(sigma) scale(v)) + Fresnel; blur raises each roughness to the floor."""
    v, _, _, _, eta = (float(c) for c in hc.chiang_constants(0.3, 0.3, 0.0, 0.0, 1.55))
    wo = view(0.5)
    f = fresnel(math.sqrt(0.75) * math.sqrt(1.0 - 0.4**2), 1.55)
    np.testing.assert_allclose(hc.chiang_albedo(v, eta, 0.0, 1.0, 4.0, 0.4, *TANGENT, *wo),
                               np.exp(-np.sqrt([0.0, 1.0, 4.0]) * albedo_roughness_scale(v)) + f, rtol=1e-12)
    assert hc.chiang_blur(0.01, 0.5, 0.002, 0.1) == (0.1, 0.5, 0.1)


def test_constants_follow_the_setup():
    """chiang_constants against bsdf_hair_chiang_setup (bsdf_principled_hair_chiang.h lines 162-170:
    clamp v and s to [0.001, 1], m0 = clamp(m0_roughness * clamped v, 0.001, 1), then map v and m0 by
    (0.726 r + 0.812 r^2 + 3.7 r^20)^2 and s by (0.265 s + 1.194 s^2 + 5.372 s^22) sqrt(pi / 8); line
    192: alpha = -alpha) with m0_roughness = 1 - clamp(coat, 0, 1) (svm/closure.h line 974)."""
    def var(r):
        return (0.726 * r + 0.812 * r * r + 3.700 * r**20) ** 2

    def scale(s):
        return (0.265 * s + 1.194 * s * s + 5.372 * s**22) * math.sqrt(math.pi / 8.0)

    v, s, m0, alpha, eta = hc.chiang_constants(0.3, 0.5, 0.25, 0.035, 1.55)
    assert v == pytest.approx(var(0.3), rel=1e-14) and v == pytest.approx(0.0846111745, rel=1e-9)
    assert s == pytest.approx(scale(0.5), rel=1e-14) and s == pytest.approx(0.2700899992, rel=1e-9)
    assert m0 == pytest.approx(var(0.75 * 0.3), rel=1e-14)
    assert (alpha, eta) == (-0.035, 1.55)
    v, s, m0, _, _ = hc.chiang_constants(0.0, 2.0, 0.0, 0.0, 1.55)  # clamped below and above
    assert (v, s, m0) == pytest.approx((var(0.001), scale(1.0), var(0.001)), rel=1e-14)
    assert v == pytest.approx(0.726812**2 * 1e-6, rel=1e-9)
    v, _, m0, _, _ = hc.chiang_constants(1.0, 1.0, 1.0, 0.0, 1.55)  # full coat: m0 at its floor
    assert v == pytest.approx((0.726 + 0.812 + 3.7) ** 2, rel=1e-14) and m0 == pytest.approx(var(0.001), rel=1e-14)
    v, s, m0, alpha, eta = hc.chiang_constants(np.array([0.2, 0.6]), 0.3, np.array([-1.0, 0.5]), 0.1, 1.4)
    np.testing.assert_allclose(v, var(np.array([0.2, 0.6])), rtol=1e-14)
    np.testing.assert_allclose(m0, var(np.array([0.2, 0.3])), rtol=1e-14)  # coat clamped to 0: m0 = v
    assert alpha == -0.1 and eta == 1.4 and s == pytest.approx(scale(0.3), rel=1e-14)
