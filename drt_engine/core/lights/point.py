"""Point and spot lights: sample, pdf, hit and closed form.

Radius 0 is a delta (pdf inf: MIS gives it full weight); with a radius, a sphere sampled
uniformly over the cone it subtends, or with Cycles' soft falloff the disk facing the shading
point, sampled by area. A spot weights each sampled ray by its cone and blend (``spot_factor``).
The closed form (``unoccluded_point``) is the delta's one sample, or the sphere or facing disk
as a horizon-clipped spherical cap (lights.solid_angle); a spot with a radius has none.
"""
from __future__ import annotations

import math

from ..base.constants import TINY
from ..base.jit import kernel
from ..base.vectors import basis
from ..base.warps import concentric_disk
from .solid_angle import cap_about
from .table import COS_HALF, DX, DY, DZ, EB, EG, ER, INF, KIND, PX, PY, PZ, RADIUS, SMOOTH, SOFT, SPOT


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


# -- closed form -----------------------------------------------------------------------------------
@kernel(inline="always")
def unoccluded_point(table, i, px, py, pz, nx, ny, nz):
    """Irradiance per unit of intensity from a point or spot light: a delta with its cone, a
    sphere of radiance 1 / (pi r^2), or (soft falloff) the disk of that radiance facing p."""
    dx, dy, dz = table[i, PX] - px, table[i, PY] - py, table[i, PZ] - pz
    d2 = dx * dx + dy * dy + dz * dz
    d = math.sqrt(d2)
    if not d > 0:
        return 0.0
    cx, cy, cz = dx / d, dy / d, dz / d
    r = table[i, RADIUS]
    if r <= 0:
        e = max(cx * nx + cy * ny + cz * nz, 0.0) / d2
        return e * spot_factor(table, i, -cx, -cy, -cz) if table[i, KIND] == SPOT else e
    if table[i, SOFT] != 0.0:
        h2 = d2 + r * r
        return cap_about(cx, cy, cz, nx, ny, nz, r * r / h2, d / math.sqrt(h2)) / (math.pi * r * r)
    if d <= r:  # inside the sphere light sampling gives nothing
        return 0.0
    return cap_about(cx, cy, cz, nx, ny, nz, r * r / d2, math.sqrt((d - r) * (d + r)) / d) / (math.pi * r * r)
