"""Thin-film Fresnel: a film of some thickness and IOR over a dielectric or a metal, as Cycles'
``fresnel_iridescence`` (kernel/closure/bsdf_util.h) computes it for the Principled BSDF.

Belcour and Barla 2017: the two interfaces' polarised Fresnel and phase shifts, the Airy series
over the film's round trips truncated after three, each term's spectral integral read from the
Fourier transform of the colour matching functions at the optical path difference (OPD). That
transform (``SENSITIVITY``) is DRT's own: the CIE 1931 functions from Wyman, Sloan and Shirley's
multi-lobe Gaussian fit (JCGT 2013), turned into linear Rec.709 with the XYZ (D65) matrix Cycles
uses, integrated over wavelength and normalised so that each channel's DC term is 1. Like
Cycles' table it covers OPDs up to 60 um / 2 pi and holds its last value past that.

Films up to ``CUTOFF`` nm are no film (Cycles' THINFILM_THICKNESS_CUTOFF); below 1 nm the film's
IOR blends toward the outside's, as Cycles does. Per-ray functions return RGB reflectance.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel

CUTOFF = 0.1
"""Thickness (nm) up to which Cycles renders no film."""

OPD_MAX = 60000.0 / (2.0 * np.pi)
"""Largest optical path difference (nm) Cycles' sensitivity table covers (it clamps past it)."""
TABLE_SIZE = 2048

XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                          [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])
"""CIE XYZ (D65) to linear Rec.709, the matrix Cycles defaults to (scene/shader.cpp)."""


def _lobe(lam, mu, s_below, s_above):
    s = np.where(lam < mu, s_below, s_above)
    return np.exp(-0.5 * ((lam - mu) / s) ** 2)


def cmf_xyz(lam: np.ndarray) -> np.ndarray:
    """(N, 3) CIE 1931 2-degree x, y, z at wavelengths ``lam`` (nm): Wyman, Sloan and Shirley's
    multi-lobe piecewise-Gaussian fit."""
    x = (1.056 * _lobe(lam, 599.8, 37.9, 31.0) + 0.362 * _lobe(lam, 442.0, 16.0, 26.7)
         - 0.065 * _lobe(lam, 501.1, 20.4, 26.2))
    y = 0.821 * _lobe(lam, 568.8, 46.9, 40.5) + 0.286 * _lobe(lam, 530.9, 16.3, 31.1)
    z = 1.217 * _lobe(lam, 437.0, 11.8, 36.0) + 0.681 * _lobe(lam, 459.0, 26.0, 13.8)
    return np.stack([x, y, z], axis=-1)


def sensitivity_table(size: int = TABLE_SIZE) -> np.ndarray:
    """(6, size): real parts (R, G, B) then imaginary parts of S(OPD) = integral of the RGB
    matching function times exp(-2 pi i OPD / lambda) d lambda over its integral, at ``size``
    OPDs evenly from 0 to OPD_MAX."""
    lam = np.linspace(360.0, 830.0, 4701)
    rgb = cmf_xyz(lam) @ XYZ_TO_REC709.T
    opd = np.linspace(0.0, OPD_MAX, size)
    phase = np.exp(-2j * np.pi * opd[:, None] / lam[None, :])
    s = phase @ rgb  # (size, 3), uniform d lambda
    s /= s[0].real
    return np.ascontiguousarray(np.concatenate([s.real.T, s.imag.T]))


def sensitivity() -> np.ndarray:
    """``SENSITIVITY``, made on first use and kept: it costs 0.6 s of CPU, which a process whose
    kernels load from the cache and whose materials have no film never needs."""
    table = globals().get("SENSITIVITY")
    if table is None:
        table = globals()["SENSITIVITY"] = sensitivity_table()
    return table


def __getattr__(name: str):
    """``tf.SENSITIVITY`` (what the kernels read, when they compile) through ``sensitivity()``."""
    if name == "SENSITIVITY":
        return sensitivity()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@kernel(inline="always")
def _sensitivity(table, opd, c):
    """S at ``opd`` for channel c: (real, imaginary), linear between entries, held past the end."""
    n = table.shape[1]
    x = min(max(opd / OPD_MAX, 0.0), 1.0) * (n - 1)
    i = min(int(x), n - 2)
    t = x - i
    re = table[c, i] + (table[c, i + 1] - table[c, i]) * t
    im = table[3 + c, i] + (table[3 + c, i + 1] - table[3 + c, i]) * t
    return re, im


