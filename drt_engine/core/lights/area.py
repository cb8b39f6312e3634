"""Area lights (rectangles, disks, ellipses): sample, pdf, hit and closed form.

One-sided shapes emitting along their local +z, with Cycles' spread (``spread_factor``).
Rectangles are sampled uniformly in solid angle (spherical rectangles, Urena et al. 2013; by
area where that angle is too small to sample precisely), disks and ellipses by area.

Closed form (``unoccluded_area``): the projected solid angle of the shape seen from its
emitting side. A rectangle is a polygon (Lambert's edge integral clipped to the horizon,
lights.solid_angle); an ellipse is the same boundary integral along its rim, by quadrature
(the periodic trapezoid rule over a rim wholly above the horizon, adaptive Gauss-Legendre over
a clipped arc, closed by its chord). A spread between 0 and 180 degrees weights the light
non-uniformly, with no closed form.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from ..base.warps import concentric_disk
from .solid_angle import edge, polygon4
from .table import (
    AREA, DISK, EB, EG, ER, EXX, EXY, EXZ, EYX, EYY, EYZ, EZX, EZY, EZZ, INF, KIND, PX, PY, PZ, RECT, SIZE_X,
    SIZE_Y, SPREAD_MODE, SPREAD_NORM, SPREAD_TAN,
)


MIN_SOLID_ANGLE = 1e-5
"""Below this a rectangle's solid angle is sampled by area instead (the spherical-rectangle
method loses precision; both strategies are exact there)."""


@kernel(inline="always")
def spread_factor(table, i, cos_l):
    mode = table[i, SPREAD_MODE]
    if mode == 0.0:
        return 1.0
    if mode == 2.0:
        return 0.0
    c = min(max(cos_l, 1e-12), 1.0)
    tan_a = math.sqrt(1.0 - c * c) / c
    return max((table[i, SPREAD_TAN] - tan_a) * table[i, SPREAD_NORM], 0.0)


@kernel(inline="always")
def spherical_rectangle(table, i, ox, oy, oz):
    """The rectangle of light i seen from o, in its local frame (Urena et al. 2013):
    (x0, y0, x1, y1, z0, flip, b0, b1, k, solid angle). z0 >= 0 is the distance to the plane,
    flip turns local z away from the rectangle."""
    sx, sy = table[i, SIZE_X], table[i, SIZE_Y]
    dx = table[i, PX] - 0.5 * sx * table[i, EXX] - 0.5 * sy * table[i, EYX] - ox
    dy = table[i, PY] - 0.5 * sx * table[i, EXY] - 0.5 * sy * table[i, EYY] - oy
    dz = table[i, PZ] - 0.5 * sx * table[i, EXZ] - 0.5 * sy * table[i, EYZ] - oz
    z0 = dx * table[i, EZX] + dy * table[i, EZY] + dz * table[i, EZZ]
    flip = -1.0 if z0 > 0 else 1.0
    z0 *= flip
    x0 = dx * table[i, EXX] + dy * table[i, EXY] + dz * table[i, EXZ]
    y0 = dx * table[i, EYX] + dy * table[i, EYY] + dz * table[i, EYZ]
    x1, y1 = x0 + sx, y0 + sy
    # z components of the unit normals of the planes through o and each edge; each pair of
    # neighbouring normals shares one non-zero product, so their dot products are these products
    zz = z0 * z0
    c0 = -y0 / max(math.sqrt(zz + y0 * y0), TINY)
    c1 = x1 / max(math.sqrt(zz + x1 * x1), TINY)
    c2 = y1 / max(math.sqrt(zz + y1 * y1), TINY)
    c3 = -x0 / max(math.sqrt(zz + x0 * x0), TINY)
    g0 = math.acos(min(max(-(c0 * c1), -1.0), 1.0))
    g1 = math.acos(min(max(-(c1 * c2), -1.0), 1.0))
    g2 = math.acos(min(max(-(c2 * c3), -1.0), 1.0))
    g3 = math.acos(min(max(-(c3 * c0), -1.0), 1.0))
    k = 2 * math.pi - g2 - g3
    return x0, y0, x1, y1, z0, flip, c0, c2, k, g0 + g1 - k


@kernel(inline="always")
def rectangle_usable(z0, solid):
    return solid > MIN_SOLID_ANGLE and abs(z0) > 0 and math.isfinite(solid)


@kernel(inline="always")
def sample_spherical_rectangle(x0, y0, x1, y1, z0, b0, b1, k, solid, u0, u1):
    """Local (x, y) on the rectangle for the 2D sample u, uniform in solid angle."""
    au = u0 * solid + k
    sin_au = math.sin(au)
    if abs(sin_au) <= 1e-12:
        sin_au = 1e-12
    fu = (math.cos(au) * b0 - b1) / sin_au
    sign = 1.0 if fu > 0 else (-1.0 if fu < 0 else 0.0)
    cu = min(max(sign / math.sqrt(fu * fu + b0 * b0), -1.0), 1.0)
    xu = min(max(-(cu * z0) / max(math.sqrt(1.0 - cu * cu), 1e-12), x0), x1)
    dd = math.sqrt(xu * xu + z0 * z0)
    h0 = y0 / math.sqrt(dd * dd + y0 * y0)
    h1 = y1 / math.sqrt(dd * dd + y1 * y1)
    hv = h0 + u1 * (h1 - h0)
    yv = hv * dd / math.sqrt(max(1.0 - hv * hv, 1e-24)) if hv * hv < 1 - 1e-12 else y1
    return xu, min(max(yv, y0), y1)


@kernel(inline="always")
def sample_area(table, i, px, py, pz, u0, u1):
    """Rectangles by solid angle (by area where it is too small), disks and ellipses by area."""
    sx, sy = table[i, SIZE_X], table[i, SIZE_Y]
    exx, exy, exz = table[i, EXX], table[i, EXY], table[i, EXZ]
    eyx, eyy, eyz = table[i, EYX], table[i, EYY], table[i, EYZ]
    ezx, ezy, ezz = table[i, EZX], table[i, EZY], table[i, EZZ]
    solid_pdf = 0.0
    if table[i, KIND] == DISK:
        a, b = concentric_disk(u0, u1)
        a, b = 0.5 * a * sx, 0.5 * b * sy
        qx, qy, qz = table[i, PX] + a * exx + b * eyx, table[i, PY] + a * exy + b * eyy, table[i, PZ] + a * exz + b * eyz
    else:
        x0, y0, x1, y1, z0, flip, b0, b1, k, solid = spherical_rectangle(table, i, px, py, pz)
        if rectangle_usable(z0, solid):
            xu, yv = sample_spherical_rectangle(x0, y0, x1, y1, z0, b0, b1, k, solid, u0, u1)
            zf = z0 * flip
            qx, qy, qz = px + xu * exx + yv * eyx + zf * ezx, py + xu * exy + yv * eyy + zf * ezy, \
                pz + xu * exz + yv * eyz + zf * ezz
            solid_pdf = 1.0 / max(solid, TINY)
        else:
            a, b = (u0 - 0.5) * sx, (u1 - 0.5) * sy
            qx, qy = table[i, PX] + a * exx + b * eyx, table[i, PY] + a * exy + b * eyy
            qz = table[i, PZ] + a * exz + b * eyz
    tx, ty, tz = qx - px, qy - py, qz - pz
    dist = math.sqrt(tx * tx + ty * ty + tz * tz)
    inv = 1.0 / max(dist, TINY)
    wx, wy, wz = tx * inv, ty * inv, tz * inv
    cos_l = wx * ezx + wy * ezy + wz * ezz
    if cos_l <= 0:  # the back, which does not emit
        return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0
    pdf = solid_pdf if solid_pdf > 0 else dist * dist / max(cos_l * table[i, AREA], TINY)
    scale = spread_factor(table, i, cos_l) / max(pdf, TINY)
    return wx, wy, wz, dist, table[i, ER] * scale, table[i, EG] * scale, table[i, EB] * scale, pdf


@kernel(inline="always")
def pdf_area(table, i, ox, oy, oz, dx, dy, dz, t):
    if table[i, KIND] == RECT:
        _, _, _, _, z0, _, _, _, _, solid = spherical_rectangle(table, i, ox, oy, oz)
        if rectangle_usable(z0, solid):
            return 1.0 / max(solid, TINY)
    cos_l = dx * table[i, EZX] + dy * table[i, EZY] + dz * table[i, EZZ]
    return t * t / (max(cos_l, TINY) * table[i, AREA])


@kernel(inline="always")
def hit_area(table, i, ox, oy, oz, dx, dy, dz):
    """The one-sided rectangle, disk or ellipse, seen from its emitting side."""
    ezx, ezy, ezz = table[i, EZX], table[i, EZY], table[i, EZZ]
    denom = dx * ezx + dy * ezy + dz * ezz
    if denom <= 0:
        return INF, 0.0, 0.0, 0.0
    cx, cy, cz = table[i, PX] - ox, table[i, PY] - oy, table[i, PZ] - oz
    t = (cx * ezx + cy * ezy + cz * ezz) / denom
    qx, qy, qz = t * dx - cx, t * dy - cy, t * dz - cz
    x = (qx * table[i, EXX] + qy * table[i, EXY] + qz * table[i, EXZ]) / (0.5 * table[i, SIZE_X])
    y = (qx * table[i, EYX] + qy * table[i, EYY] + qz * table[i, EYZ]) / (0.5 * table[i, SIZE_Y])
    inside = x * x + y * y <= 1.0 if table[i, KIND] == DISK else (abs(x) <= 1.0 and abs(y) <= 1.0)
    if not inside:
        return INF, 0.0, 0.0, 0.0
    s = spread_factor(table, i, denom)
    return t, table[i, ER] * s, table[i, EG] * s, table[i, EB] * s


# -- closed form: rectangles as polygons -----------------------------------------------------------
@kernel(inline="always")
def _rectangle(table, i, dx, dy, dz, nx, ny, nz):
    """Projected solid angle of rectangle i whose centre is d from the shading point."""
    hx, hy = 0.5 * table[i, SIZE_X], 0.5 * table[i, SIZE_Y]
    ux, uy, uz = table[i, EXX], table[i, EXY], table[i, EXZ]
    vx, vy, vz = table[i, EYX], table[i, EYY], table[i, EYZ]
    ax, ay, az = dx - hx * ux - hy * vx, dy - hx * uy - hy * vy, dz - hx * uz - hy * vz
    sx, sy = 2.0 * hx, 2.0 * hy
    return 0.5 * polygon4(ax, ay, az, sx * ux, sx * uy, sx * uz, sy * vx, sy * vy, sy * vz,
                          -sx * ux, -sx * uy, -sx * uz, nx, ny, nz)


# -- closed form: ellipses, the same boundary integral along the rim -------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


TRAPEZOID_MAX = 512
"""Points of the periodic trapezoid rule before a whole ellipse falls back to adaptive
Gauss-Legendre (only points very near the rim need more)."""


RIM_TOLERANCE = 1e-8
"""Difference allowed between a Gauss-Legendre step and its two halves, relative to the integral
of the integrand's magnitude (beside the rounding of the step's own sum, which no step length
removes); the halves, which are kept, are some 2^16 times closer."""


PERIODIC_SETTLED = 1e-6
"""Change allowed between the trapezoid rule and its doubling, relative to the integral of the
integrand's magnitude: the error falls geometrically with the points, so the doubled rule's is
about the square of this."""


MAX_STEPS = 4096


@kernel(inline="always")
def _rim(phi, prm):
    """n . (v x v') / |v|^2 at rim angle phi, v = d + a cos U + b sin V: the integrand of the
    boundary integral, from the terms ``_ellipse`` precomputes (|v| from v itself, which keeps
    its precision when the point is near the rim)."""
    a, b, mu, mv, k, dx, dy, dz, ux, uy, uz, vx, vy, vz = prm
    co, si = math.cos(phi), math.sin(phi)
    c, s = a * co, b * si
    x, y, z = dx + c * ux + s * vx, dy + c * uy + s * vy, dz + c * uz + s * vz
    return (b * co * mv - a * si * mu + k) / max(x * x + y * y + z * z, 1e-300)


@kernel(inline="always")
def _gauss(lo, hi, prm):
    h = 0.5 * (hi - lo)
    m = lo + h
    total, size = 0.0, 0.0
    for j in range(len(_GL_X)):
        f = _GL_W[j] * _rim(m + h * _GL_X[j], prm)
        total += f
        size += abs(f)
    return total * h, size * h


@kernel(inline="always")
def _adaptive(lo, hi, prm):
    """Integral of ``_rim`` over [lo, hi] by 8-point Gauss-Legendre steps, each accepted when
    its two halves agree with it (step length adapted on the way, no stack)."""
    span = hi - lo
    if not span > 0:
        return 0.0
    coarse, size = _gauss(lo, hi, prm)
    tol = RIM_TOLERANCE * max(size, 1e-300)
    total, x, h = 0.0, lo, span
    known = True  # whether ``coarse`` is this step's sum already (a halved step's is the left half)
    for step in range(MAX_STEPS):
        last = h >= hi - x or step == MAX_STEPS - 1  # (the last allowed step takes the rest)
        if last and h != hi - x:
            h, known = hi - x, False
        if not known:
            coarse, _ = _gauss(x, x + h, prm)
        left, size_l = _gauss(x, x + 0.5 * h, prm)
        right, size_r = _gauss(x + 0.5 * h, x + h, prm)
        settled = abs(left + right - coarse) <= tol * h / span + 1e-13 * (size_l + size_r)
        if settled or step == MAX_STEPS - 1:
            total += left + right
            if last:
                return total
            x += h
            h *= 2.0
            known = False
        else:
            h *= 0.5
            coarse, known = left, True
    return total


@kernel(inline="always")
def _periodic(prm):
    """Integral of ``_rim`` over a whole turn: the periodic trapezoid rule (exponential
    convergence for an ellipse wholly above the horizon), doubled until it settles."""
    n = 8
    step = 2.0 * math.pi / n
    total, size = 0.0, 0.0
    for j in range(n):
        f = _rim(j * step, prm)
        total += f
        size += abs(f)
    previous = total * step
    while n < TRAPEZOID_MAX:
        for j in range(n):  # the midpoints of the current rule
            f = _rim((j + 0.5) * step, prm)
            total += f
            size += abs(f)
        n *= 2
        step *= 0.5
        current = total * step
        if abs(current - previous) <= PERIODIC_SETTLED * size * step:
            return current
        previous = current
    return _adaptive(0.0, 2.0 * math.pi, prm)


@kernel(inline="always")
def _ellipse(table, i, dx, dy, dz, nx, ny, nz):
    """Projected solid angle of disk or ellipse i whose centre is d from the shading point: half
    the boundary integral of n . (v x dv) / |v|^2, over the arc above the horizon plus its chord."""
    a, b = 0.5 * table[i, SIZE_X], 0.5 * table[i, SIZE_Y]
    ux, uy, uz = table[i, EXX], table[i, EXY], table[i, EXZ]
    vx, vy, vz = table[i, EYX], table[i, EYY], table[i, EYZ]
    mx, my, mz = ny * dz - nz * dy, nz * dx - nx * dz, nx * dy - ny * dx  # n x d
    k = a * b * (nx * table[i, EZX] + ny * table[i, EZY] + nz * table[i, EZZ])
    prm = (a, b, mx * ux + my * uy + mz * uz, mx * vx + my * vy + mz * vz, k, dx, dy, dz, ux, uy, uz, vx, vy, vz)
    # height above the horizon along the rim: hc + ha cos(phi) + hb sin(phi)
    hc, ha, hb = nx * dx + ny * dy + nz * dz, a * (nx * ux + ny * uy + nz * uz), b * (nx * vx + ny * vy + nz * vz)
    r = math.sqrt(ha * ha + hb * hb)
    if hc >= r:
        return 0.5 * _periodic(prm)
    if hc <= -r:
        return 0.0
    mid, half = math.atan2(hb, ha), math.atan2(math.sqrt(max(r * r - hc * hc, 0.0)), -hc)
    out, back = mid + half, mid - half  # where the rim leaves the upper side, and comes back
    co, so, cb, sb = math.cos(out), math.sin(out), math.cos(back), math.sin(back)
    px, py, pz = dx + a * co * ux + b * so * vx, dy + a * co * uy + b * so * vy, dz + a * co * uz + b * so * vz
    ea, eb = a * (cb - co), b * (sb - so)
    chord = edge(px, py, pz, ea * ux + eb * vx, ea * uy + eb * vy, ea * uz + eb * vz, nx, ny, nz)
    return 0.5 * (_adaptive(back, out, prm) + chord)


# -- closed form -----------------------------------------------------------------------------------
@kernel(inline="always")
def unoccluded_area(table, i, px, py, pz, nx, ny, nz):
    """Irradiance per unit of radiance at p about n from rectangle, disk or ellipse i, seen from
    its emitting side (0 from behind); exact without spread only (``closed_form``, lights.kinds)."""
    dx, dy, dz = table[i, PX] - px, table[i, PY] - py, table[i, PZ] - pz
    lit = dx * table[i, EZX] + dy * table[i, EZY] + dz * table[i, EZZ] > 0  # the emitting side
    if lit and table[i, SPREAD_MODE] == 0.0:
        if table[i, KIND] == RECT:
            return max(_rectangle(table, i, dx, dy, dz, nx, ny, nz), 0.0)
        return max(_ellipse(table, i, dx, dy, dz, nx, ny, nz), 0.0)
    return 0.0
