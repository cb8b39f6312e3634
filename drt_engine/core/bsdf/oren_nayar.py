"""Oren-Nayar lobe as Cycles 4.3+ computes it (kernel/closure/bsdf_oren_nayar.h): Fujii's improved
Oren-Nayar plus the energy-preserving multiple-scattering term of OpenPBR's "EON" diffuse, so a
white surface reflects everything at every roughness. Evaluated for light sampling only, as the
Lambert lobe (Cycles with diffuse bounces 0 continues no ray from it)."""
from __future__ import annotations

import math

from ..base.jit import kernel
from .layout import H_COLOUR, P_SIGMA
from .tables import lobe_scale

G_GRAZING = math.pi / 2.0 - 2.0 / 3.0
"""G at cos 0; also the sigma factor of the normalisation A = 1 / (pi + sigma G(0))."""


@kernel(inline="always")
def oren_nayar_g(c):
    """Fujii's G(theta): the single-scatter albedo at cos theta is A pi + B G (the tangent's
    cancellation near grazing replaced by its Taylor expansion there, as Cycles does)."""
    if c < 1e-6:
        return G_GRAZING - c
    s = math.sqrt(max(1.0 - c * c, 0.0))
    theta = math.acos(min(c, 1.0))
    return s * (theta - 2.0 / 3.0 - s * c) + 2.0 / 3.0 * (s / c) * (1.0 - s * s * s)


@kernel(inline="always")
def _channel(rho, single, ev, el, e_avg):
    """rho times (single scatter + Cycles' multiple-scattering term) for one albedo channel: Cycles
    weights the closure by its colour and also forms the multiple-scattering albedo from it."""
    rho = min(max(rho, 0.0), 1.0)
    if e_avg >= 1.0:  # sigma 0: Lambert
        return rho * single
    e_ms = rho * rho * (e_avg / (1.0 - e_avg)) / (math.pi * (1.0 - rho * (1.0 - e_avg)))
    return rho * (single + e_ms * (1.0 - ev) * (1.0 - el))


@kernel(inline="always")
def oren_nayar_eval(lp, lt, hp, r, j, t, l, wox, woy, woz, wix, wiy, wiz):
    """f |cos| RGB toward wi in the upper hemisphere (wiz > 0), weight included."""
    sigma = min(max(lp[l, P_SIGMA], 0.0), 1.0)
    a = 1.0 / (math.pi + sigma * G_GRAZING)
    b = sigma * a
    nv, nl = max(woz, 0.0), max(wiz, 0.0)
    s = wox * wix + woy * wiy + woz * wiz - nl * nv
    if s > 0.0:
        s /= max(nl, nv) + 1e-38
    single = a + b * s
    e_avg = a * math.pi + (2.0 * math.pi - 5.6) / 3.0 * b
    ev = a * math.pi + b * oren_nayar_g(nv)
    el = a * math.pi + b * oren_nayar_g(nl)
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    return (s0 * nl * _channel(hp[r, l, H_COLOUR], single, ev, el, e_avg),
            s1 * nl * _channel(hp[r, l, H_COLOUR + 1], single, ev, el, e_avg),
            s2 * nl * _channel(hp[r, l, H_COLOUR + 2], single, ev, el, e_avg))
