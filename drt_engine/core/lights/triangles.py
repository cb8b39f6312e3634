"""Emissive triangles, together one next-event strategy: pick, sample, pdf and closed form.

A triangle is picked per shading point down lights.emitter_tree (by power over distance), then
a point on it uniformly in the solid angle it subtends where that is large
(lights.spherical_triangle), else uniformly by area; both sides emit, and the solid-angle pdf
includes the chance of the pick. Batch loops over a wave's points, since the triangles are not
rows of the light table. The closed form (``unoccluded_triangles``) sums each triangle's projected
solid angle (Lambert's edge integral, lights.solid_angle) times its constant emission: O(number
of triangles) per point.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from .emitter_tree import leaf_chance
from .solid_angle import polygon4
from .spherical_triangle import barycentrics_along, sample_direction, subtended


# -- sampling --------------------------------------------------------------------------------------
@kernel(inline="always")
def sample_triangle(vertices, triangles, ng, area, chance, i, px, py, pz, u0, u1):
    """A point on triangle i seen from p: (wx, wy, wz, dist, pdf, b0, b1, cos_l), pdf in solid
    angle including the ``chance`` of picking the triangle, two-sided. Uniform in the
    solid angle where lights.spherical_triangle chooses so, else uniform by area."""
    a, b, c = triangles[i, 0], triangles[i, 1], triangles[i, 2]
    nx, ny, nz = ng[i, 0], ng[i, 1], ng[i, 2]
    omega = subtended(vertices, a, b, c, nx, ny, nz, px, py, pz)
    if omega > 0:
        dx, dy, dz = sample_direction(vertices, a, b, c, omega, px, py, pz, u0, u1)
        b0, b1 = barycentrics_along(vertices, a, b, c, px, py, pz, dx, dy, dz)
    else:
        su = math.sqrt(u0)
        b0, b1 = 1.0 - su, u1 * su
    b2 = 1.0 - b0 - b1
    qx = b0 * vertices[a, 0] + b1 * vertices[b, 0] + b2 * vertices[c, 0]
    qy = b0 * vertices[a, 1] + b1 * vertices[b, 1] + b2 * vertices[c, 1]
    qz = b0 * vertices[a, 2] + b1 * vertices[b, 2] + b2 * vertices[c, 2]
    tx, ty, tz = qx - px, qy - py, qz - pz
    dist = math.sqrt(tx * tx + ty * ty + tz * tz)
    inv = 1.0 / max(dist, TINY)
    wx, wy, wz = tx * inv, ty * inv, tz * inv
    cos_l = abs(wx * nx + wy * ny + wz * nz)
    if omega > 0:
        pdf = chance / omega
    else:
        pdf = dist * dist / max(cos_l, TINY) * (chance / area[i])
    return wx, wy, wz, dist, pdf, b0, b1, cos_l


@kernel
def pdf_emissive_batch(vertices, triangles, ng, area, tree, rank, prim, origins, dirs, t):
    """The emissive strategy's pdf of directions ``dirs`` from ``origins`` that reach emissive
    triangles ``prim`` (their indices among the emitters) at distances ``t``: ``sample_triangle``'s
    with the chance lights.emitter_tree's walk takes the triangle (its leaf ``rank``) there."""
    out = np.empty(len(prim))
    for j in range(len(prim)):
        i = prim[j]
        ox, oy, oz = origins[j, 0], origins[j, 1], origins[j, 2]
        c = leaf_chance(tree, rank[i], ox, oy, oz)
        omega = subtended(vertices, triangles[i, 0], triangles[i, 1], triangles[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                          ox, oy, oz)
        if omega > 0:
            out[j] = c / omega
        else:
            cos_l = max(abs(dirs[j, 0] * ng[i, 0] + dirs[j, 1] * ng[i, 1] + dirs[j, 2] * ng[i, 2]), TINY)
            out[j] = c / area[i] * t[j] * t[j] / cos_l
    return out


# -- closed form -----------------------------------------------------------------------------------
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
