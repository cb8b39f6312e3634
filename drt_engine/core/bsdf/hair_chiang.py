"""Chiang hair: Cycles' Principled Hair BSDF, Chiang model (kernel/closure/bsdf_principled_hair_chiang.h,
after Chiang, Bitterli, Tappan and Burley 2016 and pbrt-v3), ported in float64.

A fibre scatters through four lobes: R (reflection), TT, TRT and the residual TRRT+. Each is a
longitudinal term Mp (d'Eon's, about the view elevation tilted by the cuticle angle) times an
azimuthal term Np (a logistic trimmed to [-pi, pi]; uniform for TRRT+), weighted by its attenuation
Ap (Fresnel at the hit's offset h and the absorption sigma along the refracted path). The frame is
X the hair tangent, Y = X x wo normalised (the closure's N) and Z = X x Y. Sampling picks a lobe by
its share of Ap's luminance, then Mp and Np exactly; the pdf is that share-weighted sum (Cycles'
F_energy). F, like Cycles' eval, already includes the cosine: it is f |cos| here.

Where Cycles divides by zero or takes a square root of a negative (a degenerate frame, wo along
the tangent, eta <= 1 at grazing, a zero path with infinite sigma), these kernels return the limit
or 0 instead of NaN; elsewhere they compute what Cycles computes. The host helpers turn the node's
inputs into the closure's constants as svm/closure.h and bsdf_hair_chiang_setup do.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel
from ..base.vectors import cross3, safe_unit
from .hair_absorption import albedo_roughness_scale
from .microfacet import fresnel_dielectric1

LUMA = (0.2126, 0.7152, 0.0722)
"""Blender's default Rec.709 luminance weights: Cycles' spectrum_to_gray (linear_rgb_to_gray) dots
with these for the default colour space."""
SQRT_PI_8 = math.sqrt(math.pi / 8.0)
LN_2PI = math.log(2.0 * math.pi)
V_MIN = 0.001
"""bsdf_hair_chiang_setup clamps the roughnesses to [V_MIN, 1] before mapping them."""


def _f64(x):
    """x as float64: a NumPy scalar for a number, an array for an array."""
    return np.asarray(x, dtype=np.float64)[()]


def _variance(r):
    """Longitudinal roughness -> logistic variance (the setup's map of v and m0_roughness)."""
    return (0.726 * r + 0.812 * r**2 + 3.700 * r**20) ** 2


_roughness_scale = kernel(inline="always")(albedo_roughness_scale)


def chiang_constants(roughness, radial_roughness, coat, offset, ior):
    """(v, s, m0, alpha, eta) as bsdf_hair_chiang_setup leaves them, from the node's Roughness and
    Radial Roughness (already randomised), Coat, Offset (radians) and IOR; numbers or arrays."""
    v = np.clip(_f64(roughness), V_MIN, 1.0)
    s = np.clip(_f64(radial_roughness), V_MIN, 1.0)
    m0 = np.clip((1.0 - np.clip(_f64(coat), 0.0, 1.0)) * v, V_MIN, 1.0)
    s = (0.265 * s + 1.194 * s**2 + 5.372 * s**22) * SQRT_PI_8
    return _variance(v), s, _variance(m0), -_f64(offset), _f64(ior)


@kernel(inline="always")
def _cos_from_sin(s):
    """sqrt(1 - s^2), 0 past |s| = 1 (Cycles' cos_from_sin and sin_from_cos)."""
    return math.sqrt(max(1.0 - s * s, 0.0))


@kernel(inline="always")
def _safe_asin(a):
    """asin of a clamped to [-1, 1]."""
    return math.asin(min(max(a, -1.0), 1.0))


@kernel(inline="always")
def _safe_divide(a, b):
    """a / b, 0 where b is 0."""
    return a / b if b != 0.0 else 0.0


@kernel(inline="always")
def _delta_phi(p, gamma_o, gamma_t):
    """Change of azimuth of the p-th order path."""
    return 2.0 * p * gamma_t - 2.0 * gamma_o + p * math.pi


@kernel(inline="always")
def _wrap_angle(a):
    """a remapped to [-pi, pi]."""
    return (a + math.pi) - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi)) - math.pi


