"""The Hair BSDF's two lobes as Cycles defines them (kernel/closure/bsdf_hair.h, Kajiya-Kay-like):
reflection and transmission about a strand's tangent T, a Cauchy-shaped spread of the half angle
along the strand (RoughnessU, shifted by Offset) and across it (RoughnessV: a cosine lobe for
reflection, a Cauchy one about the far side for transmission). Each is its own sampling density:
f |cos| equals the pdf, so a sample's weight is the closure's colour.

On a mesh Cycles takes T as the triangle's dPdv (Offset then 0) unless Tangent is linked; the
hit's T, in the local frame, is ``H_HAIR`` (core.bsdf.hair_frames). The reflection lobe lights
only what lies above the closure's normal, the transmission lobe only what lies below."""
from __future__ import annotations

import math

from ..base.jit import kernel
from .layout import H_HAIR, P_HAIR

GRAZING = 0.001
"""Cycles gives nothing within this angle (radians) of the tangent, where theta's density diverges."""


@kernel(inline="always")
def _params(lp, l):
    """(RoughnessU, RoughnessV, Offset) as bsdf_hair_*_setup clamps them (0.001 to 1)."""
    r1 = min(max(lp[l, P_HAIR], 0.001), 1.0)
    r2 = min(max(lp[l, P_HAIR + 1], 0.001), 1.0)
    return r1, r2, lp[l, P_HAIR + 2]


@kernel(inline="always")
def _across(tx, ty, tz, x, y, z):
    """(component along T, the unit part across T): zero across where the direction lies along T."""
    along = tx * x + ty * y + tz * z
    ax, ay, az = x - tx * along, y - ty * along, z - tz * along
    n = math.sqrt(ax * ax + ay * ay + az * az)
    if n < 1e-300:
        return along, 0.0, 0.0, 0.0
    return along, ax / n, ay / n, az / n


@kernel(inline="always")
def _theta_pdf(r1, offset, theta_r, theta_i, width):
    """Density of theta_i (per solid angle's cos) for the view's theta_r: the half angle's Cauchy
    spread over [-pi/2, pi/2] (``width`` = a - b, its arctangent range)."""
    t = 0.5 * (theta_i + theta_r) - offset
    return r1 / (2.0 * (t * t + r1 * r1) * width * math.cos(theta_i))


@kernel(inline="always")
def _width(r1, offset, theta_r):
    """a - b: the arctangent range the half angle's Cauchy spread is sampled over."""
    a = math.atan((0.5 * (0.5 * math.pi + theta_r) - offset) / r1)
    b = math.atan((0.5 * (-0.5 * math.pi + theta_r) - offset) / r1)
    return a, b


@kernel(inline="always")
def hair_eval(lp, hp, r, l, transmit, wox, woy, woz, wix, wiy, wiz):
    """f |cos| (= the pdf) toward wi, without the closure's colour and weight: bsdf_hair_reflection_eval
    (``transmit`` False) or bsdf_hair_transmission_eval; 0 on the wrong side of the normal (z)."""
    if (wiz < 0.0) != transmit:
        return 0.0
    return _density(lp, hp, r, l, transmit, True, wox, woy, woz, wix, wiy, wiz)


@kernel(inline="always")
def _density(lp, hp, r, l, transmit, evaluated, wox, woy, woz, wix, wiy, wiz):
    """The lobe's density toward wi; ``evaluated``: with the evaluation's check that reflection
    stays on the view's side of the strand (Cycles' sampling reports its density without it)."""
    r1, r2, offset = _params(lp, l)
    tx, ty, tz = hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2]
    iz, lx, ly, lz = _across(tx, ty, tz, wox, woy, woz)
    if lx == 0.0 and ly == 0.0 and lz == 0.0:  # seen along the strand (or no strand): no azimuth, no light
        return 0.0
    theta_r = 0.5 * math.pi - math.acos(min(max(iz, -1.0), 1.0))
    oz, yx, yy, yz = _across(tx, ty, tz, wix, wiy, wiz)
    theta_i = 0.5 * math.pi - math.acos(min(max(oz, -1.0), 1.0))
    cos_phi = min(max(yx * lx + yy * ly + yz * lz, -1.0), 1.0)
    if 0.5 * math.pi - abs(theta_i) < GRAZING or (cos_phi < 0.0 and not transmit and evaluated):
        return 0.0
    a, b = _width(r1, offset, theta_r)
    theta_pdf = _theta_pdf(r1, offset, theta_r, theta_i, a - b)
    if transmit:
        p = math.pi - math.acos(cos_phi)
        c = 2.0 * math.atan(0.5 * math.pi / r2)
        return r2 / (c * (p * p + r2 * r2)) * theta_pdf
    phi = min(math.acos(cos_phi) / r2, math.pi)
    return math.cos(0.5 * phi) * 0.25 / r2 * theta_pdf


@kernel(inline="always")
def hair_sample(lp, hp, r, l, transmit, wox, woy, woz, u0, u1):
    """(wi, its f |cos| = pdf): bsdf_hair_reflection_sample or bsdf_hair_transmission_sample, whose
    value and density do not look at the side of the normal wi leaves by (a reflection may go
    below the surface, a transmission stay above: Cycles continues either with weight 1; the
    mixture keeps them, core.bsdf.mixture.sample_lobes). Cycles' sampled azimuth for reflection has
    the density its evaluation gives (its sample function reports cos(phi / 2) / (4 RoughnessV),
    which differs unless RoughnessV is 1); the density returned here is the true one."""
    r1, r2, offset = _params(lp, l)
    tx, ty, tz = hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2]
    iz, lx, ly, lz = _across(tx, ty, tz, wox, woy, woz)
    bx, by, bz = ly * tz - lz * ty, lz * tx - lx * tz, lx * ty - ly * tx  # Cycles' locx = cross(locy, T)
    theta_r = 0.5 * math.pi - math.acos(min(max(iz, -1.0), 1.0))
    a, b = _width(r1, offset, theta_r)
    t = r1 * math.tan(u0 * (a - b) + b)
    theta_i = 2.0 * (t + offset) - theta_r
    if transmit:
        c = 2.0 * math.atan(0.5 * math.pi / r2)
        phi = r2 * math.tan(c * (u1 - 0.5)) + math.pi
    else:
        phi = 2.0 * math.asin(min(max(1.0 - 2.0 * u1, -1.0), 1.0)) * r2
    ct, st = math.cos(theta_i), math.sin(theta_i)
    cp, sp = math.cos(phi), math.sin(phi)
    wix = cp * ct * lx - sp * ct * bx + st * tx
    wiy = cp * ct * ly - sp * ct * by + st * ty
    wiz = cp * ct * lz - sp * ct * bz + st * tz
    return wix, wiy, wiz, _density(lp, hp, r, l, transmit, False, wox, woy, woz, wix, wiy, wiz)
