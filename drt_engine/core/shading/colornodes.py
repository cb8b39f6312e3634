"""Colour and converter nodes of shader programs that need tables or colour models of their own,
each as Cycles' SVM computes it (kernel/svm/: brightness.h, blackbody.h and math_util.h,
wavelength.h, fresnel.h, color_util.h, ramp.h; the tables of kernel/tables.h). Vectorised over
hits: scalars (N,), colours (N, 3).
"""
from __future__ import annotations

import numpy as np

from ..bsdf.microfacet import fresnel_dielectric

BLACKBODY_R = np.array([
    [1.61919106e+03, -2.05010916e-03, 5.02995757e+00],
    [2.48845471e+03, -1.11330907e-03, 3.22621544e+00],
    [3.34143193e+03, -4.86551192e-04, 1.76486769e+00],
    [4.09461742e+03, -1.27446582e-04, 7.25731635e-01],
    [4.67028036e+03, 2.91258199e-05, 1.26703442e-01],
    [4.59509185e+03, 2.87495649e-05, 1.50345020e-01],
    [3.78717450e+03, 9.35907826e-06, 3.99075871e-01]])
BLACKBODY_G = np.array([
    [-4.88999748e+02, 6.04330754e-04, -7.55807526e-02],
    [-7.55994277e+02, 3.16730098e-04, 4.78306139e-01],
    [-1.02363977e+03, 1.20223470e-04, 9.36662319e-01],
    [-1.26571316e+03, 4.87340896e-06, 1.27054498e+00],
    [-1.42529332e+03, -4.01150431e-05, 1.43972784e+00],
    [-1.17554822e+03, -2.16378048e-05, 1.30408023e+00],
    [-5.00799571e+02, -4.59832026e-06, 1.09098763e+00]])
BLACKBODY_B = np.array([
    [5.96945309e-11, -4.85742887e-08, -9.70622247e-05, -4.07936148e-03],
    [2.40430366e-11, 5.55021075e-08, -1.98503712e-04, 2.89312858e-02],
    [-1.40949732e-11, 1.89878968e-07, -3.56632824e-04, 9.10767778e-02],
    [-3.61460868e-11, 2.84822009e-07, -4.93211319e-04, 1.56723440e-01],
    [-1.97075738e-11, 1.75359352e-07, -2.50542825e-04, -2.22783266e-02],
    [-1.61997957e-13, -1.64216008e-08, 3.86216271e-04, -7.38077418e-01],
    [6.72650283e-13, -2.73078809e-08, 4.24098264e-04, -7.52335691e-01]])
"""Cycles' piecewise fit of the blackbody colour in Rec.709 (kernel/tables.h): R and G as
a / T + b T + c, B as a cubic in T, one row per temperature band."""
BLACKBODY_BANDS = np.array([965.0, 1167.0, 1449.0, 1902.0, 3315.0, 6365.0])
BLACKBODY_HOT = np.array([0.8262954810464208, 0.9945080501520986, 1.566307710274283])  # T >= 12000 K
BLACKBODY_COLD = np.array([5.413294490189271, -0.20319390035873933, -0.0822535242887164])  # T < 800 K

