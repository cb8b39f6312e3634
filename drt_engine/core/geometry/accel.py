"""Triangles in Embree scenes, and batched ray queries at each ray's own time.

Embree works in float32 with tnear fixed at 0 and has no motion in this binding, so
precision and motion are ours to manage:

- static geometry is flattened to world space in one Embree scene, relative to a
  centre (the camera), and hit points are rebuilt in float64 from barycentrics;
- a rigidly moving instance keeps its own object-space scene; rays are carried into
  object space at their own time (the direction is not renormalised, so distances
  along the ray stay world distances);
- a deforming mesh is baked into one scene per time bucket; a ray uses the bucket of
  its time, and the time dimension is stratified, so buckets are too;
- new rays leave a surface offset along the geometric normal by a bound on the
  float32 error of the hit.

Triangles of all parts share one global numbering, so materials, normals and lights
index the same arrays whatever part a hit came from. The per-ray arithmetic (hit
reconstruction, the terminator lift, offsets, carrying rays into a part's frame) is in
scalar kernels over ``Geometry.tables``, flat arrays a fused stage kernel can read too;
Embree is called in batches between them.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..base.jit import kernel
from ..base.vectors import unit
from ..errors import SceneError
from ..scene import SceneData
from .motion import Motion, frame_at, invert_frame

_EPS_REL = 2.0**-16  # ~64 float32 ulps: covers origin rounding plus Embree's own test error
_EPS_ABS = 2.0**-34  # with _EPS_REL: ~4 float64 ulps of the world coordinates hit points are rebuilt in
_CHUNK = 1 << 16  # rays per Embree call: bounds its output buffers
_FAR = np.float32(3.0e38)
DEFORM_BUCKETS = 8
_KINDS = {"static": 0, "rigid": 1, "deform": 2}


@dataclass
class Hits:
    """Closest hits of a batch of rays; ``prim`` is -1 for a miss."""

    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray

    @property
    def hit(self) -> np.ndarray:
        return self.prim >= 0


@dataclass
class RayTimes:
    """Shutter times of a batch of rays (None when nothing moves).

    A path keeps its camera sample's time down its whole tree. Kernels work out a moving
    part's transform at a ray's time where they need it: a slerp and a 3x3 inverse cost
    less than gathering precomputed transforms as paths go on.
    """

    values: np.ndarray | None

    def __getitem__(self, index) -> "RayTimes":
        return RayTimes(None if self.values is None else self.values[index])


@dataclass
class _Part:
    kind: str  # "static" | "rigid" | "deform"
    base: int  # first global triangle id
    count: int
    center: np.ndarray
    scenes: list
    motion: Motion | None = None
    buckets: list | None = None  # deform, until Geometry.tables stacks them: (world vertices, mirrored) per bucket
    first_vertex: int = 0


def _embree(vertices: np.ndarray, triangles: np.ndarray):
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    v = vertices.astype(np.float32)
    if not np.isfinite(v).all():
        raise SceneError("geometry too far from the camera to be represented in single precision")
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, np.ascontiguousarray(v), np.ascontiguousarray(triangles, dtype=np.int32))
    return scene


def _cross_normals(p: np.ndarray):
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = np.linalg.norm(n, axis=1)
    return n, length


class Geometry:
    """All instanced triangles and the Embree scenes that answer ray queries.

    Global per-triangle arrays: ``triangles`` (indices into ``vertices``: world space
    for static and deforming parts, object space for rigid ones), ``material``,
    ``part``, ``ng``/``ns`` in the same space as the vertices, and mid-shutter world
    copies ``world_vertices``, ``world_ng``, ``area`` for light sampling.
    """

    def __init__(self, scene: SceneData, center: np.ndarray):
        self.center = np.asarray(center, dtype=np.float64)
        self.warnings: list[str] = []
        self.parts: list[_Part] = []
        verts, world_verts, tris, mats, normals, flips, sources = [], [], [], [], [], [], []
        self._dropped = 0
        static = []
        moving = []
        for i_inst, inst in enumerate(scene.instances):
            mesh = scene.meshes[inst.mesh]
            if len(mesh.triangles) == 0:
                continue
            motion = Motion(inst.matrices)
            deforming = mesh.motion_vertices is not None and not np.allclose(
                mesh.motion_vertices, mesh.motion_vertices[:1])
            (moving if motion.moving or deforming else static).append((i_inst, mesh, motion, deforming))

        vertex_count = [0]  # vertices appended so far (a running count: summing is quadratic in objects)

        def add(mesh, linear, translation, in_world, inst_index):
            """Append one mesh's triangles; returns the (kept) triangle count."""
            v_obj = mesh.vertices
            with np.errstate(invalid="ignore", over="ignore"):  # NaN / Inf vertices are dropped below
                v_world = v_obj @ linear.T + translation
            v = v_world if in_world else v_obj
            bad = ~np.isfinite(v_world).all(axis=1)
            tri = mesh.triangles
            keep = ~bad[tri].any(axis=1)
            p = v_world[tri]
            keep &= _cross_normals(np.where(np.isfinite(p), p, 0.0))[1] > 0
            self._dropped += int((~keep & bad[tri].any(axis=1)).sum())
            offset = vertex_count[0]
            vertex_count[0] += len(v)
            verts.append(np.where(bad[:, None], 0.0, v))
            world_verts.append(np.where(bad[:, None], 0.0, v_world))
            tris.append(tri[keep] + offset)
            mats.append(mesh.material_indices[keep])
            kept = np.flatnonzero(keep)
            sources.append(np.stack([np.full(len(kept), inst_index), kept], axis=1))
            det = np.linalg.det(linear)
            if mesh.corner_normals is not None:
                ns = mesh.corner_normals[keep].astype(np.float64)
                if in_world:
                    ns = ns @ _normal_matrix(linear).T
                normals.append(ns)
            else:
                normals.append(int(keep.sum()))
            # baked world triangles wind backwards under mirroring; object-space ones do not
            flips.append(np.full(int(keep.sum()), in_world and det < 0))
            return int(keep.sum()), offset

        count = 0
        if static:
            start = count
            for inst, mesh, motion, _ in static:
                n, _ = add(mesh, motion.linear[0], motion.translation[0], True, inst)
                count += n
            self.parts.append(_Part("static", start, count - start, self.center, []))
        for inst, mesh, motion, deforming in moving:
            if deforming:
                mid = motion.matrix_at(0.5)
                n, first = add(_mid_mesh(mesh), mid[:3, :3], mid[:3, 3], True, inst)
                part = _Part("deform", count, n, self.center, [], first_vertex=first)
                part.buckets = [(mesh, motion)]
            else:
                n, first = add(mesh, motion.linear[len(motion.linear) // 2],
                               motion.translation[len(motion.translation) // 2], False, inst)
                lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
                part = _Part("rigid", count, n, 0.5 * (lo + hi), [], motion=motion, first_vertex=first)
            count += n
            self.parts.append(part)

        if self._dropped:
            self.warnings.append(f"{self._dropped} triangles with NaN or infinite vertex coordinates were left out")
        self.vertices = np.concatenate(verts) if verts else np.zeros((0, 3))
        self.world_vertices = np.concatenate(world_verts) if world_verts else np.zeros((0, 3))
        self.triangles = np.concatenate(tris) if tris else np.zeros((0, 3), np.int32)
        self.material = np.concatenate(mats) if mats else np.zeros(0, np.int32)
        self.source = np.concatenate(sources) if sources else np.zeros((0, 2), np.int64)
        """Per triangle: (instance index in the scene, triangle index in its mesh), for attributes."""
        flip = np.concatenate(flips) if flips else np.zeros(0, bool)
        self.part = np.zeros(len(self.triangles), np.int64)
        for k, part in enumerate(self.parts):
            self.part[part.base:part.base + part.count] = k

        n_local, length = _cross_normals(self.vertices[self.triangles])
        self.ng = n_local / np.maximum(length, 1e-300)[:, None] * np.where(flip, -1.0, 1.0)[:, None]
        n_world, world_len = _cross_normals(self.world_vertices[self.triangles])
        self.area = 0.5 * world_len
        self.world_ng = self._mid_world_normals(n_world / np.maximum(world_len, 1e-300)[:, None])
        self.ns = self._shading_normals(normals)
        rel = self.world_vertices[self.triangles] - self.center
        # the offset also clears the float64 rounding of world positions far from the origin
        world = np.abs(self.world_vertices[self.triangles]).max(axis=(1, 2)) * _EPS_ABS if len(rel) else 0.0
        self.tri_scale = np.maximum(np.abs(rel).max(axis=(1, 2)), world) if len(rel) else np.zeros(0)
        for part in self.parts:
            self._build(part)
        self.tables = self._tables()

    # -- construction helpers ------------------------------------------------------
    def _mid_world_normals(self, n_world):
        """World normals at mid-shutter, oriented like ``ng`` (outward under mirroring)."""
        out = n_world.copy()
        for part in self.parts:
            s = slice(part.base, part.base + part.count)
            det = np.linalg.det(part.motion.linear[len(part.motion.linear) // 2]) if part.motion else 1.0
            if part.kind == "rigid" and det < 0:
                out[s] = -out[s]
            elif part.kind != "rigid":
                out[s] = self.ng[s]
        return out

    def _shading_normals(self, normals):
        """Corner normals per triangle; ``normals`` holds an array, or a flat mesh's count."""
        if all(isinstance(n, int) for n in normals):
            return None
        ns = np.repeat(self.ng[:, None, :], 3, axis=1)
        start = 0
        for n in normals:
            if isinstance(n, int):
                start += n
                continue
            seg = ns[start:start + len(n)]
            length = np.linalg.norm(n, axis=2, keepdims=True)
            good = (length > 1e-12) & np.isfinite(length)
            ns[start:start + len(n)] = np.where(good, n / np.where(good, length, 1.0), seg)
            start += len(n)
        return ns

    def _build(self, part: _Part):
        tri = self.triangles[part.base:part.base + part.count]
        if part.count == 0:
            return
        if part.kind == "static":
            part.scenes = [_embree(self.vertices - part.center, tri)]
        elif part.kind == "rigid":
            part.scenes = [_embree(self.vertices - part.center, tri)]
        else:
            mesh, motion = part.buckets[0]
            part.buckets = []
            keep_tri = tri - part.first_vertex
            for b in range(DEFORM_BUCKETS):
                time = (b + 0.5) / DEFORM_BUCKETS
                m = motion.matrix_at(time)
                v = _vertices_at(mesh, time) @ m[:3, :3].T + m[:3, 3]
                part.buckets.append((v, np.linalg.det(m[:3, :3]) < 0))
                part.scenes.append(_embree(v - part.center, keep_tri))

    def _tables(self):
        """Everything the hit kernels read, as one tuple of flat arrays (see ``hit_surface``).

        Per part: kind, the rows of its shutter steps in the stacked motion tables, the
        first row of its vertices in the stacked deform buckets (and which buckets mirror)."""
        n_parts = max(len(self.parts), 1)
        kind = np.zeros(n_parts, np.int64)
        steps = np.zeros((n_parts, 2), np.int64)  # first row and count in the motion tables
        deform = np.zeros(n_parts, np.int64)  # offset from global vertex ids to bucket rows
        mirrored = np.zeros((n_parts, DEFORM_BUCKETS), np.bool_)
        motion = [np.zeros((0, 3)), np.zeros((0, 4)), np.zeros((0, 3, 3))]
        buckets, rows = [], 0
        for k, part in enumerate(self.parts):
            kind[k] = _KINDS[part.kind]
            if part.kind == "rigid":
                table = part.motion.table
                steps[k] = len(motion[0]), len(table[0])
                motion = [np.concatenate([a, b]) for a, b in zip(motion, table)]
            elif part.kind == "deform" and part.scenes:
                deform[k] = rows - part.first_vertex
                buckets.append(np.stack([v for v, _ in part.buckets]))
                mirrored[k] = [m for _, m in part.buckets]
                rows += buckets[-1].shape[1]
                part.buckets = None  # the rows below hold them
        bucket_vertices = np.concatenate(buckets, axis=1) if buckets else np.zeros((DEFORM_BUCKETS, 0, 3))
        ns = self.ns if self.ns is not None else np.zeros((0, 3, 3))
        return (self.vertices, self.triangles, self.ng, ns, self.part, kind, steps,
                motion[0], motion[1], motion[2], deform, bucket_vertices, mirrored, self.center, self.tri_scale)

    # -- queries ---------------------------------------------------------------------
    @property
    def triangle_count(self) -> int:
        return len(self.triangles)

    @property
    def moving(self) -> bool:
        return any(p.kind != "static" for p in self.parts)

    def _run(self, scene, o, d, tmax, query):
        far = np.minimum(tmax, _FAR).astype(np.float32)
        output = 1 if query == "INTERSECT" else 0
        return [scene.run(o[a:a + _CHUNK], d[a:a + _CHUNK], far[a:a + _CHUNK], query=query, output=output)
                for a in range(0, max(len(o), 1), _CHUNK)]

    def ray_times(self, time) -> RayTimes:
        """The times as a RayTimes (None when nothing moves)."""
        if isinstance(time, RayTimes):
            return time
        return RayTimes(None if time is None else np.asarray(time, dtype=np.float64))

    def _rays_in(self, k: int, origins, directions, times: RayTimes, index):
        """float32 (origins, directions) of rays ``index`` in part k's Embree frame."""
        o = np.empty((len(index), 3), np.float32)
        d = np.empty((len(index), 3), np.float32)
        t = times.values if self.parts[k].kind == "rigid" else np.zeros(0)
        _to_part(self.tables, k, origins, directions, t, index, self.parts[k].center, o, d)
        return o, d

    def _groups(self, part: _Part, n: int, time):
        """(scene, ray indices) pairs a part must answer for n rays."""
        if part.kind != "deform":
            return [(part.scenes[0], np.arange(n))]
        bucket = np.minimum((time.values * DEFORM_BUCKETS).astype(np.int64), DEFORM_BUCKETS - 1)
        return [(part.scenes[b], np.flatnonzero(bucket == b)) for b in range(DEFORM_BUCKETS)]

    def intersect(self, origins, directions, tmax, time=None) -> Hits:
        n = len(origins)
        best = Hits(np.full(n, np.inf), np.full(n, -1, np.int64), np.zeros(n), np.zeros(n))
        limit = np.array(tmax, dtype=np.float64, copy=True)
        times = self.ray_times(time)
        for pk, part in enumerate(self.parts):
            if not part.scenes:
                continue
            for scene, idx in self._groups(part, n, times):
                if len(idx) == 0:
                    continue
                o, d = self._rays_in(pk, origins, directions, times, idx)
                for a, found in zip(range(0, len(idx), _CHUNK), self._run(scene, o, d, limit[idx], "INTERSECT")):
                    _keep_closer(idx[a:a + _CHUNK], found["primID"], found["tfar"], found["u"], found["v"],
                                 part.base, best.t, best.prim, best.u, best.v, limit)
        return best

    def occluded(self, origins, directions, tmax, time=None) -> np.ndarray:
        n = len(origins)
        blocked = np.zeros(n, dtype=bool)
        times = self.ray_times(time)
        for k, part in enumerate(self.parts):
            if not part.scenes:
                continue
            for scene, idx in self._groups(part, n, times):
                idx = idx[~blocked[idx]]
                if len(idx) == 0:
                    continue
                o, d = self._rays_in(k, origins, directions, times, idx)
                blocked[idx] = np.concatenate(self._run(scene, o, d, tmax[idx], "OCCLUDED")) >= 0
        return blocked

    def surface(self, hits: Hits, index: np.ndarray, time=None):
        """Float64 world position, geometric and shading normal of hits[index]."""
        n = len(index)
        out = np.empty((n, 9))
        _surfaces(self.tables, hits.prim, hits.u, hits.v, self._time_values(time), np.asarray(index), out)
        return out[:, 0:3], out[:, 3:6], out[:, 6:9]

    def smooth_offset(self, hits: Hits, index: np.ndarray, time=None) -> np.ndarray:
        """World vector from hits[index] to the smooth surface its corner normals describe (see
        ``lift``); zero on flat triangles."""
        out = np.zeros((len(index), 3))
        if self.ns is None or len(index) == 0:
            return out
        _lifts(self.tables, hits.prim, hits.u, hits.v, self._time_values(time), np.asarray(index), out)
        return out

    def _time_values(self, time) -> np.ndarray:
        if not self.moving or time is None:
            return np.zeros(0)
        return self.ray_times(time).values

    def offset_scale(self, prim: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Distance that safely clears the surface of triangle ``prim`` at ``pos``."""
        out = np.empty(len(prim))
        _offset_scales(self.tables, prim, pos, out)
        return out


def spawn(pos: np.ndarray, ng: np.ndarray, direction: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Ray origins pushed off the surface to the side ``direction`` leaves through."""
    out = np.empty((len(pos), 3))
    _spawns(pos, ng, direction, scale, out)
    return out


# -- kernels: one hit, one ray -----------------------------------------------------------
@kernel
def part_frame(geo, k, time, m):
    """Object-to-world transform m (3, 4) of rigid part k at shutter fraction ``time``."""
    steps, translation, quat, stretch = geo[6], geo[7], geo[8], geo[9]
    a, count = steps[k, 0], steps[k, 1]
    frame_at(translation[a:a + count], quat[a:a + count], stretch[a:a + count], time, m)


@kernel
def _bucket(time):
    return min(int(time * DEFORM_BUCKETS), DEFORM_BUCKETS - 1)


@kernel
def hit_surface(geo, prim, u, v, time, scratch):
    """World position, geometric and shading normal of the hit (prim, u, v) at ``time``.

    Positions are rebuilt in float64 from the barycentrics; a rigid part's are carried to
    the world by its transform at the ray's time, its normals by the inverse transpose; a
    deforming part's come from the time bucket the ray was traced in. ``scratch`` is a
    (2, 3, 4) work array.
    """
    vertices, triangles, ng_all, ns_all, part, kind = geo[0], geo[1], geo[2], geo[3], geo[4], geo[5]
    w = 1.0 - u - v
    k = part[prim]
    i0, i1, i2 = triangles[prim, 0], triangles[prim, 1], triangles[prim, 2]
    if kind[k] == 2:
        b = _bucket(time)
        rows, src = geo[10][k], geo[11][b]
        ax, ay, az = src[i0 + rows, 0], src[i0 + rows, 1], src[i0 + rows, 2]
        bx, by, bz = src[i1 + rows, 0], src[i1 + rows, 1], src[i1 + rows, 2]
        cx, cy, cz = src[i2 + rows, 0], src[i2 + rows, 1], src[i2 + rows, 2]
    else:
        ax, ay, az = vertices[i0, 0], vertices[i0, 1], vertices[i0, 2]
        bx, by, bz = vertices[i1, 0], vertices[i1, 1], vertices[i1, 2]
        cx, cy, cz = vertices[i2, 0], vertices[i2, 1], vertices[i2, 2]
    gx, gy, gz = ng_all[prim, 0], ng_all[prim, 1], ng_all[prim, 2]
    if len(ns_all):
        c = ns_all[prim]
        sx, sy, sz = unit(w * c[0, 0] + u * c[1, 0] + v * c[2, 0], w * c[0, 1] + u * c[1, 1] + v * c[2, 1],
                           w * c[0, 2] + u * c[1, 2] + v * c[2, 2], 1e-300)
    else:
        sx, sy, sz = gx, gy, gz
    px = w * ax + u * bx + v * cx
    py = w * ay + u * by + v * cy
    pz = w * az + u * bz + v * cz
    if kind[k] == 1:
        m, inv = scratch[0], scratch[1]
        part_frame(geo, k, time, m)
        invert_frame(m, inv)
        px, py, pz = (m[0, 0] * px + m[0, 1] * py + m[0, 2] * pz + m[0, 3],
                      m[1, 0] * px + m[1, 1] * py + m[1, 2] * pz + m[1, 3],
                      m[2, 0] * px + m[2, 1] * py + m[2, 2] * pz + m[2, 3])
        gx, gy, gz = unit(inv[0, 0] * gx + inv[1, 0] * gy + inv[2, 0] * gz,
                           inv[0, 1] * gx + inv[1, 1] * gy + inv[2, 1] * gz,
                           inv[0, 2] * gx + inv[1, 2] * gy + inv[2, 2] * gz, 1e-300)
        sx, sy, sz = unit(inv[0, 0] * sx + inv[1, 0] * sy + inv[2, 0] * sz,
                           inv[0, 1] * sx + inv[1, 1] * sy + inv[2, 1] * sz,
                           inv[0, 2] * sx + inv[1, 2] * sy + inv[2, 2] * sz, 1e-300)
    elif kind[k] == 2:
        ex, ey, ez = bx - ax, by - ay, bz - az
        fx, fy, fz = cx - ax, cy - ay, cz - az
        gx, gy, gz = unit(ey * fz - ez * fy, ez * fx - ex * fz, ex * fy - ey * fx, 1e-300)
        if geo[12][k, _bucket(time)]:
            gx, gy, gz = -gx, -gy, -gz
    return px, py, pz, gx, gy, gz, sx, sy, sz


@kernel
def lift(geo, prim, u, v, time, scratch):
    """World vector from the hit to the smooth surface its corner normals describe.

    Hanika's shadow-terminator fix (Ray Tracing Gems II, ch. 4), as Cycles applies it:
    the hit is moved, for each corner, onto that corner's tangent plane where it lies
    below it, and the moves are blended by the barycentrics. Zero on flat triangles.
    """
    vertices, triangles, ns = geo[0], geo[1], geo[3]
    if len(ns) == 0:
        return 0.0, 0.0, 0.0
    bary = (1.0 - u - v, u, v)
    px = py = pz = 0.0
    for j in range(3):
        i = triangles[prim, j]
        px += bary[j] * vertices[i, 0]
        py += bary[j] * vertices[i, 1]
        pz += bary[j] * vertices[i, 2]
    ox = oy = oz = 0.0
    for j in range(3):
        i = triangles[prim, j]
        nx, ny, nz = ns[prim, j, 0], ns[prim, j, 1], ns[prim, j, 2]
        below = min((px - vertices[i, 0]) * nx + (py - vertices[i, 1]) * ny + (pz - vertices[i, 2]) * nz, 0.0)
        ox -= bary[j] * below * nx
        oy -= bary[j] * below * ny
        oz -= bary[j] * below * nz
    k = geo[4][prim]
    if geo[5][k] == 1:
        m = scratch[0]
        part_frame(geo, k, time, m)
        ox, oy, oz = (m[0, 0] * ox + m[0, 1] * oy + m[0, 2] * oz, m[1, 0] * ox + m[1, 1] * oy + m[1, 2] * oz,
                      m[2, 0] * ox + m[2, 1] * oy + m[2, 2] * oz)
    return ox, oy, oz


@kernel
def offset_scale(geo, prim, px, py, pz):
    """Distance that safely clears the surface of triangle ``prim`` at (px, py, pz): a bound
    on the float32 error of the hit, from the triangle's and the point's distance to the centre."""
    center, tri_scale = geo[13], geo[14]
    local = max(abs(px - center[0]), abs(py - center[1]), abs(pz - center[2]))
    return _EPS_REL * max(tri_scale[prim], local) + 1e-30


@kernel
def spawn_point(px, py, pz, gx, gy, gz, dx, dy, dz, scale):
    """Ray origin pushed off the surface (normal g) to the side direction d leaves through."""
    side = scale if gx * dx + gy * dy + gz * dz >= 0.0 else -scale
    return px + gx * side, py + gy * side, pz + gz * side


# -- kernels: batch loops ------------------------------------------------------------------
@kernel
def _time_of(times, r):
    return times[r] if len(times) else 0.5


@kernel
def _surfaces(geo, prim, u, v, times, index, out):
    scratch = np.empty((2, 3, 4))
    for i in range(len(index)):
        r = index[i]
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5], out[i, 6], out[i, 7], out[i, 8] = \
            hit_surface(geo, prim[r], u[r], v[r], _time_of(times, r), scratch)


@kernel
def _lifts(geo, prim, u, v, times, index, out):
    scratch = np.empty((2, 3, 4))
    for i in range(len(index)):
        r = index[i]
        out[i, 0], out[i, 1], out[i, 2] = lift(geo, prim[r], u[r], v[r], _time_of(times, r), scratch)


@kernel
def _offset_scales(geo, prim, pos, out):
    for i in range(len(prim)):
        out[i] = offset_scale(geo, prim[i], pos[i, 0], pos[i, 1], pos[i, 2])


@kernel
def _spawns(pos, ng, direction, scale, out):
    for i in range(len(pos)):
        out[i, 0], out[i, 1], out[i, 2] = spawn_point(pos[i, 0], pos[i, 1], pos[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                                                      direction[i, 0], direction[i, 1], direction[i, 2], scale[i])


@kernel
def _keep_closer(index, prim, t, u, v, base, best_t, best_prim, best_u, best_v, limit):
    """Merge one Embree answer for rays ``index`` into the closest hits so far."""
    for j in range(len(index)):
        r = index[j]
        if prim[j] >= 0 and t[j] < best_t[r]:
            best_t[r] = limit[r] = t[j]
            best_prim[r] = prim[j] + base
            best_u[r], best_v[r] = u[j], v[j]


@kernel
def _to_part(geo, k, origins, directions, times, index, center, o, d):
    """Rays ``index`` in part k's Embree frame (float32): object space at each ray's time for a
    rigid part (directions not renormalised: distances stay world distances), less the centre."""
    m = np.empty((3, 4))
    inv = np.empty((3, 4))
    rigid = geo[5][k] == 1
    for i in range(len(index)):
        r = index[i]
        x, y, z = origins[r, 0], origins[r, 1], origins[r, 2]
        dx, dy, dz = directions[r, 0], directions[r, 1], directions[r, 2]
        if rigid:
            part_frame(geo, k, times[r], m)
            invert_frame(m, inv)
            x, y, z = x - m[0, 3], y - m[1, 3], z - m[2, 3]
            x, y, z = (inv[0, 0] * x + inv[0, 1] * y + inv[0, 2] * z, inv[1, 0] * x + inv[1, 1] * y + inv[1, 2] * z,
                       inv[2, 0] * x + inv[2, 1] * y + inv[2, 2] * z)
            dx, dy, dz = (inv[0, 0] * dx + inv[0, 1] * dy + inv[0, 2] * dz,
                          inv[1, 0] * dx + inv[1, 1] * dy + inv[1, 2] * dz,
                          inv[2, 0] * dx + inv[2, 1] * dy + inv[2, 2] * dz)
        o[i, 0], o[i, 1], o[i, 2] = x - center[0], y - center[1], z - center[2]
        d[i, 0], d[i, 1], d[i, 2] = dx, dy, dz


def _normal_matrix(linear: np.ndarray) -> np.ndarray:
    """Inverse transpose: keeps normals perpendicular, and outward under mirroring."""
    try:
        return np.linalg.inv(linear).T
    except np.linalg.LinAlgError:
        return np.eye(3)


def _vertices_at(mesh, time: float) -> np.ndarray:
    """Object-space vertices of a deforming mesh at a shutter fraction (linear between steps)."""
    steps = mesh.motion_vertices
    x = np.clip(time, 0.0, 1.0) * (len(steps) - 1)
    i = min(int(x), len(steps) - 2)
    u = x - i
    return (1 - u) * steps[i] + u * steps[i + 1]


def _mid_mesh(mesh):
    """The mesh with its mid-shutter vertices (for normals, areas and light sampling)."""
    from dataclasses import replace

    return replace(mesh, vertices=_vertices_at(mesh, 0.5), motion_vertices=None)
