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


def surface_records(geometry, prim, u, v, ray_times, rows, dirs, raises, **carried) -> SurfaceHits:
    """The hits ``rows`` of a step's rays (``prim``, ``u``, ``v``, ``dirs`` per ray; ``ray_times``
    their shutter times, None when nothing moves) as a record (``surface_hits``), with the fields
    the paths carry to them (path, mat, throughput, straight, time, bounces) as given; ``raises``
    per material: its Bump Map Correction is on (Cycles raises its specular normals only then)."""
    n = len(rows)
    pos, ng, wo_l, normal, ns, dn = (np.empty((n, 3)) for _ in range(6))
    frame, inside, scale = np.empty((n, 3, 3)), np.empty(n, bool), np.empty(n)
    surface_hits(geometry.tables, prim, u, v, geometry.time_values(ray_times), rows, dirs, raises[carried["mat"]],
                 pos, ng, frame, wo_l, inside, scale, normal, ns, dn)
    return SurfaceHits(row=rows, prim=prim[rows], pos=pos, ng=ng, frame=Frame(frame), ns=ns, dn=dn, wo=-dirs[rows],
                       wo_l=wo_l, inside=inside, scale=scale, normal=normal, **carried)


@kernel
def surface_hits(geo, prim, u, v, times, rows, dirs, raises, pos, ng, frame, wo_l, inside, scale, normal, ns, dn):
    """For hits ``rows`` of the step's rays (each ray's triangle, barycentrics, shutter time (empty:
    nothing moves) and direction; per hit, whether its material raises normals): world position,
    geometric normal and the shading frame (tangent, bitangent, normal rows) on the side the ray came from, wo in that frame, whether
    the ray came from the back, offset scale, the shading normal as the mesh has it, and facing
    the ray (``ns``, Cycles' sd->N), and that normal in the frame (``dn``).

    Cycles gives its diffuse closures the smooth shading normal as it is, whose light does not
    depend on wo, and the others that normal raised toward the geometric one where wo's mirror
    image about it would leave below the surface, near a silhouette's rim, wo below the normal or
    not (core.bsdf.specular_normal). The frame is about the raised normal (the geometric normal
    where wo is still below it), and the diffuse lobes take theirs as ``dn``
    (core.bsdf.diffuse_normal): (0, 0, 1) exactly where nothing was raised. A material whose Bump
    Map Correction is off keeps the mesh's normal for every lobe, wo below it or not, as Cycles'
    maybe_ensure_valid_specular_reflection does (its specular lobes then reflect nothing where
    wo lies below: Cycles' microfacet closures need cos(N, wi) > 0).
    """
    scratch = np.empty((2, 3, 4))
    for i in range(len(rows)):
        r = rows[i]
        time = times[r] if len(times) else 0.5
        px, py, pz, gx, gy, gz, sx, sy, sz = hit_surface(geo, prim[r], u[r], v[r], time, scratch)
        ox, oy, oz = -dirs[r, 0], -dirs[r, 1], -dirs[r, 2]
        back = ox * gx + oy * gy + oz * gz < 0
        flip = -1.0 if back else 1.0
        gx, gy, gz, kx, ky, kz = gx * flip, gy * flip, gz * flip, sx * flip, sy * flip, sz * flip
        nx, ny, nz = raised(gx, gy, gz, ox, oy, oz, kx, ky, kz) if raises[i] else (kx, ky, kz)
        if raises[i] and ox * nx + oy * ny + oz * nz <= 1e-6:
            nx, ny, nz = gx, gy, gz
        turned = nx != kx or ny != ky or nz != kz
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
        ns[i, 0], ns[i, 1], ns[i, 2] = kx, ky, kz
        dn[i, 0], dn[i, 1], dn[i, 2] = 0.0, 0.0, 1.0
        if turned:
            dn[i, 0] = kx * tx + ky * ty + kz * tz
            dn[i, 1] = kx * bx + ky * by + kz * bz
            dn[i, 2] = kx * nx + ky * ny + kz * nz
