"""Sheen lobe as Cycles' microfiber sheen (kernel/closure/bsdf_sheen.h): Zeltner, Burley and Chiang,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines" (2022). A clamped cosine
transformed by the matrix [[a, 0, b], [0, a, 0], [0, 0, 1]] (inverted), in the frame whose tangent
lies toward wo, times the lobe's directional albedo; sampled exactly through the transform.

Cycles reads a, b and the albedo from the paper's 32 x 32 table over (cos theta_o, roughness); DRT
takes the analytic fits of that table MaterialX publishes (mx_microfacet_sheen.glsl,
mx_zeltner_sheen_dir_albedo / _ltc_aInv / _ltc_bInv, adapted from github.com/tizian/ltc-sheen):
no table to ship, and the parity render against Cycles (tests/blender/test_sheen_cycles.py) is
within its limit. A diffuse closure in Cycles: light-sampled, and a path continues through it only
with diffuse bounces on, as the other diffuse lobes here."""
from __future__ import annotations

import math

from ..base.jit import kernel
from ..base.warps import concentric_disk
from .layout import H_COLOUR, P_SHEEN_ROUGH
from .tables import lobe_scale

ROUGH_MIN = 1e-3
"""Cycles' bsdf_sheen_setup clamps the roughness to [1e-3, 1]."""


@kernel(inline="always")
def sheen_albedo(cos_o, rough):
    """Directional albedo at view cosine ``cos_o`` (a Gaussian in cos_o fitted per roughness), in [0, 1]."""
    x = min(max(cos_o, 0.0), 1.0)
    y = rough
    s = y * (0.0206607 + 1.58491 * y) / (0.0379424 + y * (1.32227 + y))
    m = y * (-0.193854 + y * (-1.14885 + y * (1.7932 - 0.95943 * y * y))) / (0.046391 + y)
    o = y * (0.000654023 + (-0.0207818 + 0.119681 * y) * y) / (1.26264 + y * (-1.92021 + y))
    g = math.exp(-0.5 * ((x - m) / s) ** 2) / (s * math.sqrt(2.0 * math.pi)) + o
    return min(max(g, 0.0), 1.0)


@kernel(inline="always")
def sheen_transform(cos_o, rough):
    """(a, b) of the inverse transform at view cosine ``cos_o``: a scales the tangent plane, b (<= 0)
    shears toward wo."""
    x = min(max(cos_o, 0.0), 1.0)
    y = rough
    a = (2.58126 * x + 0.813703 * y) * y / (1.0 + 0.310327 * x * x + 2.60994 * x * y)
    b = math.sqrt(1.0 - x) * (y - 1.0) * y * y * y / (0.0000254053 + 1.71228 * x - 1.71506 * x * y + 1.34174 * y * y)
    return a, b


@kernel(inline="always")
def sheen_frame(wox, woy):
    """Tangent (tx, ty, 0) toward wo in the shading plane (x where wo is the normal); bitangent n x t."""
    length = math.sqrt(wox * wox + woy * woy)
    if length < 1e-9:
        return 1.0, 0.0
    return wox / length, woy / length


@kernel(inline="always")
def sheen_density(a, b, x, y, z):
    """The transformed cosine's density at the unit direction (x, y, z) of the sheen frame."""
    if z <= 0.0:
        return 0.0
    len_sq = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return z / math.pi * (a / len_sq) ** 2


@kernel(inline="always")
def sheen_eval(lp, lt, hp, r, j, t, l, wox, woy, woz, wix, wiy, wiz):
    """f |cos| RGB toward wi, weight and colour included (the albedo times the density), and the density."""
    rough = lp[l, P_SHEEN_ROUGH]
    a, b = sheen_transform(woz, rough)
    albedo = sheen_albedo(woz, rough)
    if abs(a) < 1e-5 or albedo < 1e-5 or wiz <= 0.0:  # Cycles skips the closure
        return 0.0, 0.0, 0.0, 0.0
    tx, ty = sheen_frame(wox, woy)
    p = sheen_density(a, b, wix * tx + wiy * ty, -wix * ty + wiy * tx, wiz)
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    v = albedo * p
    return s0 * hp[r, l, H_COLOUR] * v, s1 * hp[r, l, H_COLOUR + 1] * v, s2 * hp[r, l, H_COLOUR + 2] * v, p


@kernel(inline="always")
def sheen_sample(lp, l, wox, woy, woz, u0, u1):
    """A direction drawn from the transformed cosine (a cosine-weighted disk point, transformed and
    normalised, as Cycles' bsdf_sheen_sample); the mixture weighs it by evaluating every lobe."""
    a, b = sheen_transform(woz, lp[l, P_SHEEN_ROUGH])
    dx, dy = concentric_disk(u0, u1)
    dz = math.sqrt(max(1.0 - dx * dx - dy * dy, 0.0))
    x, y, z = dx - dz * b, dy, dz * a
    norm = math.sqrt(x * x + y * y + z * z)
    if norm <= 0.0:
        return 0.0, 0.0, 1.0
    x, y, z = x / norm, y / norm, z / norm
    tx, ty = sheen_frame(wox, woy)
    return x * tx - y * ty, x * ty + y * tx, z
