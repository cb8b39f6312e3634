"""One contract for every light kind: the switch over a light's kind, over one flat row of numbers per light.

A light is one row of ``table`` (columns named in lights.table), built once from ``scene.Light``.
Each kind lives in its own module (lights.point: point and spot; lights.sun; lights.area:
rectangle, disk, ellipse) and answers the same questions for one shading point or ray, which
these switches route by the row's kind:

- ``sample_light``: a direction toward the light, the distance to it (inf for a distant
  light), the radiance it brings divided by the pdf, and the solid-angle pdf (inf for a delta
  light: a point without radius, a sun without angle; MIS then gives it full weight);
- ``light_pdf``: the solid-angle density with which ``sample_light`` picks a given direction
  that hits the light at distance t;
- ``hit_light``: where a ray meets the light's body (area shapes, spheres, soft-falloff disks)
  and the radiance it sees there;
- ``unoccluded``: the closed form where there is one (``closed_form``), E(p, n) = integral over
  the light of L_e(w) max(0, n.w) dw, the diffuse lobe's direct light with no shadow, for the
  ratio estimator (core.integrator.ratio; Heitz, Hill and McGuire 2018). It is in the units of
  light sampling: E is the mean of ``value * max(0, n.wi)`` over ``sample_light``'s samples, so
  a diffuse lobe's unshadowed direct light is albedo / pi * E.

Emissive triangles are one strategy of their own, not rows of the table (lights.triangles).
Scalars in, scalars out: the batch loops in lights.collection and a later fused stage kernel
call these. They are inlined into their callers (``inline="always"``): a call from one compiled
function to another is not inlined by LLVM across Numba's libraries, and measured 3x the
arithmetic of a delta point light's sample (41 against 13 ns a sample).
"""
from __future__ import annotations

from ..base.jit import kernel
from .area import hit_area, pdf_area, sample_area, unoccluded_area
from .point import hit_point, pdf_point, sample_point, unoccluded_point
from .sun import sample_sun, sun_seen, unoccluded_sun
from .table import DISK, EB, EG, ER, INF, KIND, POINT, RADIUS, RECT, SPOT, SPREAD_MODE, SUN, VARYING


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


@kernel(inline="always")
def closed_form(table, i):
    """Whether ``unoccluded`` gives light i's exact irradiance: False for a spot light with a
    radius (its cone weights each sampled ray of the sphere or disk differently: no closed form)
    and for area lights with a spread between 0 and 180 degrees (the spread factor varies over
    the light), nor for a light whose node tree varies its emission (lights.programs). Spread 0 is
    exact: such a light lights nothing."""
    kind = table[i, KIND]
    if table[i, VARYING] != 0.0:
        return False
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
        e = unoccluded_area(table, i, px, py, pz, nx, ny, nz)
    elif kind == SUN:
        e = unoccluded_sun(table, i, nx, ny, nz)
    elif kind == POINT or (kind == SPOT and table[i, RADIUS] <= 0):
        e = unoccluded_point(table, i, px, py, pz, nx, ny, nz)
    return table[i, ER] * e, table[i, EG] * e, table[i, EB] * e
