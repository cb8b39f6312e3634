"""Toon lobes as Cycles defines them (kernel/closure/bsdf_toon.h, from OSL): a constant intensity
inside a cone of half-angle ``size``, falling linearly to 0 over a further ``smooth``, divided by
the solid angle of the cone they are sampled in (size + smooth, at most a hemisphere). The diffuse
lobe's cone is about the shading normal (a diffuse closure: light sampling only, a diffuse bounce
with diffuse bounces on); the glossy lobe's about wo mirrored in the normal (a glossy closure that
paths continue through). Neither has a cosine factor: the intensity is f |cos| itself."""
from __future__ import annotations

import math

from ..base import vectors as vec
from ..base.jit import kernel
from .layout import H_COLOUR, P_TOON_SIZE, P_TOON_SMOOTH
from .tables import lobe_scale


@kernel(inline="always")
def toon_intensity(size, smooth, angle):
    """1 within ``size`` of the cone's axis, falling linearly to 0 over ``smooth`` past it."""
    if angle < size:
        return 1.0
    if smooth != 0.0 and angle < size + smooth:
        return 1.0 - (angle - size) / smooth
    return 0.0


@kernel(inline="always")
def toon_cone(lp, l):
    """(1 - cos of the sampled cone's half-angle min(size + smooth, pi / 2), that half-angle)."""
    angle = min(lp[l, P_TOON_SIZE] + lp[l, P_TOON_SMOOTH], 0.5 * math.pi)
    s = math.sin(0.5 * angle)
    return 2.0 * s * s, angle


@kernel(inline="always")
def toon_value(lp, l, cos_axis):
    """(f |cos| without colour and weight, density of sampling it) toward a direction at cosine
    ``cos_axis`` from the lobe's cone axis: both 0 outside the cone."""
    one_minus_cos, cone = toon_cone(lp, l)
    angle = math.acos(min(max(cos_axis, 0.0), 1.0))
    if angle >= cone:
        return 0.0, 0.0
    pdf = 1.0 / (2.0 * math.pi * one_minus_cos)
    return pdf * toon_intensity(lp[l, P_TOON_SIZE], lp[l, P_TOON_SMOOTH], angle), pdf


@kernel(inline="always")
def toon_diffuse_eval(lp, lt, hp, r, j, t, l, wiz):
    """Diffuse toon f |cos| RGB toward wi, weight included, and its density: the cone is about the normal."""
    if wiz < 0.0:
        return 0.0, 0.0, 0.0, 0.0
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    v, pdf = toon_value(lp, l, wiz)
    return s0 * hp[r, l, H_COLOUR] * v, s1 * hp[r, l, H_COLOUR + 1] * v, s2 * hp[r, l, H_COLOUR + 2] * v, pdf


@kernel(inline="always")
def toon_glossy_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz):
    """Glossy toon f |cos| RGB toward wi (without the lobe's weight), and its density: the cone
    is about wo mirrored in the normal; nothing below the surface."""
    if woz <= 0.0 or wiz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    v, pdf = toon_value(lp, l, -wox * wix - woy * wiy + woz * wiz)
    return hp[r, l, H_COLOUR] * v, hp[r, l, H_COLOUR + 1] * v, hp[r, l, H_COLOUR + 2] * v, pdf


@kernel(inline="always")
def toon_cone_sample(lp, l, ax, ay, az, u0, u1):
    """A direction uniform in the lobe's cone about the unit axis a (as Cycles' sample_uniform_cone)."""
    one_minus_cos, _ = toon_cone(lp, l)
    z = 1.0 - u0 * one_minus_cos
    sin_t = math.sqrt(max(1.0 - z * z, 0.0))
    phi = 2.0 * math.pi * u1
    x, y = sin_t * math.cos(phi), sin_t * math.sin(phi)
    tx, ty, tz, bx, by, bz = vec.basis(ax, ay, az)
    return x * tx + y * bx + z * ax, x * ty + y * by + z * ay, x * tz + y * bz + z * az


@kernel(inline="always")
def toon_glossy_sample(lp, hp, r, l, wox, woy, woz, u0, u1):
    """Sample the glossy lobe alone: (wi, weight f |cos| / pdf RGB without the lobe's weight, valid)."""
    wix, wiy, wiz = toon_cone_sample(lp, l, -wox, -woy, woz, u0, u1)
    f0, f1, f2, pdf = toon_glossy_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
    if pdf <= 0.0:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, False
    return wix, wiy, wiz, f0 / pdf, f1 / pdf, f2 / pdf, True
