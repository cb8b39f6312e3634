"""The Bevel node's normal, as Cycles' svm_bevel computes it (kernel/svm/bevel.h).

Each of Samples points on a disk of the node's Radius about the hit (Cycles' cubic BSSRDF
profile for its distance from the centre, the disk's axis the geometric normal with probability
1/2, either tangent with 1/4; Cycles' make_orthonormals frame) casts a short ray along that axis,
across the disk's height on both sides, against the hit's own object alone. Every surface
point the ray finds gives its normal (smooth where the mesh has corner normals, as Cycles'
smooth triangles), weighted by the power heuristic over the three axes and by the profile at
its real distance over the profile at the disk point's. The normalised sum, turned to face the
ray as the hit's normal does, is the node's normal; none found: the hit's shading normal.

Cycles keeps at most 4 of a ray's hits (a random subset, the weights scaled by hits / 4): DRT
takes them all, the same sum in expectation. Rays run in the object's own Embree scene
(core.geometry.accel.Geometry.local_scenes), closest hit after closest hit. Cycles skips the
node (the shading normal) on paths whose least bounce density (min_ray_pdf) is below 8, and
wherever it does not trace rays from a shader (light samples, shadow rays). A hit's disk samples
are consecutive sample ids of one 2D dimension (core.sampling.dims.bevel), stratified together
as Cycles' branched samples are: the normalised sum is not linear in them, so their
stratification shows in the mean image.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..geometry import embree
from ..geometry.accel import hit_surface, instance_frame, instance_of, object_ray
from ..sampling import dims as D

MAX_SAMPLES = 128
"""Blender's limit on the node's Samples (core.sampling.dims reserves that many pairs per depth)."""
BLURRY_PDF = 8.0
"""Cycles' min_ray_pdf below which a path no longer bevels (a blurry indirect ray)."""
_MAX_HITS = 64  # hits taken along one disk ray (Cycles takes 4 at random and scales)


def bevel_normals(rays, radius, samples: int) -> np.ndarray:
    """(N, 3) the Bevel node's normal at the points of ``rays`` (core.shading.occlusion.OcclusionRays)
    for ``radius`` (scalar or per point); their shading normal where Cycles would not bevel."""
    n = len(rays.pos)
    samples = min(int(samples), MAX_SAMPLES)
    radius = np.ascontiguousarray(np.broadcast_to(np.asarray(radius, float), (n,)))
    go = radius > 0
    if rays.min_pdf is not None:
        go &= ~(rays.min_pdf < BLURRY_PDF)
    if samples < 1 or not go.any():
        return np.array(rays.normal, float)
    # sample k of a hit at sample id samples * id + k of one dimension, as Cycles' branched samples
    ids = np.asarray(rays.sample, np.int64)[:, None] * samples + np.arange(samples)
    rand = rays.sampler.pairs(np.repeat(rays.pixel, samples), ids.ravel(), [D.bevel(rays.depth)])
    rand = rand.reshape(n, samples, 2)
    g = rays.geometry
    handles, pivots = g.local_scenes
    if rays.count is not None:
        rays.count(int(go.sum()) * samples)
    out = np.empty((n, 3))
    _bevel(g.tables, handles, pivots, _c(rays.pos), _c(rays.ng), _c(rays.normal), _c(rays.prim),
           g.time_values(rays.time), rand, radius, go, out)
    return out


def bevels(program) -> bool:
    """Whether a shader program has a Bevel node (its paths then keep their least bounce density)."""
    return program is not None and any(node.op == "bevel" for node in program.nodes)


def _c(a):
    return np.ascontiguousarray(a)


@kernel(inline="always")
def _cubic_pdf(radius, r):
    """Cycles' cubic profile 10 (R - r)^3 / (pi R^5) (0 from R on)."""
    if r >= radius:
        return 0.0
    f = radius - r
    return 10.0 * f * f * f / (radius ** 5 * np.pi)


@kernel(inline="always")
def _cubic_radius(xi):
    """The root of 10x^2 - 20x^3 + 15x^4 - 4x^5 = xi in [0, 1] by Cycles' Newton steps."""
    x = 0.25
    for _ in range(10):
        x2 = x * x
        x3 = x2 * x
        nx = 1.0 - x
        f = 10.0 * x2 - 20.0 * x3 + 15.0 * x2 * x2 - 4.0 * x2 * x3 - xi
        d = 20.0 * (x * nx) * (nx * nx)
        if abs(f) < 1e-6 or d == 0.0:
            break
        x = min(max(x - f / d, 0.0), 1.0)
    return x


