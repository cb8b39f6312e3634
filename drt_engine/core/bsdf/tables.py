"""Reading a lobe's albedo tables at a view cosine, and the weights and albedos built on them.

A ray finds its place among the table cosines once (``locate``) and reads every table of every
lobe there (``at``); the albedos drive lobe choice, layering, multiple-scattering compensation
and the pass colours.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from . import microfacet as mf
from .layout import (GLASS, H_COLOUR, H_F0, H_PLACE, H_SCALE, H_TINT_R, H_TINT_T, P_A_AVG, P_AFFINE, P_B_AVG,
                     P_E_AVG, P_KIND, P_LAYER_TINT, P_LAYERS, P_MS, P_OWN_NORMAL, P_UNDER_OWN, P_WEIGHT, REFLECT, SHEEN,
                     T_E, T_E1, T_EA, T_EB, T_LAYER_E, T_MS, T_UNDER)


@kernel(inline="always")
def locate(mu, x):
    """Where x falls in the table cosines ``mf.MU_TABLE``: (j, t) with x = mu[j] + t (mu[j + 1] - mu[j]),
    held at the ends. Found once per ray; every table of every lobe is then read with ``at``.
    The index comes from the table's two spacings, not a search (a binary search over random
    cosines mispredicts half its steps: it cost more than a diffuse lobe's evaluation)."""
    n = len(mu)
    y = min(max(x, mu[0]), mu[n - 1])
    if y >= mf.MU_SPLIT:
        j = mf.MU_GEOMETRIC - 1 + int((y - mf.MU_SPLIT) * ((mf.MU_LINEAR - 1) / (1.0 - mf.MU_SPLIT)))
    else:
        j = int(np.log(y / mf.MU_GRAZING) * ((mf.MU_GEOMETRIC - 1) / np.log(mf.MU_SPLIT / mf.MU_GRAZING)))
    j = min(max(j, 0), n - 2)
    if mu[j + 1] <= y and j < n - 2:  # rounding of the index near a table point
        j += 1
    elif mu[j] > y and j > 0:
        j -= 1
    return j, (y - mu[j]) / (mu[j + 1] - mu[j])


@kernel(inline="always")
def at(lt, l, k, j, t):
    """Table k of lobe l at the cosine ``locate`` found (linear interpolation)."""
    return lt[l, k, j] + (lt[l, k, j + 1] - lt[l, k, j]) * t


@kernel(inline="always")
def place(lp, hp, r, l, j, t):
    """Where lobe l reads its own tables: at the ray's (j, t), or for a lobe with its own normal
    (a Coat Normal) at wo's cosine to that normal, located once per hit (``H_PLACE``)."""
    if lp[l, P_OWN_NORMAL] != 0.0:
        return int(hp[r, l, H_PLACE]), hp[r, l, H_PLACE + 1]
    return j, t


@kernel(inline="always")
def lobe_scale(lp, lt, hp, r, j, t, l):
    """RGB weight of lobe l: constant weight, attenuation by the layers above (the coat's read at
    the coat normal's cosine, as Cycles takes the coat's albedo, where it has its own), per-hit scale."""
    a0 = a1 = a2 = 1.0
    for m in range(int(lp[l, P_LAYERS])):
        if m == 0 and lp[l, P_UNDER_OWN] != 0.0:
            att = min(max(1.0 - at(lt, l, T_UNDER, int(hp[r, l, H_PLACE]), hp[r, l, H_PLACE + 1]), 0.0), 1.0)
        else:
            att = min(max(1.0 - at(lt, l, T_UNDER + m, j, t), 0.0), 1.0)
        k = P_LAYER_TINT + 3 * m
        a0 *= att * lp[l, k]
        a1 *= att * lp[l, k + 1]
        a2 *= att * lp[l, k + 2]
    return (lp[l, P_WEIGHT] * a0 * hp[r, l, H_SCALE], lp[l, P_WEIGHT + 1] * a1 * hp[r, l, H_SCALE + 1],
            lp[l, P_WEIGHT + 2] * a2 * hp[r, l, H_SCALE + 2])