@kernel(inline="always")
def polarized(cos_i, eta):
    """Dielectric Fresnel per polarisation: (R_s, R_p, cos of the refracted ray (negative),
    sign of r_s, sign of r_p, total internal reflection)."""
    d = eta * eta - (1.0 - cos_i * cos_i)
    if d <= 0.0:
        return 1.0, 1.0, 0.0, 1.0, 1.0, True
    c = abs(cos_i)
    cos_t = -np.sqrt(d) / eta
    r_s = (c + eta * cos_t) / (c - eta * cos_t)
    r_p = (cos_t + eta * c) / (eta * c - cos_t)
    return r_s * r_s, r_p * r_p, cos_t, 1.0 if r_s >= 0.0 else -1.0, 1.0 if r_p >= 0.0 else -1.0, False


@kernel(inline="always")
def _airy(table, c, r12, r23, opd, ph_re, ph_im):
    """Reflectance of channel c from the Airy series of one polarisation (three orders), the
    round trip's phase shift as the phasor (ph_re, ph_im)."""
    t121 = 1.0 - r12
    r123 = r12 * r23
    if r123 >= 1.0:
        return 1.0
    rs = t121 * t121 * r23 / (1.0 - r123)
    r = rs + r12
    cm = rs - t121
    sq = np.sqrt(r123)
    a_re, a_im = ph_re, ph_im
    for m in range(1, 4):
        cm *= sq
        s_re, s_im = _sensitivity(table, m * opd, c)
        r += cm * 2.0 * (a_re * s_re + a_im * s_im)
        a_re, a_im = a_re * ph_re - a_im * ph_im, a_re * ph_im + a_im * ph_re
    return r


@kernel(inline="always")
def _film_top(cos_i, thickness, film_ior):
    """The film's IOR (blended toward the outside's below 1 nm), and the top interface."""
    if thickness < 1.0:
        t = min(max(thickness, 0.0), 1.0)
        film_ior = 1.0 + (film_ior - 1.0) * t * t * (3.0 - 2.0 * t)
    return (film_ior,) + polarized(cos_i, film_ior)


@kernel
def film_dielectric(table, cos_i, thickness, film_ior, eta):
    """RGB reflectance at cos(wo, h) = cos_i of a film (thickness nm, IOR relative to the outside)
    over a dielectric of relative IOR eta."""
    film, r12_s, r12_p, cos2, sg12_s, sg12_p, tir = _film_top(cos_i, thickness, film_ior)
    if tir:
        return 1.0, 1.0, 1.0
    r23_s, r23_p, _, sg23_s, sg23_p, tir23 = polarized(-cos2, eta / film)
    if tir23:
        return 1.0, 1.0, 1.0
    opd = -2.0 * film * thickness * cos2
    ps, pp = -sg23_s * sg12_s, -sg23_p * sg12_p
    return (min(max(0.5 * (_airy(table, 0, r12_s, r23_s, opd, ps, 0.0) + _airy(table, 0, r12_p, r23_p, opd, pp, 0.0)),
                    0.0), 1.0),
            min(max(0.5 * (_airy(table, 1, r12_s, r23_s, opd, ps, 0.0) + _airy(table, 1, r12_p, r23_p, opd, pp, 0.0)),
                    0.0), 1.0),
            min(max(0.5 * (_airy(table, 2, r12_s, r23_s, opd, ps, 0.0) + _airy(table, 2, r12_p, r23_p, opd, pp, 0.0)),
                    0.0), 1.0))


@kernel(inline="always")
def f82_value(cos_i, f0, b):
    """Cycles' F82 metal Fresnel of one channel with its precomputed b term (clamped)."""
    s = min(max(1.0 - cos_i, 0.0), 1.0)
    s5 = s * s * s * s * s
    return min(max(f0 + (1.0 - f0) * s5 - b * cos_i * s5 * s, 0.0), 1.0)


@kernel(inline="always")
def f82_b(f0, f82):
    """The b term of the F82 model that takes the value f82 at cos = 1/7."""
    f = 6.0 / 7.0
    f5 = f * f * f * f * f
    return (7.0 / (f5 * f)) * (f0 + (1.0 - f0) * f5 - f82)


