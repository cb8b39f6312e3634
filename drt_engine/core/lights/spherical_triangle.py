"""Directions toward a triangle uniform in the solid angle it subtends (Arvo 1995, "Stratified
sampling of spherical triangles"), and where to use them instead of area sampling.

Near a large emitter, area sampling's solid-angle pdf (d^2 / cos over the area) varies across the
triangle by orders of magnitude and leaves the noise Cycles does not have; the solid angle's pdf
is constant. Like Cycles (kernel/light/triangle.h), the spherical construction is used where the
shading point is nearer the triangle's plane than its longest edge (far away both densities are
alike and area sampling is cheaper); unlike Cycles' test, which divides by the unnormalised
normal and so depends on the scene's scale, this one is scale-free. It also needs the solid angle
above ``MIN_SOLID_ANGLE``: below it the three directions nearly coincide (or lie in one plane)
and the construction's differences of cosines lose their digits, while area sampling's pdf is
nearly constant there anyway. The choice is a function of the point and the triangle only, so
light sampling and the pdf of a BSDF ray that hits the triangle (MIS) agree.
"""
from __future__ import annotations

import math

from ..base.jit import kernel

MIN_SOLID_ANGLE = 1e-6
"""Steradians below which a triangle is area sampled (about 0.06 degrees across): float64 keeps
about 10 digits of the construction's 1 - cos differences there."""


@kernel(inline="always")
def _unit(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    if not n > 0:
        return 0.0, 0.0, 0.0
    return x / n, y / n, z / n


@kernel(inline="always")
def subtended(vertices, a, b, c, nx, ny, nz, px, py, pz):
    """The solid angle of triangle (a, b, c) (vertex rows, unit normal n) seen from p when it is
    to be sampled by solid angle there, else 0 (area sampling)."""
    v0x, v0y, v0z = vertices[a, 0] - px, vertices[a, 1] - py, vertices[a, 2] - pz
    v1x, v1y, v1z = vertices[b, 0] - px, vertices[b, 1] - py, vertices[b, 2] - pz
    v2x, v2y, v2z = vertices[c, 0] - px, vertices[c, 1] - py, vertices[c, 2] - pz
    plane = nx * v0x + ny * v0y + nz * v0z
    e0 = (v1x - v0x) ** 2 + (v1y - v0y) ** 2 + (v1z - v0z) ** 2
    e1 = (v2x - v0x) ** 2 + (v2y - v0y) ** 2 + (v2z - v0z) ** 2
    e2 = (v2x - v1x) ** 2 + (v2y - v1y) ** 2 + (v2z - v1z) ** 2
    if not max(e0, e1, e2) > plane * plane:
        return 0.0
    ax, ay, az = _unit(v0x, v0y, v0z)
    bx, by, bz = _unit(v1x, v1y, v1z)
    cx, cy, cz = _unit(v2x, v2y, v2z)
    mixed = abs(ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx))
    omega = 2.0 * math.atan2(mixed, 1.0 + (bx * cx + by * cy + bz * cz) + (ax * cx + ay * cy + az * cz)
                             + (ax * bx + ay * by + az * bz))
    return omega if omega > MIN_SOLID_ANGLE else 0.0


@kernel(inline="always")
def sample_direction(vertices, a, b, c, omega, px, py, pz, u0, u1):
    """A unit direction from p uniform over the solid angle ``omega`` (``subtended``'s, > 0) of
    triangle (a, b, c): Arvo's map, continuous in (u0, u1), so stratified samples stay so.
    u0 picks the sub-triangle of area u0 * omega (its new corner c' on arc a-c), u1 the point
    on the arc from b to c'."""
    ax, ay, az = _unit(vertices[a, 0] - px, vertices[a, 1] - py, vertices[a, 2] - pz)
    bx, by, bz = _unit(vertices[b, 0] - px, vertices[b, 1] - py, vertices[b, 2] - pz)
    cx, cy, cz = _unit(vertices[c, 0] - px, vertices[c, 1] - py, vertices[c, 2] - pz)
    cos_c = ax * bx + ay * by + az * bz
    cos_b = ax * cx + ay * cy + az * cz
    # the angle at a, between the planes (a, b) and (a, c): (a x b) . (a x c) and |a . (b x c)|
    abx, aby, abz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    acx, acy, acz = ay * cz - az * cy, az * cx - ax * cz, ax * cy - ay * cx
    cos_part = abx * acx + aby * acy + abz * acz
    sin_part = abs(ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx))
    h = math.hypot(cos_part, sin_part)
    cos_alpha, sin_alpha = (cos_part / h, sin_part / h) if h > 0 else (1.0, 0.0)
    # s, t: sine and cosine of (u0 * omega - alpha)
    sa, ca = math.sin(u0 * omega), math.cos(u0 * omega)
    s, t = sa * cos_alpha - ca * sin_alpha, ca * cos_alpha + sa * sin_alpha
    uu = t - cos_alpha
    vv = s + sin_alpha * cos_c
    den = (vv * s + uu * t) * sin_alpha
    q = ((vv * t - uu * s) * cos_alpha - vv) / den if den != 0 else 1.0
    q = min(max(q, -1.0), 1.0)
    # c' = q a + sqrt(1 - q^2) * (the unit part of c orthogonal to a)
    ox, oy, oz = _unit(cx - cos_b * ax, cy - cos_b * ay, cz - cos_b * az)
    r = math.sqrt(max(0.0, (1.0 - q) * (1.0 + q)))
    kx, ky, kz = _unit(q * ax + r * ox, q * ay + r * oy, q * az + r * oz)
    # along the arc b -> c': 1 - z = u1 (1 - b . c'), the latter as |c' - b|^2 / 2 (no cancellation)
    one_minus_z = u1 * 0.5 * ((kx - bx) ** 2 + (ky - by) ** 2 + (kz - bz) ** 2)
    z = 1.0 - one_minus_z
    sz = math.sqrt(max(0.0, one_minus_z * (2.0 - one_minus_z)))
    kb = kx * bx + ky * by + kz * bz
    wx, wy, wz = _unit(kx - kb * bx, ky - kb * by, kz - kb * bz)
    return _unit(z * bx + sz * wx, z * by + sz * wy, z * bz + sz * wz)


@kernel(inline="always")
def barycentrics_along(vertices, a, b, c, px, py, pz, dx, dy, dz):
    """(b0, b1) of the point where the ray p + t d meets triangle (a, b, c)'s plane, clamped into
    the triangle (a direction from ``sample_direction`` misses only by rounding)."""
    e1x, e1y, e1z = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1], vertices[b, 2] - vertices[a, 2]
    e2x, e2y, e2z = vertices[c, 0] - vertices[a, 0], vertices[c, 1] - vertices[a, 1], vertices[c, 2] - vertices[a, 2]
    sx, sy, sz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * sx + e1y * sy + e1z * sz
    if det == 0:
        return 1.0 / 3.0, 1.0 / 3.0
    tx, ty, tz = px - vertices[a, 0], py - vertices[a, 1], pz - vertices[a, 2]
    u = (tx * sx + ty * sy + tz * sz) / det
    qx, qy, qz = ty * e1z - tz * e1y, tz * e1x - tx * e1z, tx * e1y - ty * e1x
    v = (dx * qx + dy * qy + dz * qz) / det
    u, v = max(u, 0.0), max(v, 0.0)
    if u + v > 1.0:
        u, v = u / (u + v), v / (u + v)
    return 1.0 - u - v, u