@kernel
def _bevel(geo, handles, pivots, pos, ng, normal, prim, times, rand, radius, go, out):
    """``bevel_normals`` row by row: ``rand`` (N, S, 2) the disk samples' values, ``ng`` and
    ``normal`` the geometric and shading normals facing the ray."""
    rayhit = embree.new_rayhit()
    frame = np.empty((2, 3, 4))
    scratch = np.empty((2, 3, 4))
    samples = rand.shape[1]
    for r in range(len(pos)):
        if not go[r]:
            out[r, 0], out[r, 1], out[r, 2] = normal[r, 0], normal[r, 1], normal[r, 2]
            continue
        R = radius[r]
        time = times[r] if len(times) else 0.5
        i = instance_of(geo, prim[r])
        instance_frame(geo, i, time, frame)
        row = geo[5][i]
        handle = handles[row]
        first = geo[6][i]
        # the hit's own outward normal says whether the ray came from the back (Cycles' SD_BACKFACING)
        own = hit_surface(geo, prim[r], 1.0 / 3.0, 1.0 / 3.0, time, scratch)
        nx, ny, nz = ng[r, 0], ng[r, 1], ng[r, 2]
        back = own[3] * nx + own[4] * ny + own[5] * nz < 0.0
        # Cycles' make_orthonormals about the geometric normal
        if nx != ny or nx != nz:
            ax, ay, az = nz - ny, nx - nz, ny - nx
        else:
            ax, ay, az = nz - ny, nx + nz, -ny - nx
        length = np.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax / length, ay / length, az / length
        bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
        sx = sy = sz = 0.0
        for k in range(samples):
            u0, u1 = rand[r, k, 0], rand[r, k, 1]
            # the disk's axis: the normal (1/2) or a tangent (1/4 each), the others span the disk
            if u0 < 0.5:
                pn, pt, pb = 0.5, 0.25, 0.25
                u0 *= 2.0
                dn = (nx, ny, nz)
                dt = (ax, ay, az)
                db = (bx, by, bz)
            elif u0 < 0.75:
                pn, pt, pb = 0.25, 0.5, 0.25
                u0 = (u0 - 0.5) * 4.0
                dn = (ax, ay, az)
                dt = (nx, ny, nz)
                db = (bx, by, bz)
            else:
                pn, pt, pb = 0.25, 0.25, 0.5
                u0 = (u0 - 0.75) * 4.0
                dn = (bx, by, bz)
                dt = (ax, ay, az)
                db = (nx, ny, nz)
            phi = 2.0 * np.pi * u0
            disk_r = _cubic_radius(u1) * R
            height = np.sqrt(max(R * R - disk_r * disk_r, 0.0))
            cx, cy = disk_r * np.cos(phi), disk_r * np.sin(phi)
            ox = pos[r, 0] + dn[0] * height + cx * dt[0] + cy * db[0]
            oy = pos[r, 1] + dn[1] * height + cx * dt[1] + cy * db[1]
            oz = pos[r, 2] + dn[2] * height + cx * dt[2] + cy * db[2]
            px, py, pz, ex, ey, ez = object_ray(frame, pivots, row, ox, oy, oz, -dn[0], -dn[1], -dn[2])
            disk_pdf = _cubic_pdf(R, disk_r)
            tnear = 0.0
            for _ in range(_MAX_HITS):
                t, hu, hv, _gx, _gy, _gz, local, _geom, _inst = embree.intersect1(
                    handle, rayhit, px, py, pz, ex, ey, ez, tnear, 2.0 * height, time, -1)
                if local < 0:
                    break
                tnear = t + max(t, 1e-30) * 2.0**-20  # past this hit: the next one along the ray
                hit = hit_surface(geo, first + local, hu, hv, time, scratch)
                gx, gy, gz = hit[3], hit[4], hit[5]  # outward, as Cycles' Ng under negative scale
                an = pn * abs(dn[0] * gx + dn[1] * gy + dn[2] * gz)
                at = pt * abs(dt[0] * gx + dt[1] * gy + dt[2] * gz)
                ab = pb * abs(db[0] * gx + db[1] * gy + db[2] * gz)
                denom = an * an + at * at + ab * ab
                if denom == 0.0 or disk_pdf == 0.0:
                    continue
                dx, dy, dz = hit[0] - pos[r, 0], hit[1] - pos[r, 1], hit[2] - pos[r, 2]
                w = an / denom * _cubic_pdf(R, np.sqrt(dx * dx + dy * dy + dz * dz)) / disk_pdf
                sx += w * hit[6]
                sy += w * hit[7]
                sz += w * hit[8]
        length = np.sqrt(sx * sx + sy * sy + sz * sz)
        if not length > 0.0:
            out[r, 0], out[r, 1], out[r, 2] = normal[r, 0], normal[r, 1], normal[r, 2]
            continue
        side = -1.0 / length if back else 1.0 / length
        out[r, 0], out[r, 1], out[r, 2] = sx * side, sy * side, sz * side
