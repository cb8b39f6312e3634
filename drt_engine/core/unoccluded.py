"""Unoccluded irradiance from one light, in closed form: the diffuse lobe's direct light with no
shadow, for the ratio estimator (Heitz, Hill and McGuire 2018).

``unoccluded`` gives E(p, n) = integral over the light of L_e(w) max(0, n.w) dw for one row of
light_kinds' table, in the units of light sampling: E is the mean of ``value * max(0, n.wi)``
over ``sample_light``'s samples, so a diffuse lobe's unshadowed direct light is albedo / pi * E.

Polygons (rectangles, emissive triangles) use Lambert's edge integral clipped to the tangent
plane of n; spheres, soft-falloff disks and suns are spherical caps (Snyder's clipped cap);
delta lights are their one sample. Where light sampling weights the light non-uniformly in a
way with no closed form (a spot cone over a light with a radius, area spread) ``closed_form``
is False and callers keep Monte Carlo.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .light_kinds import (
    AREA, COS_HALF, DISK, DX, DZ, EB, EG, ER, EXX, EXY, EXZ, EYX, EYY, EYZ, EZX, EZY, EZZ, KIND, PX, PY, PZ, POINT,
    RADIUS, RECT, SIZE_X, SIZE_Y, SOFT, SOLID, SPOT, SPREAD_MODE, SUN, SUN_SCALE, TINY, spot_factor,
)


# -- polygons: Lambert's edge integral, clipped to the horizon -----------------------------------
@kernel(inline="always")
def _edge(ax, ay, az, ex, ey, ez, nx, ny, nz):
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
        return _edge(ax, ay, az, ex, ey, ez, nx, ny, nz), 0, 0.0, 0.0, 0.0
    if ha < 0 and hb < 0:
        return 0.0, 0, 0.0, 0.0, 0.0
    t = ha / (ha - hb)
    x, y, z = ax + t * ex, ay + t * ey, az + t * ez
    if ha >= 0:
        return _edge(ax, ay, az, t * ex, t * ey, t * ez, nx, ny, nz), 1, x, y, z
    u = 1.0 - t
    return _edge(x, y, z, u * ex, u * ey, u * ez, nx, ny, nz), 2, x, y, z


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
        s += _edge(ox, oy, oz, ix - ox, iy - oy, iz - oz, nx, ny, nz)
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


# -- the contract ----------------------------------------------------------------------------
@kernel(inline="always")
def closed_form(table, i):
    """Whether ``unoccluded`` gives light i's exact irradiance: False for a spot light with a
    radius (the cone weights each sampled ray of the sphere or disk: no closed form) and for
    area lights with spread (the spread factor varies over the light)."""
    kind = table[i, KIND]
    if kind == SPOT:
        return table[i, RADIUS] <= 0
    if kind == RECT or kind == DISK:
        return table[i, SPREAD_MODE] != 1.0
    return kind == POINT or kind == SUN


@kernel(inline="always")
def unoccluded(table, i, px, py, pz, nx, ny, nz):
    """(r, g, b) irradiance at p about the unit shading normal n from light i with no occluder,
    in light sampling's units; (0, 0, 0) where ``closed_form`` is False (callers check it)."""
    kind = table[i, KIND]
    e = 0.0
    if kind == RECT:
        dx, dy, dz = table[i, PX] - px, table[i, PY] - py, table[i, PZ] - pz
        lit = dx * table[i, EZX] + dy * table[i, EZY] + dz * table[i, EZZ] > 0  # the emitting side
        if lit and table[i, SPREAD_MODE] == 0.0:
            e = max(_rectangle(table, i, dx, dy, dz, nx, ny, nz), 0.0)
    return table[i, ER] * e, table[i, EG] * e, table[i, EB] * e


@kernel
def _unoccluded_rows(table, rows, pos, normal, out):
    for j in range(len(pos)):
        r, g, b = unoccluded(table, rows[j], pos[j, 0], pos[j, 1], pos[j, 2], normal[j, 0], normal[j, 1],
                             normal[j, 2])
        out[j, 0], out[j, 1], out[j, 2] = r, g, b


@kernel
def closed_forms(table):
    """``closed_form`` for every row of the table."""
    out = np.empty(len(table), np.bool_)
    for i in range(len(table)):
        out[i] = closed_form(table, i)
    return out


def unoccluded_batch(table, rows, pos, normal, out):
    """``out[j]`` = light ``rows[j]``'s unoccluded irradiance at ``pos[j]`` about ``normal[j]``
    (a wave's arrays; ``rows`` int64, positions and unit normals (N, 3) float64)."""
    used = np.unique(rows)
    bad = used[~closed_forms(table)[used]]
    if len(bad):
        raise ValueError(f"lights {bad.tolist()} have no closed-form unoccluded irradiance (check closed_form)")
    _unoccluded_rows(table, rows, pos, normal, out)
    return out
