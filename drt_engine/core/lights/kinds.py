"""Each light kind as scalar kernels behind one contract, over one flat row of numbers per light.

A light is one row of ``table`` (columns named in lights.table), built once from ``scene.Light``. Every
kind answers the same three questions for one shading point or ray:

- ``sample_light``: a direction toward the light, the distance to it (inf for a distant
  light), the radiance it brings divided by the pdf, and the solid-angle pdf (inf for a delta
  light: a point without radius, a sun without angle; MIS then gives it full weight);
- ``light_pdf``: the solid-angle density with which ``sample_light`` picks a given direction
  that hits the light at distance t;
- ``hit_light``: where a ray meets the light's body (area shapes, spheres, soft-falloff disks)
  and the radiance it sees there.

Kinds: point and spot (radius, soft falloff, cone and blend), sun (angle), rectangle
(spherical-rectangle sampling, Urena et al. 2013), disk and ellipse (area sampling), all area
shapes with Cycles' spread. Scalars in, scalars out: the batch loops in lights.collection and a later
fused stage kernel call these. They are inlined into their callers (``inline="always"``): a
call from one compiled function to another is not inlined by LLVM across Numba's libraries,
and measured 3x the arithmetic of a delta point light's sample (41 against 13 ns a sample).
"""
from __future__ import annotations

import math