@kernel(inline="always")
def _conductor_channel(table, c, cos_i, thickness, film_ior, f0, tint):
    """Channel c of a film over Cycles' F82-tint metal (f0, tint): n and k from f0 and the value
    at 82 degrees (Gulbrandsen's mapping), the bottom interface's reflectance from the F82 model
    rescaled to the film, its phase shifts from the complex Fresnel equations."""
    film, r12_s, r12_p, cos2, sg12_s, sg12_p, tir = _film_top(cos_i, thickness, film_ior)
    if tir:
        return 1.0
    f5 = (6.0 / 7.0) ** 5
    g = min(max((f0 + (1.0 - f0) * f5) * tint, 0.0), 1.0)
    r = min(f0, 0.999)
    sr = np.sqrt(max(r, 0.0))
    n = (1.0 + sr) / (1.0 - sr) + ((1.0 - r) / (1.0 + r) - (1.0 + sr) / (1.0 - sr)) * g
    k = np.sqrt(max((r * (n + 1.0) ** 2 - (n - 1.0) ** 2) / (1.0 - r), 0.0))
    cosi = -cos2
    e1 = film
    t1 = n * n - k * k - e1 * e1 * (1.0 - cosi * cosi)
    t2 = np.sqrt(t1 * t1 + (2.0 * n * k) ** 2)
    u2, v2 = max(0.5 * (t2 + t1), 0.0), max(0.5 * (t2 - t1), 0.0)
    u, v = np.sqrt(u2), np.sqrt(v2)
    nn, kk = n / e1, (k / e1) ** 2
    f0_film = ((nn - 1.0) ** 2 + kk) / ((nn + 1.0) ** 2 + kk)
    r23 = f82_value(cosi, f0_film, f82_b(f0_film, g))
    re_s = -u2 - v2 + (e1 * cosi) ** 2
    im_s = -2.0 * e1 * cosi * v
    mag_s = np.sqrt(re_s * re_s + im_s * im_s)
    ps_re, ps_im = (1.0, 0.0) if mag_s == 0.0 else (re_s / mag_s, im_s / mag_s)
    re_p = ((n * n + k * k) * cosi) ** 2 - e1 * e1 * (u2 + v2)
    im_p = 2.0 * e1 * cosi * (2.0 * n * k * u - (n * n - k * k) * v)
    mag_p = np.sqrt(re_p * re_p + im_p * im_p)
    pp_re, pp_im = (1.0, 0.0) if mag_p == 0.0 else (re_p / mag_p, im_p / mag_p)
    opd = -2.0 * film * thickness * cos2
    rs = _airy(table, c, r12_s, r23, opd, -sg12_s * ps_re, -sg12_s * ps_im)
    rp = _airy(table, c, r12_p, r23, opd, -sg12_p * pp_re, -sg12_p * pp_im)
    return min(max(0.5 * (rs + rp), 0.0), 1.0)


@kernel
def film_conductor(table, cos_i, thickness, film_ior, f0r, f0g, f0b, tr, tg, tb):
    """RGB reflectance of a film over Cycles' F82-tint metal of colour f0 and edge tint t."""
    return (_conductor_channel(table, 0, cos_i, thickness, film_ior, f0r, tr),
            _conductor_channel(table, 1, cos_i, thickness, film_ior, f0g, tg),
            _conductor_channel(table, 2, cos_i, thickness, film_ior, f0b, tb))


@kernel(inline="always")
def tinted(f, tint, f0_real):
    """Cycles' specular tint on a film's reflectance f of one channel (generalized Schlick's
    thin-film branch): scaled by tint where f is near the substrate's F0, untouched toward 1."""
    if f0_real <= 1e-5 or f >= 1.0:
        return f
    s = min(max((f - 1.0) / (f0_real - 1.0), 0.0), 1.0)
    return f * (1.0 + (tint - 1.0) * s)


@kernel
def _dielectric_rows(table, cos_i, thickness, film_ior, eta, tint, out):
    f0_real = ((eta - 1.0) / (eta + 1.0)) ** 2
    for i in range(len(cos_i)):
        r, g, b = film_dielectric(table, cos_i[i], thickness, film_ior, eta)
        out[i, 0] = tinted(r, tint[0], f0_real)
        out[i, 1] = tinted(g, tint[1], f0_real)
        out[i, 2] = tinted(b, tint[2], f0_real)


@kernel
def _conductor_rows(table, cos_i, thickness, film_ior, f0, tint, out):
    for i in range(len(cos_i)):
        out[i, 0], out[i, 1], out[i, 2] = film_conductor(table, cos_i[i], thickness, film_ior, f0[0], f0[1], f0[2],
                                                         tint[0], tint[1], tint[2])


def dielectric(cos_i, thickness: float, film_ior: float, eta: float, tint=np.ones(3)) -> np.ndarray:
    """(N, 3) ``film_dielectric`` with Cycles' specular ``tint`` over an array of cosines (tables)."""
    cos_i = np.ascontiguousarray(np.atleast_1d(cos_i), np.float64)
    out = np.empty((len(cos_i), 3))
    _dielectric_rows(sensitivity(), cos_i, float(thickness), float(film_ior), float(eta),
                     np.ascontiguousarray(tint, np.float64), out)
    return out


def conductor(cos_i, thickness: float, film_ior: float, f0, tint) -> np.ndarray:
    """(N, 3) ``film_conductor`` over an array of cosines (tables)."""
    cos_i = np.ascontiguousarray(np.atleast_1d(cos_i), np.float64)
    out = np.empty((len(cos_i), 3))
    _conductor_rows(sensitivity(), cos_i, float(thickness), float(film_ior), np.ascontiguousarray(f0, np.float64),
                    np.ascontiguousarray(tint, np.float64), out)
    return out
