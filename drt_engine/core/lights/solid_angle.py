"""Projected solid angles that several light kinds' closed forms share: geometry only, no light table.

Lambert's edge integral of a convex polygon clipped to the horizon of the normal n (rectangles,
emissive triangles, the chord closing an ellipse's clipped rim), and Snyder's spherical cap
clipped by the horizon (spheres, soft-falloff disks, suns). The closed forms of lights.point,
lights.sun, lights.area and lights.triangles build on these.
"""
from __future__ import annotations

import math

from ..base.jit import kernel


# -- polygons: Lambert's edge integral, clipped to the horizon -------------------------------------
@kernel(inline="always")
def edge(ax, ay, az, ex, ey, ez, nx, ny, nz):
    """One edge a -> a + e seen from the origin: angle(a, b) * n . unit(a x b). The cross product
    is a x e (exact edges keep tiny polygons accurate) and the angle an atan2."""
    cx, cy, cz = ay * ez - az * ey, az * ex - ax * ez, ax * ey - ay * ex
    s = math.sqrt(cx * cx + cy * cy + cz * cz)
    if not s > 0:
        return 0.0
    c = ax * (ax + ex) + ay * (ay + ey) + az * (az + ez)
    return math.atan2(s, c) / s * (nx * cx + ny * cy + nz * cz)


@kernel(inline="always")
def _clipped_edge(ax, ay, az, ex, ey, ez, nx, ny, nz):
    """The part of edge a -> a + e above the plane n.v = 0: (term, crossing, x, y, z) with
    crossing 0 (none), 1 (the edge leaves the upper side at x) or 2 (it enters there)."""
    ha = nx * ax + ny * ay + nz * az
    hb = ha + nx * ex + ny * ey + nz * ez
    if ha >= 0 and hb >= 0:
        return edge(ax, ay, az, ex, ey, ez, nx, ny, nz), 0, 0.0, 0.0, 0.0
    if ha < 0 and hb < 0:
        return 0.0, 0, 0.0, 0.0, 0.0
    t = ha / (ha - hb)
    x, y, z = ax + t * ex, ay + t * ey, az + t * ez
    if ha >= 0:
        return edge(ax, ay, az, t * ex, t * ey, t * ez, nx, ny, nz), 1, x, y, z
    u = 1.0 - t
    return edge(x, y, z, u * ex, u * ey, u * ez, nx, ny, nz), 2, x, y, z


@kernel(inline="always")
def _clip_state(total, kind, x, y, z, state):
    """Accumulate one clipped edge into (sum, exit x, y, z, entry x, y, z)."""
    s, ox, oy, oz, ix, iy, iz = state
    if kind == 1:
        ox, oy, oz = x, y, z
    elif kind == 2:
        ix, iy, iz = x, y, z
    return s + total, ox, oy, oz, ix, iy, iz


@kernel(inline="always")
def _close(state, crossed, nx, ny, nz):
    """The sum of a clipped convex polygon's edges, closed along the horizon from where its
    boundary leaves the upper side to where it comes back."""
    s, ox, oy, oz, ix, iy, iz = state
    if crossed:
        s += edge(ox, oy, oz, ix - ox, iy - oy, iz - oz, nx, ny, nz)
    return s


@kernel(inline="always")
def polygon4(ax, ay, az, e0x, e0y, e0z, e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz):
    """Twice the projected solid angle (about n, above its horizon) of the convex polygon
    a, a + e0, a + e0 + e1, a + e0 + e1 + e2 seen from the origin (e3 closes it); positive
    when its vertices turn clockwise seen from the origin (their right-hand normal points away
    from it). With e2 = 0, a triangle."""
    e3x, e3y, e3z = -(e0x + e1x + e2x), -(e0y + e1y + e2y), -(e0z + e1z + e2z)
    state = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    crossed = False
    bx, by, bz = ax, ay, az
    t, k, x, y, z = _clipped_edge(bx, by, bz, e0x, e0y, e0z, nx, ny, nz)
    state, crossed = _clip_state(t, k, x, y, z, state), crossed or k != 0
    bx, by, bz = ax + e0x, ay + e0y, az + e0z
    t, k, x, y, z = _clipped_edge(bx, by, bz, e1x, e1y, e1z, nx, ny, nz)
    state, crossed = _clip_state(t, k, x, y, z, state), crossed or k != 0
    bx, by, bz = bx + e1x, by + e1y, bz + e1z
    t, k, x, y, z = _clipped_edge(bx, by, bz, e2x, e2y, e2z, nx, ny, nz)
    state, crossed = _clip_state(t, k, x, y, z, state), crossed or k != 0
    bx, by, bz = bx + e2x, by + e2y, bz + e2z
    t, k, x, y, z = _clipped_edge(bx, by, bz, e3x, e3y, e3z, nx, ny, nz)
    state, crossed = _clip_state(t, k, x, y, z, state), crossed or k != 0
    return _close(state, crossed, nx, ny, nz)


# -- spherical caps --------------------------------------------------------------------------------
@kernel(inline="always")
def cap(cos_t, sin_t, sin2, cos_s):
    """Projected solid angle about n of a cap of half angle s (sin^2 s, cos s) whose centre is at
    angle t (cos t, sin t) from n, clipped by the horizon (Snyder 1996). Written so tiny caps
    keep their relative precision: atan(z) - z by its series for small z."""
    sin_s = math.sqrt(sin2)
    if cos_t >= sin_s:
        return math.pi * sin2 * cos_t
    if cos_t <= -sin_s:
        return 0.0
    y = min(max(-cos_s * cos_t / max(sin_s * sin_t, 1e-300), -1.0), 1.0)
    w = sin_t * math.sqrt(max(1.0 - y * y, 0.0))  # sin t sqrt(1 - y^2)
    base = cos_t * math.atan2(math.sqrt(max(1.0 - y * y, 0.0)), y) * sin2
    z = sin_s * w / cos_s if cos_s > 0 else math.inf
    if z < 1e-2:  # atan(z) - cos s sin s w = (atan z - z) + z sin^2 s
        z2 = z * z
        return base + z * z2 * (-1.0 / 3.0 + z2 * (1.0 / 5.0 - z2 * (1.0 / 7.0 - z2 / 9.0))) + z * sin2
    return base + math.atan2(sin_s * w, cos_s) - cos_s * sin_s * w


@kernel(inline="always")
def cap_about(cx, cy, cz, nx, ny, nz, sin2, cos_s):
    """``cap`` for a centre direction c (unit) and normal n, the angle between them by atan2."""
    cos_t = cx * nx + cy * ny + cz * nz
    qx, qy, qz = cy * nz - cz * ny, cz * nx - cx * nz, cx * ny - cy * nx
    return cap(cos_t, math.sqrt(qx * qx + qy * qy + qz * qz), sin2, cos_s)
