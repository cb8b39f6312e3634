"""Transparent shadows: shadow rays that go on through surfaces whose material lets light through.

As Cycles (intersect_shadow.h, shade_shadow.h): a shadow ray that meets a material that can be
transparent (``see_through``: a Transparent BSDF, a Principled Alpha below 1, either mixed or
textured) is attenuated by that surface's transparency (the transparent closures' weight, Cycles'
surface_shader_transparency) and goes on; an opaque surface blocks it, and so does a transparent
one past the limit: a path that took b transparent bounces may pass max(Max Transparent Bounces
- b - 1, 0) surfaces with its shadow rays (Cycles' integrate_shadow_max_transparent_hits, the
shadow path counting on from the path's transparent bounces).

The direct-light kernel (core.integrator.direct) traces each shadow ray to its first surface;
one that stops on a see-through surface is queued (``ShadowRays``). Rounds then alternate:
the queued hits' transparency per material group (shader programs, as the camera path binds
them, with Light Path's Is Shadow Ray set), and a kernel that sends the attenuated rays on from
each hit to the next surface, adding what gets through to the wave's radiance. A scene
without such a material never queues: its shadow rays stay plain occlusion queries.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..geometry import embree
from ..geometry.accel import Hits, instance_of, refine, spawn_point
from ..shading.lightpath import DEPTH, KIND, TRANSPARENT_DEPTH
from .clamp import clamped, limit_at, row_limits
from .hits import surface_records
from .records import ShadowRays

OPEN, OPAQUE, SEE_THROUGH = 0, 1, 2
"""What a shadow ray meets first: nothing, a surface that blocks it, a surface that may not."""
QF, QI = 14, 7
"""Columns of a queue's float rows (contribution RGB, origin, direction, distance left, time,
u, v, length from the shaded point) and int rows (path, triangle, the row of its paths' depths in
the batch that queued it, surfaces passed, surfaces allowed, light group or -1, the ray's Embree
mask)."""
_FAR = np.float32(3.0e38)


def limits(bounces: np.ndarray, max_transparent: int) -> np.ndarray:
    """The transparent surfaces each hit's shadow rays may pass (``bounces``: the paths' depths)."""
    return np.maximum(max_transparent - bounces[:, TRANSPARENT_DEPTH] - 1, 0).astype(np.int64)


@kernel(inline="always")
def first_surface(scene, geo, clear, rayhit, scratch, ox, oy, oz, dx, dy, dz, tmax, time, mask):
    """(what, triangle, t, u, v) of the first surface ``mask`` sees on the ray before tmax: OPEN,
    OPAQUE or SEE_THROUGH (the triangle's material can be transparent: ``clear`` per mesh triangle
    row)."""
    if scene == 0:
        return OPEN, -1, 0.0, 0.0, 0.0
    center = geo[13]
    th, uh, vh, _, _, _, p, _, inst = embree.intersect1(scene, rayhit, ox - center[0], oy - center[1],
                                                       oz - center[2], dx, dy, dz, 0.0, min(tmax, _FAR), time, mask)
    if p < 0:
        return OPEN, -1, 0.0, 0.0, 0.0
    prim = geo[6][inst] + p
    i = instance_of(geo, prim)
    if not clear[geo[4][geo[5][i], 3] + prim - geo[6][i]]:
        return OPAQUE, prim, 0.0, 0.0, 0.0
    t, u, v = refine(geo, prim, ox, oy, oz, dx, dy, dz, time, th, uh, vh, scratch)
    return SEE_THROUGH, prim, t, u, v


@kernel(inline="always")
def enqueue(qf, qi, m, c0, c1, c2, ox, oy, oz, dx, dy, dz, tmax, time, u, v, length, path, prim, hit, passed,
            allowed, group, mask):
    """Row m of a queue: a shadow ray stopped on a see-through surface (QF, QI)."""
    qf[m, 0], qf[m, 1], qf[m, 2] = c0, c1, c2
    qf[m, 3], qf[m, 4], qf[m, 5] = ox, oy, oz
    qf[m, 6], qf[m, 7], qf[m, 8] = dx, dy, dz
    qf[m, 9], qf[m, 10], qf[m, 11], qf[m, 12], qf[m, 13] = tmax, time, u, v, length
    qi[m, 0], qi[m, 1], qi[m, 2], qi[m, 3], qi[m, 4], qi[m, 5], qi[m, 6] = path, prim, hit, passed, allowed, group, mask


@kernel
def pass_through(scene, geo, clear, qf, qi, pos, ng, scale, limit, radiance, grouped, out_f, out_i):
    """Sends each queued ray (its contribution already attenuated by its surface, its own Embree
    mask in its int row) on from the far
    side of the surface at ``pos`` (geometric normal ``ng`` facing the ray, offset ``scale``):
    open, its contribution goes to ``radiance``, clamped to ``limit[r]`` (core.integrator.clamp), and
    to its light group's in ``grouped`` (empty: no light groups);
    opaque, or see-through past its allowed count, nothing; see-through within it, queued again in
    ``out``. Returns (rays traced, rows queued)."""
    rayhit = embree.new_rayhit()
    scratch = np.empty((2, 3, 4))
    m = 0
    for r in range(len(qf)):
        dx, dy, dz = qf[r, 6], qf[r, 7], qf[r, 8]
        ox, oy, oz = spawn_point(pos[r, 0], pos[r, 1], pos[r, 2], ng[r, 0], ng[r, 1], ng[r, 2], dx, dy, dz,
                                 scale[r])
        along = (ox - qf[r, 3]) * dx + (oy - qf[r, 4]) * dy + (oz - qf[r, 5]) * dz
        tmax = max(qf[r, 9] - along, 0.0)
        what, prim, t, u, v = first_surface(scene, geo, clear, rayhit, scratch, ox, oy, oz, dx, dy, dz, tmax,
                                            qf[r, 10], np.int32(qi[r, 6]))
        if what == OPEN:
            p = qi[r, 0]
            c0, c1, c2, _ = clamped(qf[r, 0], qf[r, 1], qf[r, 2], limit_at(limit, r))
            radiance[p, 0] += c0
            radiance[p, 1] += c1
            radiance[p, 2] += c2
            g = qi[r, 5]
            if len(grouped) and g >= 0:
                grouped[p, g, 0] += c0
                grouped[p, g, 1] += c1
                grouped[p, g, 2] += c2
        elif what == SEE_THROUGH and qi[r, 3] + 1 < qi[r, 4]:
            enqueue(out_f, out_i, m, qf[r, 0], qf[r, 1], qf[r, 2], ox, oy, oz, dx, dy, dz, tmax, qf[r, 10], u, v,
                    qf[r, 13] + along + t, qi[r, 0], prim, r, qi[r, 3] + 1, qi[r, 4], qi[r, 5], qi[r, 6])
            m += 1
    return len(qf), m


def new_queue(n: int, active: bool) -> tuple[np.ndarray, np.ndarray]:
    """Room for n queued rays (none when transparent shadows are off)."""
    n = n if active else 0
    return np.empty((n, QF)), np.empty((n, QI), np.int64)


def stopped(qf, qi, m: int, bounces: np.ndarray) -> ShadowRays | None:
    """The first m rows of a queue a kernel filled, with their paths' depths (None if empty)."""
    if m == 0:
        return None
    return ShadowRays(qf[:m].copy(), qi[:m].copy(), bounces[qi[:m, 2]])