CIE_XYZ = np.array([
    [0.0014, 0.0000, 0.0065], [0.0022, 0.0001, 0.0105], [0.0042, 0.0001, 0.0201],
    [0.0076, 0.0002, 0.0362], [0.0143, 0.0004, 0.0679], [0.0232, 0.0006, 0.1102],
    [0.0435, 0.0012, 0.2074], [0.0776, 0.0022, 0.3713], [0.1344, 0.0040, 0.6456],
    [0.2148, 0.0073, 1.0391], [0.2839, 0.0116, 1.3856], [0.3285, 0.0168, 1.6230],
    [0.3483, 0.0230, 1.7471], [0.3481, 0.0298, 1.7826], [0.3362, 0.0380, 1.7721],
    [0.3187, 0.0480, 1.7441], [0.2908, 0.0600, 1.6692], [0.2511, 0.0739, 1.5281],
    [0.1954, 0.0910, 1.2876], [0.1421, 0.1126, 1.0419], [0.0956, 0.1390, 0.8130],
    [0.0580, 0.1693, 0.6162], [0.0320, 0.2080, 0.4652], [0.0147, 0.2586, 0.3533],
    [0.0049, 0.3230, 0.2720], [0.0024, 0.4073, 0.2123], [0.0093, 0.5030, 0.1582],
    [0.0291, 0.6082, 0.1117], [0.0633, 0.7100, 0.0782], [0.1096, 0.7932, 0.0573],
    [0.1655, 0.8620, 0.0422], [0.2257, 0.9149, 0.0298], [0.2904, 0.9540, 0.0203],
    [0.3597, 0.9803, 0.0134], [0.4334, 0.9950, 0.0087], [0.5121, 1.0000, 0.0057],
    [0.5945, 0.9950, 0.0039], [0.6784, 0.9786, 0.0027], [0.7621, 0.9520, 0.0021],
    [0.8425, 0.9154, 0.0018], [0.9163, 0.8700, 0.0017], [0.9786, 0.8163, 0.0014],
    [1.0263, 0.7570, 0.0011], [1.0567, 0.6949, 0.0010], [1.0622, 0.6310, 0.0008],
    [1.0456, 0.5668, 0.0006], [1.0026, 0.5030, 0.0003], [0.9384, 0.4412, 0.0002],
    [0.8544, 0.3810, 0.0002], [0.7514, 0.3210, 0.0001], [0.6424, 0.2650, 0.0000],
    [0.5419, 0.2170, 0.0000], [0.4479, 0.1750, 0.0000], [0.3608, 0.1382, 0.0000],
    [0.2835, 0.1070, 0.0000], [0.2187, 0.0816, 0.0000], [0.1649, 0.0610, 0.0000],
    [0.1212, 0.0446, 0.0000], [0.0874, 0.0320, 0.0000], [0.0636, 0.0232, 0.0000],
    [0.0468, 0.0170, 0.0000], [0.0329, 0.0119, 0.0000], [0.0227, 0.0082, 0.0000],
    [0.0158, 0.0057, 0.0000], [0.0114, 0.0041, 0.0000], [0.0081, 0.0029, 0.0000],
    [0.0058, 0.0021, 0.0000], [0.0041, 0.0015, 0.0000], [0.0029, 0.0010, 0.0000],
    [0.0020, 0.0007, 0.0000], [0.0014, 0.0005, 0.0000], [0.0010, 0.0004, 0.0000],
    [0.0007, 0.0002, 0.0000], [0.0005, 0.0002, 0.0000], [0.0003, 0.0001, 0.0000],
    [0.0002, 0.0001, 0.0000], [0.0002, 0.0001, 0.0000], [0.0001, 0.0000, 0.0000],
    [0.0001, 0.0000, 0.0000], [0.0001, 0.0000, 0.0000], [0.0000, 0.0000, 0.0000]])
"""CIE 1931 colour matching functions, 380 to 780 nm in steps of 5 nm (Cycles' kernel/tables.h)."""

XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                          [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])
"""CIE XYZ (D65 white) to linear Rec.709, Blender's scene-linear space (Cycles' xyz_to_rgb there)."""


def blackbody(t):
    """(N, 3) Rec.709 colour of a blackbody at ``t`` kelvin, Cycles' fit clamped at 0 (svm_node_blackbody)."""
    t = np.asarray(t, float)
    band = np.searchsorted(BLACKBODY_BANDS, t, side="right")
    safe = np.where(t > 0, t, 1.0)
    r, g, b = BLACKBODY_R[band], BLACKBODY_G[band], BLACKBODY_B[band]
    inv = 1.0 / safe
    out = np.stack([r[:, 0] * inv + r[:, 1] * safe + r[:, 2], g[:, 0] * inv + g[:, 1] * safe + g[:, 2],
                    ((b[:, 0] * safe + b[:, 1]) * safe + b[:, 2]) * safe + b[:, 3]], axis=1)
    out = np.where((t >= 12000.0)[:, None], BLACKBODY_HOT, out)
    out = np.where((t < 800.0)[:, None], BLACKBODY_COLD, out)
    return np.maximum(out, 0.0)


def wavelength(nm):
    """(N, 3) colour of light of wavelength ``nm``: the CIE matching functions interpolated,
    to Rec.709, divided by 2.52 and clamped at 0 (svm_node_wavelength)."""
    ii = (np.asarray(nm, float) - 380.0) / 5.0
    i = np.trunc(np.where(np.isfinite(ii), ii, -1.0)).astype(np.int64)  # C's float-to-int truncates
    ok = (i >= 0) & (i < 80)
    k = np.clip(i, 0, 79)
    f = (ii - k)[:, None]
    xyz = np.where(ok[:, None], CIE_XYZ[k] + f * (CIE_XYZ[k + 1] - CIE_XYZ[k]), 0.0)
    return np.maximum(xyz @ XYZ_TO_REC709.T / 2.52, 0.0)


def fresnel(ior, cosi, backfacing):
    """The Fresnel node: its IOR (at least 1e-5) inverted on backfacing hits."""
    eta = np.maximum(ior, 1e-5)
    return fresnel_dielectric(np.abs(cosi), np.where(backfacing, 1.0 / eta, eta))


