"""The world as a light: directions cosine-weighted about the shading normal, or from the
environment map (lights.environment: its table and sun cone) with probability ``share``; the density of either,
and whether the world is seen along a ray, as its ray visibility says. Kernels per ray and their
batch loops, which lights.collection calls once per wave."""
from __future__ import annotations

import math

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from ..base.vectors import basis
from ..base.warps import concentric_disk
from .environment import map_direction, map_pdf


@kernel(inline="always")
def cosine_direction(nx, ny, nz, u0, u1):
    """A cosine-weighted direction about n (concentric disk lifted to the hemisphere)."""
    a, b = concentric_disk(u0, u1)
    z = math.sqrt(max(1.0 - (a * a + b * b), 0.0))
    t0, t1, t2, b0, b1, b2 = basis(nx, ny, nz)
    return a * t0 + b * b0 + z * nx, a * t1 + b * b1 + z * ny, a * t2 + b * b2 + z * nz, z


@kernel(inline="always")
def world_pdf(nx, ny, nz, dx, dy, dz, share, cell, cell_area, sun):
    """Density of world sampling: the map's share of its density, the rest cosine."""
    cosine = max(nx * dx + ny * dy + nz * dz, 0.0) / math.pi
    if share <= 0:
        return cosine
    return share * map_pdf(cell, cell_area, sun, dx, dy, dz) + (1.0 - share) * cosine


@kernel(inline="always")
def sample_world_direction(nx, ny, nz, u0, u1, share, row_cdf, col_cdf, cell, cell_area, sun):
    """(dx, dy, dz, pdf): from the map with probability ``share`` (the first sample coordinate
    split), else cosine-weighted about n."""
    if u0 < share:
        dx, dy, dz = map_direction(row_cdf, col_cdf, sun, min(max(u0 / share, 0.0), 1.0 - 1e-12),
                                   min(max(u1, 0.0), 1.0 - 1e-12))
    else:
        c0 = min(max((u0 - share) / (1.0 - share), 0.0), 1.0 - 1e-12)
        dx, dy, dz, _ = cosine_direction(nx, ny, nz, c0, min(max(u1, 0.0), 1.0 - 1e-12))
    return dx, dy, dz, world_pdf(nx, ny, nz, dx, dy, dz, share, cell, cell_area, sun)


@kernel
def sample_uniform_world_batch(normal, u, radiance):
    n = len(u)
    wi, value, pdf = np.empty((n, 3)), np.zeros((n, 3)), np.empty(n)
    for j in range(n):
        wx, wy, wz, z = cosine_direction(normal[j, 0], normal[j, 1], normal[j, 2], u[j, 0], u[j, 1])
        wi[j, 0], wi[j, 1], wi[j, 2] = wx, wy, wz
        pdf[j] = z / math.pi
        if pdf[j] > 0:
            s = 1.0 / max(pdf[j], TINY)
            value[j, 0], value[j, 1], value[j, 2] = radiance[0] * s, radiance[1] * s, radiance[2] * s
    return wi, value, pdf


@kernel
def sample_map_world_batch(normal, u, share, row_cdf, col_cdf, cell, cell_area, sun):
    """Directions and densities; ``lit`` marks those above the normal with density > 0 (the
    caller evaluates the map's radiance there)."""
    n = len(u)
    wi, pdf, lit = np.empty((n, 3)), np.empty(n), np.zeros(n, np.bool_)
    for j in range(n):
        nx, ny, nz = normal[j, 0], normal[j, 1], normal[j, 2]
        dx, dy, dz, p = sample_world_direction(nx, ny, nz, u[j, 0], u[j, 1], share, row_cdf, col_cdf, cell,
                                               cell_area, sun)
        wi[j, 0], wi[j, 1], wi[j, 2], pdf[j] = dx, dy, dz, p
        lit[j] = nx * dx + ny * dy + nz * dz > 0 and p > 0
    return wi, pdf, lit


@kernel
def pdf_world_batch(normal, dirs, share, cell, cell_area, sun):
    out = np.empty(len(dirs))
    for j in range(len(dirs)):
        out[j] = world_pdf(normal[j, 0], normal[j, 1], normal[j, 2], dirs[j, 0], dirs[j, 1], dirs[j, 2], share,
                           cell, cell_area, sun)
    return out


@kernel
def world_shown_batch(dirs, straight, normal, camera, glossy, transmission):
    """Whether the world is seen along each ray: by the camera, or through reflection
    (d on the normal's side) or refraction, as its ray visibility says."""
    out = np.empty(len(dirs), np.bool_)
    for j in range(len(dirs)):
        if straight[j]:
            out[j] = camera
        elif dirs[j, 0] * normal[j, 0] + dirs[j, 1] * normal[j, 1] + dirs[j, 2] * normal[j, 2] >= 0:
            out[j] = glossy
        else:
            out[j] = transmission
    return out