class TransparentShadows:
    """Resolves the queued shadow rays of a wave (see the module's docstring): ``geometry`` and
    ``clear`` (per mesh triangle row), ``raises`` (per material: Bump Map Correction), ``bind`` the
    integrator's shaders per material group, ``clamp`` the (direct, indirect) limits of a
    contribution (core.integrator.clamp)."""

    def __init__(self, geometry, clear: np.ndarray, raises: np.ndarray, bind, count, clamp):
        self.geometry, self.clear, self.raises = geometry, clear, raises
        self.bind, self.count, self.clamp = bind, count, clamp

    def resolve(self, rays: ShadowRays, radiance: np.ndarray, grouped: np.ndarray, timed: bool):
        """Every queued ray taken through its surfaces until it is blocked or gets through (what
        gets through added to ``radiance`` and its light group's in ``grouped``, empty: none)."""
        geo = self.geometry
        while len(rays):
            n = len(rays)
            mat = geo.material_of(rays.i[:, 1])
            order = np.argsort(mat, kind="stable")  # each material's hits one slice, as for camera hits
            rays, mat = rays.take(order), mat[order]
            f, i = rays.f, rays.i
            prim, u, v, dirs = (np.ascontiguousarray(a) for a in (i[:, 1], f[:, 11], f[:, 12], f[:, 6:9]))
            # the shadow path's depths at this hit: no ray kind, the surfaces passed counted on
            bounces = rays.bounces.copy()
            bounces[:, KIND] = 0
            bounces[:, TRANSPARENT_DEPTH] += i[:, 3]
            surf = surface_records(geo, prim, u, v, f[:, 10] if timed else None, np.arange(n), dirs, self.raises,
                                   path=i[:, 0],
                                   mat=mat, throughput=f[:, 0:3], straight=np.zeros(n, bool), time=f[:, 10],
                                   bounces=bounces)
            hits = Hits(t=f[:, 13], prim=prim, u=u, v=v)
            seen = np.zeros((n, 3))
            for rows, group, shader in self.bind(surf, hits, shadow=True):
                seen[rows] = shader.transparency(group.wo_l[:, 2])
            c = f[:, 0:3] * seen
            go = np.flatnonzero((c.max(axis=1) > 0) & np.isfinite(c).all(axis=1))
            qf = np.ascontiguousarray(f[go])
            qf[:, 0:3] = c[go]
            out_f, out_i = new_queue(len(go), True)
            traced, m = pass_through(geo.handle, geo.tables, self.clear, qf,
                                     np.ascontiguousarray(i[go]),
                                     surf.pos[go], surf.ng[go], surf.scale[go],
                                     row_limits(self.clamp, rays.bounces[go, DEPTH] == 0), radiance, grouped,
                                     out_f, out_i)
            self.count("shadow", traced)
            rays = ShadowRays(out_f[:m], out_i[:m], rays.bounces[go][out_i[:m, 2]])
