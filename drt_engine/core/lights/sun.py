"""Sun lights: sample, pdf and radiance seen along a direction, and closed form.

A distant light: angle 0 is a delta direction (pdf inf), a positive angle a disk of directions
sampled uniformly over its cone. Nothing hits a sun at a distance: ``sun_seen`` gives the
radiance and the sampling density of a direction that falls in its disk. The closed form
(``unoccluded_sun``) is the direction's cosine, or the disk as a horizon-clipped spherical
cap (lights.solid_angle).
"""
from __future__ import annotations

import math

from ..base.jit import kernel
from ..base.vectors import basis
from .solid_angle import cap_about
from .table import COS_HALF, DX, DY, DZ, EB, EG, ER, INF, SOLID, SUN_SCALE


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


# -- closed form -----------------------------------------------------------------------------------
@kernel(inline="always")
def unoccluded_sun(table, i, nx, ny, nz):
    """Irradiance per unit of the sun's irradiance: its direction, or its disk of half angle h
    (radiance 1 / (pi sin^2 h)) as a cap."""
    ax, ay, az = -table[i, DX], -table[i, DY], -table[i, DZ]
    if table[i, SOLID] <= 0:
        return max(ax * nx + ay * ny + az * nz, 0.0)
    sin2 = 1.0 / (math.pi * table[i, SUN_SCALE])
    return cap_about(ax, ay, az, nx, ny, nz, sin2, table[i, COS_HALF]) * table[i, SUN_SCALE]