def layer_weight(blend, cosi, backfacing):
    """(Fresnel, Facing) outputs of the Layer Weight node."""
    eta = np.maximum(1.0 - blend, 1e-5)
    fres = fresnel_dielectric(np.abs(cosi), np.where(backfacing, eta, 1.0 / eta))
    b = np.clip(blend, 0.0, 1.0 - 1e-5)
    exponent = np.where(b < 0.5, 2.0 * b, 0.5 / (1.0 - b))
    c = np.abs(cosi)
    with np.errstate(all="ignore"):
        facing = np.where(blend != 0.5, np.power(c, exponent), c)
    return fres, 1.0 - facing


def brightness_contrast(c, bright, contrast):
    a = 1.0 + contrast[:, None]
    b = (bright - 0.5 * contrast)[:, None]
    return np.maximum(a * c + b, 0.0)


def rgb_to_hsl(c):
    """Cycles' rgb_to_hsl (h, s, l; l capped at 1)."""
    r, g, b = c[:, 0], c[:, 1], c[:, 2]
    cmax, cmin = c.max(axis=1), c.min(axis=1)
    lum = np.minimum(1.0, 0.5 * (cmax + cmin))
    delta = cmax - cmin
    grey = cmax == cmin
    d = np.where(grey, 1.0, delta)
    with np.errstate(all="ignore"):
        s = np.where(lum > 0.5, delta / (2.0 - cmax - cmin), delta / (cmax + cmin))
    h = np.where(cmax == r, (g - b) / d + np.where(g < b, 6.0, 0.0),
                 np.where(cmax == g, (b - r) / d + 2.0, (r - g) / d + 4.0))
    return np.stack([np.where(grey, 0.0, h / 6.0), np.where(grey, 0.0, s), lum], axis=1)


def hsl_to_rgb(hsl):
    """Cycles' hsl_to_rgb."""
    h, s, lum = hsl[:, 0], hsl[:, 1], hsl[:, 2]
    n = np.stack([np.abs(h * 6.0 - 3.0) - 1.0, 2.0 - np.abs(h * 6.0 - 2.0), 2.0 - np.abs(h * 6.0 - 4.0)], axis=1)
    chroma = (1.0 - np.abs(2.0 * lum - 1.0)) * s
    return (np.clip(n, 0.0, 1.0) - 0.5) * chroma[:, None] + lum[:, None]


def table_lookup(table, f, interpolate=True, extrapolate=False):
    """Cycles' rgb_ramp_lookup / float_ramp_lookup: ``table`` (K, C) sampled evenly over [0, 1] at
    ``f`` (N,); linear between entries (when ``interpolate``), clamped outside [0, 1] or carried
    on along the end segments (when ``extrapolate``). Returns (N, C)."""
    table = np.asarray(table, float)
    size = len(table)
    f = np.asarray(f, float)
    g = np.clip(np.where(np.isnan(f), 0.0, f), 0.0, 1.0) * (size - 1)
    i = np.clip(np.trunc(g).astype(np.int64), 0, size - 1)
    t = (g - i)[:, None]
    out = table[i]
    if interpolate:
        out = np.where(t > 0, (1.0 - t) * out + t * table[np.minimum(i + 1, size - 1)], out)
    if extrapolate:
        low = table[0] + (table[0] - table[1]) * (-f)[:, None] * (size - 1)
        high = table[-1] + (table[-1] - table[-2]) * (f - 1.0)[:, None] * (size - 1)
        out = np.where((f < 0)[:, None], low, np.where((f > 1)[:, None], high, out))
    return out


def curves(fac, c, table, lo, hi, extrapolate):
    """RGB Curves and Vector Curves (svm_node_curves): each channel through its column of ``table``
    over [lo, hi], mixed with the input by ``fac``."""
    rel = (c - lo) / (hi - lo) if hi != lo else np.zeros_like(c)
    mapped = np.stack([table_lookup(table[:, k:k + 1], rel[:, k], True, extrapolate)[:, 0] for k in range(3)],
                      axis=1)
    return (1.0 - fac[:, None]) * c + fac[:, None] * mapped


def float_curve(fac, v, table, lo, hi, extrapolate):
    """Float Curve (svm_node_curve)."""
    rel = (v - lo) / (hi - lo) if hi != lo else np.zeros_like(v)
    mapped = table_lookup(np.asarray(table, float)[:, None], rel, True, extrapolate)[:, 0]
    return (1.0 - fac) * v + fac * mapped