@kernel(inline="always")
def _logistic(x, s):
    """Logistic density of scale s."""
    v = math.exp(-abs(x) / s)
    return v / (s * (1.0 + v) * (1.0 + v))


@kernel(inline="always")
def _logistic_cdf(x, s):
    """Logistic distribution function (0 where Cycles' expf would overflow)."""
    arg = -x / s
    if arg > 88.0:
        return 0.0
    return 1.0 / (1.0 + math.exp(arg))


@kernel(inline="always")
def _bessel_i0(x):
    """Cycles' truncated series for the modified Bessel function I0."""
    x = x * x
    val = 1.0 + 0.25 * x
    pow_x_2i = x * x
    i_fac_2 = 1
    pow_4_i = 16
    for i in range(2, 10):
        i_fac_2 *= i * i
        newval = val + pow_x_2i / (pow_4_i * i_fac_2)
        if val == newval:
            return val
        val = newval
        pow_x_2i *= x
        pow_4_i *= 4
    return val


@kernel(inline="always")
def _log_bessel_i0(x):
    """log I0(x): the asymptotic expansion past 12, the series' log below."""
    if x > 12.0:
        return x + 0.5 * (1.0 / (8.0 * x) - LN_2PI - math.log(x))
    return math.log(_bessel_i0(x))


@kernel(inline="always")
def _trimmed_logistic(x, s):
    """Logistic density renormalised to [-pi, pi]."""
    return _safe_divide(_logistic(x, s), 1.0 - 2.0 * _logistic_cdf(-math.pi, s))


@kernel(inline="always")
def _sample_trimmed_logistic(u, s):
    """Invert the trimmed logistic's distribution at u (the ends where Cycles' log meets 0 or inf)."""
    cdf_minuspi = _logistic_cdf(-math.pi, s)
    d = u * (1.0 - 2.0 * cdf_minuspi) + cdf_minuspi
    if d <= 0.0:
        return -math.pi
    t = 1.0 / d - 1.0
    if t <= 0.0:
        return math.pi
    return min(max(-s * math.log(t), -math.pi), math.pi)


@kernel(inline="always")
def _azimuthal(phi, p, s, gamma_o, gamma_t):
    """Np: the trimmed logistic about the p-th order path's change of azimuth."""
    return _trimmed_logistic(_wrap_angle(phi - _delta_phi(p, gamma_o, gamma_t)), s)


@kernel(inline="always")
def longitudinal(sin_theta_i, cos_theta_i, sin_theta_o, cos_theta_o, v):
    """Mp of variance v, in log space for v <= 0.1 as Cycles (also Huang's TRRT+ lobe)."""
    inv_v = 1.0 / v
    cos_arg = cos_theta_i * cos_theta_o * inv_v
    sin_arg = sin_theta_i * sin_theta_o * inv_v
    if v <= 0.1:
        i0 = _log_bessel_i0(cos_arg)
        return math.exp(i0 - sin_arg - inv_v + 0.6931 + math.log(0.5 * inv_v))
    return math.exp(-sin_arg) * _bessel_i0(cos_arg) / (math.sinh(inv_v) * 2.0 * v)


@kernel(inline="always")
def _alpha_angles(sin_theta_o, cos_theta_o, alpha):
    """(sin, cos) of the view elevation tilted for R (-2 alpha), TT (alpha) and TRT (4 alpha)."""
    sin_1 = math.sin(alpha)
    cos_1 = _cos_from_sin(sin_1)
    sin_2 = 2.0 * sin_1 * cos_1
    cos_2 = cos_1 * cos_1 - sin_1 * sin_1
    sin_4 = 2.0 * sin_2 * cos_2
    cos_4 = cos_2 * cos_2 - sin_2 * sin_2
    return (sin_theta_o * cos_2 - cos_theta_o * sin_2, abs(cos_theta_o * cos_2 + sin_theta_o * sin_2),
            sin_theta_o * cos_1 + cos_theta_o * sin_1, abs(cos_theta_o * cos_1 - sin_theta_o * sin_1),
            sin_theta_o * cos_4 + cos_theta_o * sin_4, abs(cos_theta_o * cos_4 - sin_theta_o * sin_4))


