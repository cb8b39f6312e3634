"""Unoccluded irradiance from one light, in closed form: the diffuse lobe's direct light with no
shadow, for the ratio estimator (Heitz, Hill and McGuire 2018).

``unoccluded`` gives E(p, n) = integral over the light of L_e(w) max(0, n.w) dw for one row of
lights.table's table, in the units of light sampling: E is the mean of ``value * max(0, n.wi)``
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

from ..base.jit import kernel
from .kinds import spot_factor
from .table import (
    COS_HALF, DISK, DX, DY, DZ, EB, EG, ER, EXX, EXY, EXZ, EYX, EYY, EYZ, EZX, EZY, EZZ, KIND, POINT, PX, PY, PZ,
    RADIUS, RECT, SIZE_X, SIZE_Y, SOFT, SOLID, SPOT, SPREAD_MODE, SUN, SUN_SCALE,
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


# -- ellipses: the same boundary integral along the rim ----------------------------------------
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
    chord = _edge(px, py, pz, ea * ux + eb * vx, ea * uy + eb * vy, ea * uz + eb * vz, nx, ny, nz)
    return 0.5 * (_adaptive(back, out, prm) + chord)


# -- spheres, facing disks and suns: spherical caps ----------------------------------------------
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
def _cap_about(cx, cy, cz, nx, ny, nz, sin2, cos_s):
    """``cap`` for a centre direction c (unit) and normal n, the angle between them by atan2."""
    cos_t = cx * nx + cy * ny + cz * nz
    qx, qy, qz = cy * nz - cz * ny, cz * nx - cx * nz, cx * ny - cy * nx
    return cap(cos_t, math.sqrt(qx * qx + qy * qy + qz * qz), sin2, cos_s)


@kernel(inline="always")
def _point(table, i, px, py, pz, nx, ny, nz):
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
        return _cap_about(cx, cy, cz, nx, ny, nz, r * r / h2, d / math.sqrt(h2)) / (math.pi * r * r)
    if d <= r:  # inside the sphere light sampling gives nothing
        return 0.0
    return _cap_about(cx, cy, cz, nx, ny, nz, r * r / d2, math.sqrt((d - r) * (d + r)) / d) / (math.pi * r * r)


@kernel(inline="always")
def _sun(table, i, nx, ny, nz):
    """Irradiance per unit of the sun's irradiance: its direction, or its disk of half angle h
    (radiance 1 / (pi sin^2 h)) as a cap."""
    ax, ay, az = -table[i, DX], -table[i, DY], -table[i, DZ]
    if table[i, SOLID] <= 0:
        return max(ax * nx + ay * ny + az * nz, 0.0)
    sin2 = 1.0 / (math.pi * table[i, SUN_SCALE])
    return _cap_about(ax, ay, az, nx, ny, nz, sin2, table[i, COS_HALF]) * table[i, SUN_SCALE]


# -- the contract ----------------------------------------------------------------------------
@kernel(inline="always")
def closed_form(table, i):
    """Whether ``unoccluded`` gives light i's exact irradiance: False for a spot light with a
    radius (its cone weights each sampled ray of the sphere or disk differently: no closed form)
    and for area lights with a spread between 0 and 180 degrees (the spread factor varies over
    the light). Spread 0 is exact: such a light lights nothing."""
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
    if kind == RECT or kind == DISK:
        dx, dy, dz = table[i, PX] - px, table[i, PY] - py, table[i, PZ] - pz
        lit = dx * table[i, EZX] + dy * table[i, EZY] + dz * table[i, EZZ] > 0  # the emitting side
        if lit and table[i, SPREAD_MODE] == 0.0:
            if kind == RECT:
                e = max(_rectangle(table, i, dx, dy, dz, nx, ny, nz), 0.0)
            else:
                e = max(_ellipse(table, i, dx, dy, dz, nx, ny, nz), 0.0)
    elif kind == SUN:
        e = _sun(table, i, nx, ny, nz)
    elif kind == POINT or (kind == SPOT and table[i, RADIUS] <= 0):
        e = _point(table, i, px, py, pz, nx, ny, nz)
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


# -- emissive triangles ------------------------------------------------------------------------
@kernel(inline="always")
def unoccluded_triangles(vertices, triangles, emission, ids, px, py, pz, nx, ny, nz):
    """(r, g, b) irradiance at p about n from the two-sided emissive triangles ``ids`` of constant
    ``emission`` (per triangle): the emissive strategy's unoccluded light, O(len(ids)) per point."""
    r, g, b = 0.0, 0.0, 0.0
    for i in ids:
        v0, v1, v2 = triangles[i, 0], triangles[i, 1], triangles[i, 2]
        ax, ay, az = vertices[v0, 0] - px, vertices[v0, 1] - py, vertices[v0, 2] - pz
        e = 0.5 * abs(polygon4(ax, ay, az,
                               vertices[v1, 0] - vertices[v0, 0], vertices[v1, 1] - vertices[v0, 1],
                               vertices[v1, 2] - vertices[v0, 2],
                               vertices[v2, 0] - vertices[v1, 0], vertices[v2, 1] - vertices[v1, 1],
                               vertices[v2, 2] - vertices[v1, 2], 0.0, 0.0, 0.0, nx, ny, nz))
        r += emission[i, 0] * e
        g += emission[i, 1] * e
        b += emission[i, 2] * e
    return r, g, b


@kernel
def unoccluded_triangles_batch(vertices, triangles, emission, ids, pos, normal, out):
    """``unoccluded_triangles`` for each point of a wave into ``out`` (N, 3)."""
    for j in range(len(pos)):
        r, g, b = unoccluded_triangles(vertices, triangles, emission, ids, pos[j, 0], pos[j, 1], pos[j, 2],
                                       normal[j, 0], normal[j, 1], normal[j, 2])
        out[j, 0], out[j, 1], out[j, 2] = r, g, b
    return out
