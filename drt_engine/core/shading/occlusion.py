"""The Ambient Occlusion node's rays, as Cycles' svm_ao traces them (kernel/svm/ao.h).

AO is the fraction of ``samples`` cosine-distributed rays (a concentric disk lifted onto the
hemisphere about the node's normal, or about its opposite with Inside) that meet nothing within
Distance: any object that casts shadows (Cycles' opaque shadow query) or, with Only Local, the
shaded object alone (Cycles' local intersection; here the object's own mesh scene, the ray
carried into its space). Rays leave the point offset off the surface as every DRT ray does
(Cycles excludes the point's own triangle instead).

Cycles evaluates the node only where it shades a surface a path hits (its raytrace kernel): at
light samples and in shadow rays' transparency it is 1. DRT does the same: a context without
``OcclusionRays`` (core.shading.surface) gives 1. Each of a hit's rays draws its own 2D
dimension of the path's sampler (core.sampling.dims.ao), so images stay deterministic.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..base.jit import kernel
from ..base.warps import concentric_disk
from ..geometry import embree
from ..geometry.accel import blocked, instance_frame, instance_of, object_ray, spawn_point
from ..sampling import dims as D
from .bevel import bevel_normals

MAX_SAMPLES = 128
"""Blender's limit on the node's Samples (core.sampling.dims reserves that many pairs per depth)."""


@dataclass
class OcclusionRays:
    """What the rays a shader traces from a batch of its points (the Ambient Occlusion node's here, the
    Bevel node's in core.shading.bevel) need: the scene (``geometry``, core.geometry.accel),
    the path's ``sampler`` with each point's pixel, sample id and depth, the point, its geometric
    normal facing the ray, offset scale, triangle and time, and ``normal`` the shading normal facing the ray
    (Cycles' sd->N, the node's default Normal); ``count`` is told how many rays each call traces."""

    geometry: object
    sampler: object
    pixel: np.ndarray
    sample: np.ndarray
    depth: int
    pos: np.ndarray
    ng: np.ndarray
    scale: np.ndarray
    prim: np.ndarray
    time: np.ndarray | None
    normal: np.ndarray
    count: Callable[[int], None] | None = None  # told how many rays each call traces
    min_pdf: np.ndarray | None = None  # the paths' least bounce density (Cycles' min_ray_pdf; None: not kept)

    def take(self, rows) -> "OcclusionRays":
        return OcclusionRays(self.geometry, self.sampler, self.pixel[rows], self.sample[rows], self.depth,
                             self.pos[rows], self.ng[rows], self.scale[rows], self.prim[rows],
                             None if self.time is None else self.time[rows], self.normal[rows], self.count,
                             None if self.min_pdf is None else self.min_pdf[rows])

    def bevel(self, radius, samples: int) -> np.ndarray:
        """(N, 3) the Bevel node's normal for ``radius`` (core.shading.bevel)."""
        return bevel_normals(self, radius, samples)

    def unoccluded(self, normal, distance, samples: int, inside: bool, only_local: bool) -> np.ndarray:
        """(N,) AO: the share of the rays about ``normal`` (None: the shading normal) that reach
        ``distance``; 1 where the distance is not positive or there are no samples (as Cycles)."""
        n = len(self.pos)
        samples = min(int(samples), MAX_SAMPLES)
        distance = np.broadcast_to(np.asarray(distance, float), (n,))
        if samples < 1 or n == 0 or not np.any(distance > 0):
            return np.ones(n)
        normal = self.normal if normal is None else np.asarray(normal, float)
        length = np.linalg.norm(normal, axis=1)
        normal = np.where(length[:, None] > 0, normal / np.where(length > 0, length, 1.0)[:, None], 0.0)
        if inside:
            normal = -normal
        dims = [D.ao(self.depth, k) for k in range(samples)]
        rand = self.sampler.pairs(self.pixel, self.sample, dims)
        g = self.geometry
        handles, pivots = g.local_scenes if only_local else (np.zeros(0, np.int64), np.zeros((0, 3)))
        if self.count is not None:
            self.count(int(((distance > 0) & (length > 0)).sum()) * samples)
        out = np.empty(n)
        _unoccluded(g.handle, g.tables, g.shadow_mask, handles, pivots, only_local, _c(self.pos), _c(self.ng),
                    _c(self.scale), _c(self.prim), g.time_values(self.time), _c(normal), rand,
                    _c(distance), out)
        return out


def traces(program) -> bool:
    """Whether a shader program has an Ambient Occlusion or a Bevel node (its hits then need
    ``OcclusionRays``)."""
    return program is not None and any(node.op in ("ao", "bevel") for node in program.nodes)


def _c(a):
    return np.ascontiguousarray(a)


@kernel
def _unoccluded(scene, geo, mask, handles, pivots, local, pos, ng, scale, prim, times, normal, rand, distance, out):
    """``OcclusionRays.unoccluded``'s rays, row by row: ``rand`` (N, S, 2) their sample values."""
    rayhit = embree.new_rayhit()
    frame = np.empty((2, 3, 4))
    center = geo[13]
    samples = rand.shape[1]
    for r in range(len(pos)):
        dist = distance[r]
        nx, ny, nz = normal[r, 0], normal[r, 1], normal[r, 2]
        if not dist > 0.0 or nx * nx + ny * ny + nz * nz == 0.0:
            out[r] = 1.0
            continue
        # a tangent frame about the normal (Duff et al. 2017)
        s = 1.0 if nz >= 0.0 else -1.0
        a = -1.0 / (s + nz)
        b = nx * ny * a
        tx, ty, tz = 1.0 + s * nx * nx * a, s * b, -s * nx
        bx, by, bz = b, s + ny * ny * a, -ny
        time = times[r] if len(times) else 0.5
        handle, row = 0, 0
        if local:
            i = instance_of(geo, prim[r])
            instance_frame(geo, i, time, frame)
            row = geo[5][i]
            handle = handles[row]
        free = 0
        for k in range(samples):
            x, y = concentric_disk(rand[r, k, 0], rand[r, k, 1])
            z = np.sqrt(max(1.0 - x * x - y * y, 0.0))
            dx, dy, dz = x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz
            ox, oy, oz = spawn_point(pos[r, 0], pos[r, 1], pos[r, 2], ng[r, 0], ng[r, 1], ng[r, 2], dx, dy, dz,
                                     scale[r])
            if local:
                hit = _blocked_in_object(handle, pivots, row, frame, rayhit, ox, oy, oz, dx, dy, dz, dist, time)
            else:
                hit = blocked(scene, center, rayhit, ox, oy, oz, dx, dy, dz, dist, time, mask)
            if not hit:
                free += 1
        out[r] = free / samples


@kernel(inline="always")
def _blocked_in_object(handle, pivots, row, frame, rayhit, ox, oy, oz, dx, dy, dz, tmax, time):
    """Whether the object whose world-to-object transform is ``frame[1]`` lies on the world ray
    before tmax (the ray carried into its mesh's scene)."""
    px, py, pz, ex, ey, ez = object_ray(frame, pivots, row, ox, oy, oz, dx, dy, dz)
    return embree.occluded1(handle, rayhit, px, py, pz, ex, ey, ez, 0.0, min(tmax, 3.0e38), time, -1)