@kernel(inline="always")
def _transmittance(sigma, length, cos_theta_t):
    """exp(-sigma length / cos_theta_t), with no absorption along no path (Cycles: NaN for
    infinite sigma) and none surviving an unbounded one (Cycles: NaN for sigma 0)."""
    if sigma == 0.0 or length == 0.0:
        return 1.0
    if cos_theta_t <= 0.0:
        return 0.0
    return math.exp(-sigma * (length / cos_theta_t))


@kernel(inline="always")
def _attenuation_channel(f, t):
    """One channel's Ap of TT, TRT and TRRT+ for Fresnel f and transmittance t (hair_attenuation)."""
    tt = (1.0 - f) * (1.0 - f) * t
    trt = tt * t * f
    return tt, trt, trt * _safe_divide(t * f, 1.0 - t * f)


@kernel(inline="always")
def _fibre(eta, sg0, sg1, sg2, h, sin_theta_o, cos_theta_o):
    """(gamma_o, gamma_t, f, Ap RGB of TT, TRT and TRRT+ (R's is f), the four lobes' sampling weights)."""
    cos_theta_t = _cos_from_sin(_safe_divide(sin_theta_o, eta))
    cos_gamma_o = _cos_from_sin(h)
    gamma_o = _safe_asin(h)
    d = eta * eta - sin_theta_o * sin_theta_o
    # d <= 0 only for eta <= 1 at or past grazing: h is the eta -> 1 limit, and Fresnel is 1 there
    sin_gamma_t = h * cos_theta_o / math.sqrt(d) if d > 0.0 else h
    length = 2.0 * _cos_from_sin(sin_gamma_t)
    gamma_t = _safe_asin(sin_gamma_t)
    f = fresnel_dielectric1(abs(cos_theta_o * cos_gamma_o), eta)
    tt0, trt0, res0 = _attenuation_channel(f, _transmittance(sg0, length, cos_theta_t))
    tt1, trt1, res1 = _attenuation_channel(f, _transmittance(sg1, length, cos_theta_t))
    tt2, trt2, res2 = _attenuation_channel(f, _transmittance(sg2, length, cos_theta_t))
    e1 = LUMA[0] * tt0 + LUMA[1] * tt1 + LUMA[2] * tt2
    e2 = LUMA[0] * trt0 + LUMA[1] * trt1 + LUMA[2] * trt2
    e3 = LUMA[0] * res0 + LUMA[1] * res1 + LUMA[2] * res2
    fac = _safe_divide(1.0, f + e1 + e2 + e3)
    return (gamma_o, gamma_t, f, tt0, tt1, tt2, trt0, trt1, trt2, res0, res1, res2,
            f * fac, e1 * fac, e2 * fac, e3 * fac)


@kernel(inline="always")
def _lobes(v, s, m0, alpha, sin_theta_o, cos_theta_o, gamma_o, gamma_t, sin_theta_i, cos_theta_i, phi):
    """Mp Np of R, TT, TRT and TRRT+ toward the direction at (theta_i, relative azimuth phi)."""
    a0, a1, a2, a3, a4, a5 = _alpha_angles(sin_theta_o, cos_theta_o, alpha)
    r = longitudinal(sin_theta_i, cos_theta_i, a0, a1, m0) * _azimuthal(phi, 0, s, gamma_o, gamma_t)
    tt = longitudinal(sin_theta_i, cos_theta_i, a2, a3, 0.25 * v) * _azimuthal(phi, 1, s, gamma_o, gamma_t)
    trt = longitudinal(sin_theta_i, cos_theta_i, a4, a5, 4.0 * v) * _azimuthal(phi, 2, s, gamma_o, gamma_t)
    res = longitudinal(sin_theta_i, cos_theta_i, sin_theta_o, cos_theta_o, 4.0 * v) / (2.0 * math.pi)
    return r, tt, trt, res


