"""The world as a light: directions cosine-weighted about the shading normal, or from the
environment map (lights.environment: its table and sun cone) with probability ``share``; the density of either,
and whether the world is seen along a ray, as its ray visibility says. Kernels per ray and their
batch loops, which lights.collection calls once per wave."""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel
from ..base.vectors import basis
from ..base.warps import concentric_disk
from ..shading.lightpath import DIFFUSE, GLOSSY, REFLECT, TRANSMIT
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
def pdf_world_batch(normal, dirs, share, cell, cell_area, sun):
    out = np.empty(len(dirs))
    for j in range(len(dirs)):
        out[j] = world_pdf(normal[j, 0], normal[j, 1], normal[j, 2], dirs[j, 0], dirs[j, 1], dirs[j, 2], share,
                           cell, cell_area, sun)
    return out


@kernel(inline="always")
def shown(straight, kinds, j, reflected, camera, diffuse, glossy, transmission):
    """Whether ray j sees a light of this ray visibility, as Cycles' background and light shaders
    decide: by the camera (``straight``); with ``kinds`` (the rays' kind bits,
    core.shading.lightpath) hidden from a diffuse ray by Diffuse, from a glossy reflection by
    Glossy, from any transmission (a translucent one too) by Transmission; without them (no ray
    took a diffuse lobe) a ray ``reflected`` (on the normal's side) is a glossy one, any other a
    transmission."""
    if straight:
        return camera
    if len(kinds):
        k = kinds[j]
        return not (((k & DIFFUSE) != 0 and not diffuse)
                    or ((k & (GLOSSY | REFLECT)) == (GLOSSY | REFLECT) and not glossy)
                    or ((k & TRANSMIT) != 0 and not transmission))
    return glossy if reflected else transmission


@kernel
def world_shown_batch(dirs, straight, normal, kinds, camera, diffuse, glossy, transmission):
    """Whether the world is seen along each ray, as its ray visibility says (``shown``)."""
    out = np.empty(len(dirs), np.bool_)
    for j in range(len(dirs)):
        reflected = dirs[j, 0] * normal[j, 0] + dirs[j, 1] * normal[j, 1] + dirs[j, 2] * normal[j, 2] >= 0
        out[j] = shown(straight[j], kinds, j, reflected, camera, diffuse, glossy, transmission)
    return out


@kernel
def lights_shown_batch(ids, dirs, straight, normal, kinds, visibility):
    """Whether each ray sees the light it hit (``ids``, -1: none), as that light's ray visibility
    (``visibility`` per light: camera, diffuse, glossy, transmission) says (``shown``)."""
    out = np.empty(len(dirs), np.bool_)
    for j in range(len(dirs)):
        i = ids[j]
        if i < 0:
            out[j] = False
            continue
        reflected = dirs[j, 0] * normal[j, 0] + dirs[j, 1] * normal[j, 1] + dirs[j, 2] * normal[j, 2] >= 0
        out[j] = shown(straight[j], kinds, j, reflected, visibility[i, 0], visibility[i, 1], visibility[i, 2],
                       visibility[i, 3])
    return out
