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
index the same arrays whatever part a hit came from.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import microfacet as mf
from .errors import SceneError
from .motion import Motion, inverse3
from .scene import SceneData

_EPS_REL = 2.0**-16  # ~64 float32 ulps: covers origin rounding plus Embree's own test error
_EPS_ABS = 2.0**-34  # with _EPS_REL: ~4 float64 ulps of the world coordinates hit points are rebuilt in
_CHUNK = 1 << 16  # rays per Embree call: bounds its output buffers
_FAR = np.float32(3.0e38)
DEFORM_BUCKETS = 8


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
    """Shutter times of a batch of rays with every rigidly moving part's transform at them.

    A path keeps its camera sample's time down the whole tree, so the transforms (slerp,
    matrix, inverse) are computed once per camera sample and gathered as paths go on.
    """

    values: np.ndarray | None
    frames: dict  # part index -> (linear (N, 3, 3), translation (N, 3), inverse of linear)

    def __getitem__(self, index) -> "RayTimes":
        values = None if self.values is None else self.values[index]
        return RayTimes(values, {k: tuple(a[index] for a in f) for k, f in self.frames.items()})


@dataclass
class _Part:
    kind: str  # "static" | "rigid" | "deform"
    base: int  # first global triangle id
    count: int
    center: np.ndarray
    scenes: list
    motion: Motion | None = None
    buckets: list | None = None  # deform: (world vertices of the part, mirrored) per time bucket
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

    # -- queries ---------------------------------------------------------------------
    @property
    def triangle_count(self) -> int:
        return len(self.triangles)

    @property
    def moving(self) -> bool:
        return any(p.kind != "static" for p in self.parts)

    def _run(self, scene, origins, directions, tmax, query):
        o = np.ascontiguousarray(origins, dtype=np.float32)
        d = np.ascontiguousarray(directions, dtype=np.float32)
        far = np.minimum(tmax, _FAR).astype(np.float32)
        output = 1 if query == "INTERSECT" else 0
        return [scene.run(o[a:a + _CHUNK], d[a:a + _CHUNK], far[a:a + _CHUNK], query=query, output=output)
                for a in range(0, max(len(o), 1), _CHUNK)]

    def ray_times(self, time) -> RayTimes:
        """Times (or None when nothing moves) with the transforms of the moving parts at them."""
        if isinstance(time, RayTimes):
            return time
        frames = {}
        for k, part in enumerate(self.parts):
            if part.kind == "rigid":
                linear, translation = part.motion.at(time)
                frames[k] = (linear, translation, inverse3(linear))
        return RayTimes(None if time is None else np.asarray(time), frames)

    def _rays_in(self, k: int, origins, directions, times: RayTimes, index):
        """(origins, directions) of rays ``index`` (ascending, no repeats) in part k's Embree frame."""
        part = self.parts[k]
        if len(index) == len(origins):  # then index is every ray, in order: no gathers
            index = slice(None)
        if part.kind == "rigid":
            _, translation, inv = (a[index] for a in times.frames[k])
            o = np.einsum("nij,nj->ni", inv, origins[index] - translation) - part.center
            d = np.einsum("nij,nj->ni", inv, directions[index])
            return o, d
        return origins[index] - part.center, directions[index]

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
                parts = self._run(scene, o, d, limit[idx], "INTERSECT")
                prim = np.concatenate([p["primID"] for p in parts]).astype(np.int64)
                t = np.concatenate([p["tfar"] for p in parts]).astype(np.float64)
                closer = (prim >= 0) & (t < best.t[idx])
                k = idx[closer]
                best.t[k] = t[closer]
                best.prim[k] = prim[closer] + part.base
                best.u[k] = np.concatenate([p["u"] for p in parts])[closer]
                best.v[k] = np.concatenate([p["v"] for p in parts])[closer]
                limit[k] = t[closer]
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
        prim = hits.prim[index]
        u, v = hits.u[index], hits.v[index]
        w = 1.0 - u - v
        bary = np.stack([w, u, v], axis=1)
        p = self.vertices[self.triangles[prim]]
        ng = self.ng[prim].copy()
        ns = self._interpolated_normals(prim, bary, ng)
        times = self.ray_times(time) if self.moving else None
        for k, part in enumerate(self.parts):
            if part.kind == "static":
                continue
            sel = np.flatnonzero(self.part[prim] == k)
            if len(sel) == 0:
                continue
            rays = index[sel]
            if part.kind == "rigid":  # this part's transforms only: gathering every part's is quadratic
                linear, translation, inv = (a[rays] for a in times.frames[k])
                normal_matrix = np.transpose(inv, (0, 2, 1))
                p[sel] = np.einsum("nij,nkj->nki", linear, p[sel]) + translation[:, None, :]
                ng[sel] = mf.normalize(np.einsum("nij,nj->ni", normal_matrix, ng[sel]), 1e-300)
                ns[sel] = mf.normalize(np.einsum("nij,nj->ni", normal_matrix, ns[sel]), 1e-300)
            else:
                bucket = np.minimum((times.values[rays] * DEFORM_BUCKETS).astype(np.int64), DEFORM_BUCKETS - 1)
                for b in np.unique(bucket):
                    world, mirrored = part.buckets[b]
                    s = sel[bucket == b]
                    p[s] = world[self.triangles[prim[s]] - part.first_vertex]
                    n_b, length = _cross_normals(p[s])
                    ng[s] = n_b / np.maximum(length, 1e-300)[:, None] * (-1.0 if mirrored else 1.0)
        pos = np.einsum("ni,nij->nj", bary, p)
        return pos, ng, ns

    def smooth_offset(self, hits: Hits, index: np.ndarray, time=None) -> np.ndarray:
        """World vector from hits[index] to the smooth surface its corner normals describe.

        Hanika's shadow-terminator fix (Ray Tracing Gems II, ch. 4), as Cycles applies it:
        the hit is moved, for each corner, onto that corner's tangent plane where it lies
        below it, and the moves are blended by the barycentrics. Zero on flat triangles.
        """
        out = np.zeros((len(index), 3))
        if self.ns is None or len(index) == 0:
            return out
        prim = hits.prim[index]
        bary = np.stack([1.0 - hits.u[index] - hits.v[index], hits.u[index], hits.v[index]], axis=1)
        corners = self.vertices[self.triangles[prim]]
        normals = self.ns[prim]
        p = np.einsum("ni,nij->nj", bary, corners)
        to_p = p[:, None, :] - corners
        below = np.minimum(np.einsum("nij,nij->ni", to_p, normals), 0.0)
        out = np.einsum("ni,nij->nj", bary, -below[:, :, None] * normals)
        times = self.ray_times(time) if self.moving else None
        for k, part in enumerate(self.parts):
            if part.kind != "rigid":
                continue
            sel = np.flatnonzero(self.part[prim] == k)
            if len(sel):
                linear = times.frames[k][0][index[sel]]
                out[sel] = np.einsum("nij,nj->ni", linear, out[sel])
        return out

    def _interpolated_normals(self, prim, bary, ng):
        if self.ns is None:
            return ng.copy()
        c = self.ns[prim]
        return mf.normalize(np.einsum("ni,nij->nj", bary, c), 1e-300)

    def offset_scale(self, prim: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Distance that safely clears the surface of triangle ``prim`` at ``pos``."""
        local = mf.max3(np.abs(pos - self.center))
        return _EPS_REL * np.maximum(self.tri_scale[prim], local) + 1e-30


def spawn(pos: np.ndarray, ng: np.ndarray, direction: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Ray origin pushed off the surface to the side ``direction`` leaves through."""
    side = np.where(np.einsum("ij,ij->i", ng, direction) >= 0.0, 1.0, -1.0)
    return pos + ng * (side * scale)[:, None]


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