@kernel(inline="always")
def _view(xx, xy, xz, yx, yy, yz, wox, woy, woz):
    """(Z = X x Y normalised, sin theta_o, cos theta_o, phi_o); Z is 0 for a degenerate frame."""
    zx, zy, zz = cross3(xx, xy, xz, yx, yy, yz)
    zx, zy, zz = safe_unit(zx, zy, zz)
    sin_theta_o = wox * xx + woy * xy + woz * xz
    phi_o = math.atan2(wox * zx + woy * zy + woz * zz, wox * yx + woy * yy + woz * yz)
    return zx, zy, zz, sin_theta_o, _cos_from_sin(sin_theta_o), phi_o


@kernel(inline="always")
def chiang_frame(xx, xy, xz, ngx, ngy, ngz, wox, woy, woz):
    """(Y = X x wo normalised, h = (Ng x X) . Z clamped to [-1, 1]) for the unit tangent X: the
    setup's frame and offset for a thick curve; Y and h are 0 when wo is along X."""
    yx, yy, yz = cross3(xx, xy, xz, wox, woy, woz)
    yx, yy, yz = safe_unit(yx, yy, yz)
    zx, zy, zz = cross3(xx, xy, xz, yx, yy, yz)
    zx, zy, zz = safe_unit(zx, zy, zz)
    cx, cy, cz = cross3(ngx, ngy, ngz, xx, xy, xz)
    return yx, yy, yz, min(max(cx * zx + cy * zy + cz * zz, -1.0), 1.0)


@kernel(inline="always")
def chiang_eval(v, s, m0, alpha, eta, sg0, sg1, sg2, h, xx, xy, xz, yx, yy, yz, wox, woy, woz, wix, wiy, wiz):
    """(F RGB = f |cos| toward wi, pdf = F_energy) as Cycles' bsdf_hair_chiang_eval; 0 for a degenerate frame."""
    zx, zy, zz, sin_theta_o, cos_theta_o, phi_o = _view(xx, xy, xz, yx, yy, yz, wox, woy, woz)
    if zx == 0.0 and zy == 0.0 and zz == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    (gamma_o, gamma_t, f, tt0, tt1, tt2, trt0, trt1, trt2, res0, res1, res2,
     e0, e1, e2, e3) = _fibre(eta, sg0, sg1, sg2, h, sin_theta_o, cos_theta_o)
    sin_theta_i = wix * xx + wiy * xy + wiz * xz
    phi_i = math.atan2(wix * zx + wiy * zy + wiz * zz, wix * yx + wiy * yy + wiz * yz)
    r, tt, trt, res = _lobes(v, s, m0, alpha, sin_theta_o, cos_theta_o, gamma_o, gamma_t,
                             sin_theta_i, _cos_from_sin(sin_theta_i), phi_i - phi_o)
    return (f * r + tt0 * tt + trt0 * trt + res0 * res, f * r + tt1 * tt + trt1 * trt + res1 * res,
            f * r + tt2 * tt + trt2 * trt + res2 * res, e0 * r + e1 * tt + e2 * trt + e3 * res)


