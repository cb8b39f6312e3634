"""The surface hits of a depth step in one kernel call: float64 position and normals rebuilt on
the world triangle (core.geometry.accel.hit_surface), the normals turned to face the ray, the
shading frame about the shading normal, the outgoing direction in it, and the distance that
clears the surface for the rays leaving it."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..base.vectors import Frame, basis
from ..bsdf.specular_normal import raised
from ..geometry.accel import hit_surface, offset_scale
from .records import SurfaceHits

_NONE = np.zeros(0, bool)


def surface_records(geometry, prim, u, v, ray_times, rows, dirs, keeps=_NONE, **carried) -> SurfaceHits:
    """The hits ``rows`` of a step's rays (``prim``, ``u``, ``v``, ``dirs`` per ray; ``ray_times``
    their shutter times, None when nothing moves) as a record (``surface_hits``), with the fields
    the paths carry to them (path, mat, throughput, straight, time, bounces) as given; ``keeps``
    per material (one past the end for none; empty: no material) whether its shading normal stays
    as the mesh has it where wo lies below it (PreparedScene.keeps_normal)."""
    n = len(rows)
    pos, ng, wo_l, normal = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    frame, inside, scale = np.empty((n, 3, 3)), np.empty(n, bool), np.empty(n)
    keep = keeps[carried["mat"]] if len(keeps) else np.zeros(n, bool)
    surface_hits(geometry.tables, prim, u, v, geometry.time_values(ray_times), rows, dirs, keep, pos, ng, frame,
                 wo_l, inside, scale, normal)
    return SurfaceHits(row=rows, prim=prim[rows], pos=pos, ng=ng, frame=Frame(frame), wo=-dirs[rows], wo_l=wo_l,
                       inside=inside, scale=scale, normal=normal, **carried)


@kernel
def surface_hits(geo, prim, u, v, times, rows, dirs, keep, pos, ng, frame, wo_l, inside, scale, normal):
    """For hits ``rows`` of the step's rays (each ray's triangle, barycentrics, shutter time (empty:
    nothing moves) and direction): world position, geometric normal and the shading frame
    (tangent, bitangent, normal rows) on the side the ray came from, wo in that frame, whether
    the ray came from the back, offset scale, and the shading normal as the mesh has it.

    A smooth shading normal that wo lies below (<= 1e-6), at a silhouette's rim, stays where the
    hit's material is Lambert-only (``keep`` per hit): Cycles keeps it for diffuse closures, whose
    light does not depend on wo. Other materials' is raised as Cycles raises a specular closure's
    (core.bsdf.specular_normal), the geometric normal where wo is still below it: one frame serves
    all their lobes, and glossy, glass and wo-dependent diffuse lobes need wo above their normal.
    """
    scratch = np.empty((2, 3, 4))
    for i in range(len(rows)):
        r = rows[i]
        time = times[r] if len(times) else 0.5
        px, py, pz, gx, gy, gz, sx, sy, sz = hit_surface(geo, prim[r], u[r], v[r], time, scratch)
        ox, oy, oz = -dirs[r, 0], -dirs[r, 1], -dirs[r, 2]
        back = ox * gx + oy * gy + oz * gz < 0
        flip = -1.0 if back else 1.0
        gx, gy, gz, nx, ny, nz = gx * flip, gy * flip, gz * flip, sx * flip, sy * flip, sz * flip
        if ox * nx + oy * ny + oz * nz <= 1e-6 and not keep[i]:
            nx, ny, nz = raised(gx, gy, gz, ox, oy, oz, nx, ny, nz)
            if ox * nx + oy * ny + oz * nz <= 1e-6:
                nx, ny, nz = gx, gy, gz
        tx, ty, tz, bx, by, bz = basis(nx, ny, nz)
        pos[i, 0], pos[i, 1], pos[i, 2] = px, py, pz
        ng[i, 0], ng[i, 1], ng[i, 2] = gx, gy, gz
        frame[i, 0, 0], frame[i, 0, 1], frame[i, 0, 2] = tx, ty, tz
        frame[i, 1, 0], frame[i, 1, 1], frame[i, 1, 2] = bx, by, bz
        frame[i, 2, 0], frame[i, 2, 1], frame[i, 2, 2] = nx, ny, nz
        wo_l[i, 0] = ox * tx + oy * ty + oz * tz
        wo_l[i, 1] = ox * bx + oy * by + oz * bz
        wo_l[i, 2] = ox * nx + oy * ny + oz * nz
        inside[i] = back
        scale[i] = offset_scale(geo, prim[r], px, py, pz)
        normal[i, 0], normal[i, 1], normal[i, 2] = sx, sy, sz
