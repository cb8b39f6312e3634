"""Sheen lobe as Cycles' microfiber sheen (kernel/closure/bsdf_sheen.h): Zeltner, Burley and Chiang,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines" (2022). A clamped cosine
transformed by the matrix [[a, 0, b], [0, a, 0], [0, 0, 1]] (inverted), in the frame whose tangent
lies toward wo, times the lobe's directional albedo; sampled exactly through the transform.

a, b and the albedo come from the paper's table over (roughness, cos theta_o), the one Cycles
ships (``sheen_table``), read as Cycles' lookup_table_read_2D reads it: linear in roughness once per
lobe (``sheen_rows``, into the lobe's constants), linear in the view cosine per ray. (MaterialX's
analytic fits of that table were tried first: their a is up to about 10% off the table's, which put
a rim lit from behind 0.020 off Cycles against a limit of 0.016.) A diffuse closure in Cycles:
light-sampled, and a path continues through it only with diffuse bounces on, as the other diffuse
lobes here."""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel
from ..base.warps import concentric_disk
from .layout import H_COLOUR, P_SHEEN_TABLE, SHEEN_N
from .sheen_table import TABLE
from .tables import lobe_scale

ROUGH_MIN = 1e-3
"""Cycles' bsdf_sheen_setup clamps the roughness to [1e-3, 1]."""


def sheen_rows(rough: float) -> np.ndarray:
    """(3, SHEEN_N) a, b and albedo over the view cosines at ``rough`` (clamped to [1e-3, 1] as
    bsdf_sheen_setup), linear between the table's roughness rows as lookup_table_read_2D."""
    y = float(np.clip(rough, ROUGH_MIN, 1.0)) * (TABLE.shape[1] - 1)
    i = min(int(y), TABLE.shape[1] - 1)
    t = y - i
    return (1.0 - t) * TABLE[:, i] + t * TABLE[:, min(i + 1, TABLE.shape[1] - 1)]


def sheen_albedo(rows: np.ndarray, cos_o) -> np.ndarray:
    """The albedo of ``sheen_rows`` at view cosines ``cos_o`` (NumPy, ``sheen_lookup``'s reading)."""
    return np.interp(np.clip(cos_o, 0.0, 1.0) * (SHEEN_N - 1), np.arange(SHEEN_N), rows[2])


@kernel(inline="always")
def sheen_lookup(lp, l, k, cos_o):
    """Row k (0: a, 1: b, 2: albedo) of the lobe's table at view cosine ``cos_o``, linear between
    the table's cosines as Cycles' lookup_table_read."""
    x = min(max(cos_o, 0.0), 1.0) * (SHEEN_N - 1)
    i = min(int(x), SHEEN_N - 1)
    n = min(i + 1, SHEEN_N - 1)
    t = x - i
    base = P_SHEEN_TABLE + k * SHEEN_N
    return (1.0 - t) * lp[l, base + i] + t * lp[l, base + n]


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
    a, b, albedo = sheen_lookup(lp, l, 0, woz), sheen_lookup(lp, l, 1, woz), sheen_lookup(lp, l, 2, woz)
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
    a, b = sheen_lookup(lp, l, 0, woz), sheen_lookup(lp, l, 1, woz)
    dx, dy = concentric_disk(u0, u1)
    dz = math.sqrt(max(1.0 - dx * dx - dy * dy, 0.0))
    x, y, z = dx - dz * b, dy, dz * a
    norm = math.sqrt(x * x + y * y + z * z)
    if norm <= 0.0:
        return 0.0, 0.0, 1.0
    x, y, z = x / norm, y / norm, z / norm
    tx, ty = sheen_frame(wox, woy)
    return x * tx - y * ty, x * ty + y * tx, z