from ..base.constants import TINY
from ..base.jit import kernel
from ..base.vectors import basis
from ..base.warps import concentric_disk
from .table import (
    AREA, COS_HALF, DISK, DX, DY, DZ, EB, EG, ER, EXX, EXY, EXZ, EYX, EYY, EYZ, EZX, EZY, EZZ, INF, KIND, POINT,
    PX, PY, PZ, RADIUS, RECT, SIZE_X, SIZE_Y, SMOOTH, SOFT, SOLID, SPOT, SPREAD_MODE, SPREAD_NORM, SPREAD_TAN,
    SUN, SUN_SCALE,
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
def spot_factor(table, i, wx, wy, wz):
    """Cycles' spot cone along the emitted direction w: smoothstep over the blend, no cosine."""
    cos_a = wx * table[i, DX] + wy * table[i, DY] + wz * table[i, DZ]
    cos_half = table[i, COS_HALF]
    if cos_a <= cos_half:
        return 0.0
    smooth = table[i, SMOOTH]
    if smooth <= 0:
        return 1.0
    t = min((cos_a - cos_half) / smooth, 1.0)
    return t * t * (3.0 - 2.0 * t)


# -- point and spot ---------------------------------------------------------------------
@kernel(inline="always")
def sample_point(table, i, px, py, pz, u0, u1):
    """Point or spot light: a delta (radius 0), Cycles' soft-falloff disk facing the point,
    or a sphere sampled uniformly over the cone it subtends."""
    cx, cy, cz = table[i, PX], table[i, PY], table[i, PZ]
    tx, ty, tz = cx - px, cy - py, cz - pz
    d = math.sqrt(tx * tx + ty * ty + tz * tz)
    inv = 1.0 / max(d, TINY)
    wcx, wcy, wcz = tx * inv, ty * inv, tz * inv
    r = table[i, RADIUS]
    if r <= 0:
        scale = 1.0 / max(d * d, TINY)
        wx, wy, wz, dist, pdf = wcx, wcy, wcz, d, INF
    elif table[i, SOFT] != 0.0:
        t0, t1, t2, b0, b1, b2 = basis(-wcx, -wcy, -wcz)
        ax, ay = concentric_disk(u0, u1)
        ax, ay = ax * r, ay * r
        qx, qy, qz = cx + ax * t0 + ay * b0, cy + ax * t1 + ay * b1, cz + ax * t2 + ay * b2
        tx, ty, tz = qx - px, qy - py, qz - pz
        dist = math.sqrt(tx * tx + ty * ty + tz * tz)
        inv = 1.0 / max(dist, TINY)
        wx, wy, wz = tx * inv, ty * inv, tz * inv
        cos_l = min(max(wx * wcx + wy * wcy + wz * wcz, 0.0), 1.0)
        area = math.pi * r * r
        pdf = dist * dist / max(cos_l * area, TINY)
        scale = (1.0 / area) * (area * cos_l / max(dist * dist, TINY))
    else:
        sin2 = min(max(r * r / max(d * d, TINY), 0.0), 1.0)
        cos_max = math.sqrt(1.0 - sin2)
        cos_t = 1.0 - u0 * (1.0 - cos_max)
        sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
        phi = 2.0 * math.pi * u1
        t0, t1, t2, b0, b1, b2 = basis(wcx, wcy, wcz)
        a, b = sin_t * math.cos(phi), sin_t * math.sin(phi)
        wx, wy, wz = a * t0 + b * b0 + cos_t * wcx, a * t1 + b * b1 + cos_t * wcy, a * t2 + b * b2 + cos_t * wcz
        dist = max(d * cos_t - math.sqrt(max(r * r - d * d * sin_t * sin_t, 0.0)), 0.0)  # to the near side
        solid = 2.0 * math.pi * max(1.0 - cos_max, TINY)
        scale = 0.0 if d <= r else solid / (math.pi * r * r)
        pdf = 1.0 / solid
    if table[i, KIND] == SPOT:  # the cone is evaluated along each sampled ray, as Cycles does
        scale *= spot_factor(table, i, -wx, -wy, -wz)
    return wx, wy, wz, dist, table[i, ER] * scale, table[i, EG] * scale, table[i, EB] * scale, pdf


@kernel(inline="always")
def pdf_point(table, i, ox, oy, oz, dx, dy, dz, t):
    cx, cy, cz = table[i, PX] - ox, table[i, PY] - oy, table[i, PZ] - oz
    d2 = cx * cx + cy * cy + cz * cz
    r = table[i, RADIUS]
    if table[i, SOFT] != 0.0:
        cos_l = (dx * cx + dy * cy + dz * cz) / math.sqrt(max(d2, TINY))
        return t * t / max(cos_l * math.pi * r * r, TINY)
    cos_max = math.sqrt(min(max(1.0 - r * r / max(d2, TINY), 0.0), 1.0))
    return 1.0 / (2.0 * math.pi * max(1.0 - cos_max, TINY))


@kernel(inline="always")
def hit_point(table, i, ox, oy, oz, dx, dy, dz):
    """A sphere, or with soft falloff the disk facing the ray origin that sampling uses."""
    cx, cy, cz = table[i, PX] - ox, table[i, PY] - oy, table[i, PZ] - oz
    r = table[i, RADIUS]
    if table[i, SOFT] != 0.0:
        inv = 1.0 / max(math.sqrt(cx * cx + cy * cy + cz * cz), TINY)
        ax, ay, az = cx * inv, cy * inv, cz * inv
        denom = dx * ax + dy * ay + dz * az
        if denom <= 0:
            return INF, 0.0, 0.0, 0.0
        t = (cx * ax + cy * ay + cz * az) / denom
        qx, qy, qz = t * dx - cx, t * dy - cy, t * dz - cz
        if not qx * qx + qy * qy + qz * qz <= r * r:
            return INF, 0.0, 0.0, 0.0
    else:
        b = cx * dx + cy * dy + cz * dz
        disc = b * b - (cx * cx + cy * cy + cz * cz - r * r)
        if disc < 0:
            return INF, 0.0, 0.0, 0.0
        t = b - math.sqrt(disc)
    scale = 1.0 / (math.pi * r * r)
    if table[i, KIND] == SPOT:
        scale *= spot_factor(table, i, -dx, -dy, -dz)
    return t, table[i, ER] * scale, table[i, EG] * scale, table[i, EB] * scale


# -- sun ----------------------------------------------------------------------------------
@kernel(inline="always")
def sample_sun(table, i, u0, u1):
    """A delta direction (angle 0) or uniform over the cone of the sun's disk."""
    ax, ay, az = -table[i, DX], -table[i, DY], -table[i, DZ]
    if table[i, SOLID] <= 0:
        return ax, ay, az, INF, table[i, ER], table[i, EG], table[i, EB], INF
    cos_t = 1.0 - u0 * (1.0 - table[i, COS_HALF])
    sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
    phi = 2.0 * math.pi * u1
    t0, t1, t2, b0, b1, b2 = basis(ax, ay, az)
    a, b = sin_t * math.cos(phi), sin_t * math.sin(phi)
    solid = table[i, SOLID]
    scale = table[i, SUN_SCALE] * solid
    return (a * t0 + b * b0 + cos_t * ax, a * t1 + b * b1 + cos_t * ay, a * t2 + b * b2 + cos_t * az, INF,
            table[i, ER] * scale, table[i, EG] * scale, table[i, EB] * scale, 1.0 / solid)


@kernel(inline="always")
def sun_seen(table, i, dx, dy, dz):
    """Radiance of a sun disk (angle > 0) seen along d, and the density of sampling d (0, 0
    outside the disk or for a delta sun)."""
    if table[i, SOLID] <= 0 or -(dx * table[i, DX] + dy * table[i, DY] + dz * table[i, DZ]) <= table[i, COS_HALF]:
        return 0.0, 0.0, 0.0, 0.0
    s = table[i, SUN_SCALE]
    return table[i, ER] * s, table[i, EG] * s, table[i, EB] * s, 1.0 / table[i, SOLID]


# -- area shapes --------------------------------------------------------------------------
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


# -- one contract for every kind ------------------------------------------------------------
@kernel(inline="always")
def sample_light(table, i, px, py, pz, u0, u1):
    """(wx, wy, wz, dist, value r, g, b, pdf): value is radiance over pdf (pdf inf: delta)."""
    kind = table[i, KIND]
    if kind == SUN:
        return sample_sun(table, i, u0, u1)
    if kind == RECT or kind == DISK:
        return sample_area(table, i, px, py, pz, u0, u1)
    return sample_point(table, i, px, py, pz, u0, u1)


@kernel(inline="always")
def light_pdf(table, i, ox, oy, oz, dx, dy, dz, t):
    """Solid-angle density of ``sample_light`` picking d from o, the light's body at distance t."""
    kind = table[i, KIND]
    if kind == SUN:
        return sun_seen(table, i, dx, dy, dz)[3]
    if kind == RECT or kind == DISK:
        return pdf_area(table, i, ox, oy, oz, dx, dy, dz, t)
    return pdf_point(table, i, ox, oy, oz, dx, dy, dz, t)


@kernel(inline="always")
def hit_light(table, i, ox, oy, oz, dx, dy, dz):
    """(t, radiance r, g, b) where the ray meets light i's body; t = inf when it misses."""
    kind = table[i, KIND]
    if kind == RECT or kind == DISK:
        return hit_area(table, i, ox, oy, oz, dx, dy, dz)
    if (kind == POINT or kind == SPOT) and table[i, RADIUS] > 0:
        return hit_point(table, i, ox, oy, oz, dx, dy, dz)
    return INF, 0.0, 0.0, 0.0