@kernel(inline="always")
def chiang_sample(v, s, m0, alpha, eta, sg0, sg1, sg2, h, xx, xy, xz, yx, yy, yz, wox, woy, woz, u0, u1, u2):
    """(wi, F RGB, pdf, reflect) as Cycles' bsdf_hair_chiang_sample with rand = (u0, u1, u2); reflect
    when the R lobe was picked. Zero F and pdf (wi = -wo) for a degenerate frame or no weight."""
    zx, zy, zz, sin_theta_o, cos_theta_o, phi_o = _view(xx, xy, xz, yx, yy, yz, wox, woy, woz)
    (gamma_o, gamma_t, f, tt0, tt1, tt2, trt0, trt1, trt2, res0, res1, res2,
     e0, e1, e2, e3) = _fibre(eta, sg0, sg1, sg2, h, sin_theta_o, cos_theta_o)
    energies = (e0, e1, e2, e3)
    p = 0
    uz = u2
    while p < 3 and uz >= energies[p]:
        uz -= energies[p]
        p += 1
    if (zx == 0.0 and zy == 0.0 and zz == 0.0) or energies[p] <= 0.0:
        return -wox, -woy, -woz, 0.0, 0.0, 0.0, 0.0, False
    uz = max(min(uz / energies[p], 1.0), 1e-5)  # at most 1: rounding past the last lobe's weight
    vp = v  # Cycles samples R's elevation with v, not m0 (the two differ only with Coat > 0)
    if p == 1:
        vp *= 0.25
    elif p >= 2:
        vp *= 4.0
    a0, a1, a2, a3, a4, a5 = _alpha_angles(sin_theta_o, cos_theta_o, alpha)
    sin_tilted, cos_tilted = sin_theta_o, cos_theta_o
    if p == 0:
        sin_tilted, cos_tilted = a0, a1
    elif p == 1:
        sin_tilted, cos_tilted = a2, a3
    elif p == 2:
        sin_tilted, cos_tilted = a4, a5
    fac = 1.0 + vp * math.log(uz + (1.0 - uz) * math.exp(-2.0 / vp))
    sin_theta_i = -fac * sin_tilted + _cos_from_sin(fac) * math.cos(2.0 * math.pi * u1) * cos_tilted
    cos_theta_i = _cos_from_sin(sin_theta_i)
    if p < 3:
        phi = _delta_phi(p, gamma_o, gamma_t) + _sample_trimmed_logistic(u0, s)
    else:
        phi = 2.0 * math.pi * u0
    r, tt, trt, res = _lobes(v, s, m0, alpha, sin_theta_o, cos_theta_o, gamma_o, gamma_t,
                             sin_theta_i, cos_theta_i, phi)
    phi_i = phi_o + phi
    ly, lz = cos_theta_i * math.cos(phi_i), cos_theta_i * math.sin(phi_i)
    return (ly * yx + lz * zx + sin_theta_i * xx, ly * yy + lz * zy + sin_theta_i * xy,
            ly * yz + lz * zz + sin_theta_i * xz,
            f * r + tt0 * tt + trt0 * trt + res0 * res, f * r + tt1 * tt + trt1 * trt + res1 * res,
            f * r + tt2 * tt + trt2 * trt + res2 * res, e0 * r + e1 * tt + e2 * trt + e3 * res, p == 0)


@kernel(inline="always")
def chiang_albedo(v, eta, sg0, sg1, sg2, h, xx, xy, xz, wox, woy, woz):
    """Cycles' bsdf_hair_chiang_albedo: exp(-sqrt(sigma) scale(v)) + Fresnel, RGB."""
    f = fresnel_dielectric1(abs(_cos_from_sin(wox * xx + woy * xy + woz * xz) * _cos_from_sin(h)), eta)
    scale = _roughness_scale(v)
    return (math.exp(-math.sqrt(max(sg0, 0.0)) * scale) + f, math.exp(-math.sqrt(max(sg1, 0.0)) * scale) + f,
            math.exp(-math.sqrt(max(sg2, 0.0)) * scale) + f)


@kernel(inline="always")
def chiang_blur(v, s, m0, roughness):
    """(v, s, m0) with each raised to at least ``roughness`` (Filter Glossy, bsdf_hair_chiang_blur)."""
    return max(roughness, v), max(roughness, s), max(roughness, m0)
