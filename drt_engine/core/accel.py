"""World-space triangles and batched ray queries through Embree.

Embree works in float32 with tnear fixed at 0, so precision is ours to manage:
geometry is kept in float64 and handed to Embree relative to a centre (the camera),
hit points are rebuilt in float64 from barycentrics, and new rays leave a surface
offset along the geometric normal by a bound on the float32 error of the hit.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .errors import SceneError
from .scene import SceneData

_EPS_REL = 2.0**-16  # ~64 float32 ulps: covers origin rounding plus Embree's own test error
_CHUNK = 1 << 15  # rays per Embree call per thread
_FAR = np.float32(3.0e38)


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


class Geometry:
    """All instanced triangles flattened to world space, with Embree on top.

    Per triangle: vertex indices into ``vertices`` (float64, world), geometric normal
    ``ng`` (oriented by winding, flipped under mirroring transforms so it agrees with
    the shading normals), shading normals per corner ``ns`` and ``material``.
    """

    def __init__(self, scene: SceneData, center: np.ndarray, pool: ThreadPoolExecutor | None = None):
        self.center = np.asarray(center, dtype=np.float64)
        self.pool = pool
        self.warnings: list[str] = []
        vertices, triangles, normals, materials, flips = [], [], [], [], []
        offset = 0
        dropped = 0
        for inst in scene.instances:
            mesh = scene.meshes[inst.mesh]
            if len(mesh.triangles) == 0:
                continue
            m = inst.matrix
            linear = m[:3, :3]
            v = mesh.vertices @ linear.T + m[:3, 3]
            tri = mesh.triangles
            bad_vertex = ~np.isfinite(v).all(axis=1)
            keep = ~bad_vertex[tri].any(axis=1)
            dropped += int((~keep).sum())
            if mesh.corner_normals is not None:
                normal_matrix = _normal_matrix(linear)
                ns = mesh.corner_normals.astype(np.float64) @ normal_matrix.T
            else:
                ns = None
            v = np.where(bad_vertex[:, None], 0.0, v)
            vertices.append(v)
            triangles.append(tri[keep] + offset)
            normals.append(ns[keep] if ns is not None else None)
            materials.append(mesh.material_indices[keep])
            flips.append(np.full(int(keep.sum()), np.linalg.det(linear) < 0))
            offset += len(v)
        if dropped:
            self.warnings.append(f"{dropped} triangles with NaN or infinite vertex coordinates were left out")
        self.vertices = np.concatenate(vertices) if vertices else np.zeros((0, 3))
        tri = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int32)
        flip = np.concatenate(flips) if flips else np.zeros(0, bool)
        material = np.concatenate(materials) if materials else np.zeros(0, np.int32)
        p = self.vertices[tri]
        ng = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        length = np.linalg.norm(ng, axis=1)
        # Zero-area triangles can never be seen and only cause trouble: leave them out.
        keep = length > 0
        self.triangles = tri[keep]
        self.material = material[keep]
        self.ng = ng[keep] / length[keep, None] * np.where(flip[keep], -1.0, 1.0)[:, None]
        if any(n is not None for n in normals):
            ns = np.full((len(tri), 3, 3), np.nan)
            start = 0
            for n, t in zip(normals, triangles):
                if n is not None:
                    ns[start:start + len(t)] = n
                start += len(t)
            ns = ns[keep]
            ns_len = np.linalg.norm(ns, axis=2, keepdims=True)
            good = (ns_len > 1e-12) & np.isfinite(ns_len)
            flat = np.repeat(self.ng[:, None, :], 3, axis=1)
            self.ns = np.where(good, ns / np.where(good, ns_len, 1.0), flat)
        else:
            self.ns = None
        rel = self.vertices[self.triangles] - self.center
        self.tri_scale = np.abs(rel).max(axis=(1, 2)) if len(rel) else np.zeros(0)
        self.area = 0.5 * length[keep]
        self._embree = None
        if len(self.triangles):
            self._build_embree()

    def _build_embree(self):
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        rel = (self.vertices - self.center).astype(np.float32)
        if not np.isfinite(rel).all():
            raise SceneError("geometry too far from the camera to be represented in single precision")
        self._embree = rtcore_scene.EmbreeScene()
        TriangleMesh(self._embree, np.ascontiguousarray(rel), np.ascontiguousarray(self.triangles, dtype=np.int32))

    @property
    def triangle_count(self) -> int:
        return len(self.triangles)

    def _run(self, origins, directions, tmax, query):
        o = np.ascontiguousarray(origins - self.center, dtype=np.float32)
        d = np.ascontiguousarray(directions, dtype=np.float32)
        far = np.minimum(tmax, _FAR).astype(np.float32)
        n = len(o)
        output = 1 if query == "INTERSECT" else 0
        if self.pool is None or n <= _CHUNK:
            return [self._embree.run(o, d, dists=far, query=query, output=output)]
        bounds = range(0, n, _CHUNK)
        jobs = [self.pool.submit(self._embree.run, o[a:a + _CHUNK], d[a:a + _CHUNK],
                                 far[a:a + _CHUNK], query, output) for a in bounds]
        return [j.result() for j in jobs]

    def intersect(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray) -> Hits:
        n = len(origins)
        if self._embree is None or n == 0:
            return Hits(np.full(n, np.inf), np.full(n, -1, np.int64), np.zeros(n), np.zeros(n))
        parts = self._run(origins, directions, tmax, "INTERSECT")
        prim = np.concatenate([p["primID"] for p in parts]).astype(np.int64)
        t = np.concatenate([p["tfar"] for p in parts]).astype(np.float64)
        u = np.concatenate([p["u"] for p in parts]).astype(np.float64)
        v = np.concatenate([p["v"] for p in parts]).astype(np.float64)
        t[prim < 0] = np.inf
        return Hits(t, prim, u, v)

    def occluded(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        n = len(origins)
        if self._embree is None or n == 0:
            return np.zeros(n, dtype=bool)
        parts = self._run(origins, directions, tmax, "OCCLUDED")
        return np.concatenate(parts) >= 0

    def surface(self, hits: Hits, index: np.ndarray):
        """Float64 position, geometric and shading normal of hits[index]."""
        prim = hits.prim[index]
        u, v = hits.u[index], hits.v[index]
        w = 1.0 - u - v
        p = self.vertices[self.triangles[prim]]
        pos = w[:, None] * p[:, 0] + u[:, None] * p[:, 1] + v[:, None] * p[:, 2]
        ng = self.ng[prim]
        if self.ns is None:
            ns = ng.copy()
        else:
            c = self.ns[prim]
            ns = w[:, None] * c[:, 0] + u[:, None] * c[:, 1] + v[:, None] * c[:, 2]
            ns /= np.maximum(np.linalg.norm(ns, axis=1, keepdims=True), 1e-30)
        return pos, ng, ns

    def offset_scale(self, prim: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Distance that safely clears the surface of triangle ``prim`` at ``pos``."""
        local = np.abs(pos - self.center).max(axis=1)
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