@kernel(inline="always")
def affine_albedo(lp, lt, hp, r, j, t, l):
    """(single-scatter albedo RGB, multiple-scattering factor) of a lobe whose Fresnel is
    f0 A + B for the per-hit colour f0."""
    e0 = hp[r, l, H_F0] * at(lt, l, T_EA, j, t) + at(lt, l, T_EB, j, t)
    e1 = hp[r, l, H_F0 + 1] * at(lt, l, T_EA + 1, j, t) + at(lt, l, T_EB + 1, j, t)
    e2 = hp[r, l, H_F0 + 2] * at(lt, l, T_EA + 2, j, t) + at(lt, l, T_EB + 2, j, t)
    if lp[l, P_MS] == 0.0:
        return e0, e1, e2, 1.0
    f_avg = ((hp[r, l, H_F0] * lp[l, P_A_AVG] + lp[l, P_B_AVG])
             + (hp[r, l, H_F0 + 1] * lp[l, P_A_AVG + 1] + lp[l, P_B_AVG + 1])
             + (hp[r, l, H_F0 + 2] * lp[l, P_A_AVG + 2] + lp[l, P_B_AVG + 2])) / 3.0
    e_avg = lp[l, P_E_AVG]
    f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
    e_w = at(lt, l, T_E1, j, t)
    return e0, e1, e2, 1.0 + f_ms * (1.0 - e_w) / max(e_w, 1e-3)


@kernel(inline="always")
def ms_factor(lp, lt, hp, r, j, t, l):
    """Multiple-scattering compensation of lobe l's single-scatter f (1: none)."""
    j, t = place(lp, hp, r, l, j, t)
    if lp[l, P_AFFINE] != 0.0:
        return affine_albedo(lp, lt, hp, r, j, t, l)[3]
    if lp[l, P_MS] != 0.0:
        return at(lt, l, T_MS, j, t)
    return 1.0


@kernel(inline="always")
def reflect_albedo(lp, lt, hp, r, j, t, l, layering):
    """Albedo of a reflect lobe without its weight: total, or as Cycles estimates it for
    layering and GlossCol (``layering``)."""
    j, t = place(lp, hp, r, l, j, t)
    if lp[l, P_AFFINE] == 0.0:
        k = T_LAYER_E if layering else T_E
        return at(lt, l, k, j, t), at(lt, l, k + 1, j, t), at(lt, l, k + 2, j, t)
    e0, e1, e2, factor = affine_albedo(lp, lt, hp, r, j, t, l)
    if lp[l, P_MS] == 0.0 and layering:
        d = max(at(lt, l, T_E1, j, t), 1e-6)
        return e0 / d, e1 / d, e2 / d
    return e0 * factor, e1 * factor, e2 * factor


@kernel(inline="always")
def lobe_albedo(lp, lt, hp, r, j, t, l):
    """Directional albedo of lobe l including its weight and the layers above."""
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    kind = int(lp[l, P_KIND])
    if kind == REFLECT:
        e0, e1, e2 = reflect_albedo(lp, lt, hp, r, j, t, l, False)
        return s0 * e0, s1 * e1, s2 * e2
    if kind == GLASS:
        return (s0 * max(hp[r, l, H_TINT_R], hp[r, l, H_TINT_T]),
                s1 * max(hp[r, l, H_TINT_R + 1], hp[r, l, H_TINT_T + 1]),
                s2 * max(hp[r, l, H_TINT_R + 2], hp[r, l, H_TINT_T + 2]))
    if kind == SHEEN:  # its colour times its tabulated albedo
        e = at(lt, l, T_E, j, t)
        return s0 * hp[r, l, H_COLOUR] * e, s1 * hp[r, l, H_COLOUR + 1] * e, s2 * hp[r, l, H_COLOUR + 2] * e
    return s0 * hp[r, l, H_COLOUR], s1 * hp[r, l, H_COLOUR + 1], s2 * hp[r, l, H_COLOUR + 2]
