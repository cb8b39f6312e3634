"""Triangles in Embree scenes, and ray queries at each ray's own time.

Each distinct mesh is one Embree scene (one BVH however many objects show it) and every object
an instance of it in one top-level scene (geometry/embree.py), so Embree does what DRT did by
hand before: it carries rays into an object's space, interpolates a moving object's transform
steps (rotation by slerp, the rest linearly, as geometry/motion.py) and a deforming mesh's
vertex steps at each ray's own time. Float32 precision stays ours to manage:

- instance transforms go to Embree relative to a centre (the camera), and a mesh's vertices
  relative to a pivot of its own (its box's point nearest the camera when the camera is close
  to it, else its middle; see ``_pivot``), so Embree's float32 numbers are small where the
  image needs them, however far from the origin the scene lies;
- each hit is refined in float64 (the float64 ray on the mesh's float64 triangle, carried by
  the instance's float64 transform at the ray's time, in the decomposition Embree
  interpolates), and hit points are rebuilt from those barycentrics;
- new rays leave a surface offset along the geometric normal by a bound on the float32 error
  of the hit.

Triangles keep one global numbering (an instance's first id plus Embree's primID), which
materials, lights and attributes resolve through the instance to its mesh's tables. The
per-ray work (queries, hit reconstruction, the terminator lift, offsets) is in scalar kernels
over ``Geometry.tables``, flat arrays a fused stage kernel can read too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..base.jit import kernel
from ..base.vectors import unit
from ..errors import SceneError
from ..scene import LIGHT_SETS_ALL, Mesh, SceneData
from . import embree
from .motion import deforms, frame_at, invert_frame, moves
from .visibility import EVERY, SHADOW, instance_mask, shadow_ray_mask

_EPS_REL = 2.0**-16  # ~64 float32 ulps: covers origin rounding plus Embree's own test error
_EPS_ABS = 2.0**-34  # with _EPS_REL: ~4 float64 ulps of the world coordinates hit points are rebuilt in
_FAR = np.float32(3.0e38)
_EVERY_RAY = np.zeros(0, np.int32)  # no ray masks: every ray sees every object


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

    A path keeps its camera sample's time down its whole tree; Embree and the hit kernels
    place moving objects at it."""

    values: np.ndarray | None

    def __getitem__(self, index) -> "RayTimes":
        return RayTimes(None if self.values is None else self.values[index])


@dataclass(frozen=True)
class _MeshScene:
    """One mesh as Embree holds it, shared by all its instances, and by the geometry of an
    edited scene while the mesh object and its pivot stay the same."""

    mesh: Mesh
    kept: np.ndarray  # indices of the mesh's triangles Embree holds (finite, not degenerate)
    bad: int  # triangles left out for non-finite vertices
    steps: np.ndarray  # (S, V, 3) float64 object-space vertices, S > 1 for a deforming mesh
    mid: np.ndarray  # (V, 3) the vertices at mid-shutter, non-finite ones zeroed
    ng: np.ndarray  # (T, 3) object-space unit normals of the kept triangles (mid-shutter)
    bounds: np.ndarray  # (2, 3) object-space box of the kept triangles over the shutter
    pivot: np.ndarray | None = None  # the object-space point Embree's vertices are relative to
    scene: embree.TriangleScene | None = None


def _cross_normals(p: np.ndarray):
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = np.linalg.norm(n, axis=1)
    return n, length


def _analyse(mesh: Mesh) -> _MeshScene:
    """The triangles of a mesh Embree can hold (finite, with an area) and their object-space data."""
    steps = mesh.motion_vertices if deforms(mesh) else mesh.vertices[None]
    mid = _vertices_at(mesh, 0.5) if len(steps) > 1 else mesh.vertices
    finite = np.isfinite(steps).all(axis=(0, 2))
    tri = mesh.triangles
    bad = ~finite[tri].all(axis=1)
    mid = np.where(finite[:, None], mid, 0.0)
    n, length = _cross_normals(mid[tri])
    kept = np.flatnonzero(~bad & (length > 0))
    used = np.zeros(len(mid), bool)
    used[tri[kept].ravel()] = True
    steps = np.where(finite[None, :, None], steps, 0.0)
    bounds = np.array([steps[:, used].min(axis=(0, 1)), steps[:, used].max(axis=(0, 1))]) if len(kept) \
        else np.zeros((2, 3))
    return _MeshScene(mesh, kept, int(bad.sum()), steps, mid, n[kept] / length[kept][:, None], bounds)


def _pivot(ms: _MeshScene, frames: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Where a mesh's vertices go to Embree from: float32 is most precise there.

    The middle of its box, unless the camera (the centre, seen from the nearest of its instances
    at mid-shutter) is within the box grown by its size on every side: then the box's point
    nearest the camera, so that geometry near the camera keeps the precision the camera-centred
    world had (a floor under the camera, a room around it). Elsewhere the vertices' rounding
    is below the offsets' bound on it, which grows with the distance to the camera."""
    lo, hi = ms.bounds
    size = (hi - lo).max()
    seen = (np.linalg.pinv(frames[:, :, :3]) @ (center - frames[:, :, 3])[:, :, None])[:, :, 0]
    away = np.linalg.norm(np.maximum(np.maximum(lo - seen, seen - hi), 0.0), axis=1)
    away = np.where(np.isfinite(away), away, np.inf)
    nearest = seen[int(np.argmin(away))]
    if np.all(nearest >= lo - size) and np.all(nearest <= hi + size):
        return np.clip(nearest, lo, hi)
    return 0.5 * (lo + hi)


def _build(ms: _MeshScene, pivot: np.ndarray) -> _MeshScene:
    local = (ms.steps - pivot).astype(np.float32)
    if not np.isfinite(local).all():
        raise SceneError(f"mesh {ms.mesh.name!r} too large to be represented in single precision")
    return replace(ms, pivot=pivot, scene=embree.TriangleScene(local, ms.mesh.triangles[ms.kept]))


class Geometry:
    """All instanced triangles and the Embree scenes that answer ray queries.

    Per mesh (``tables``): object-space vertices (every time step), triangles, normals, and the
    triangles' materials and mid-shutter vertices. Per instance: its mesh, its first global
    triangle id, its transform (or steps). A global id's material, source, world corners and
    normal are resolved through its instance (``material_of``, ``source_of``, ``world_corners``,
    ``world_normals``): memory grows with the instances' count, not their triangles.

    ``previous``: a Geometry of an earlier version of the scene (a viewport edit): meshes it
    holds as the same objects keep their Embree scenes (unless the camera's nearness moves a
    mesh's pivot); the top level is built again.
    """

    def __init__(self, scene: SceneData, center: np.ndarray, previous: "Geometry | None" = None):
        self.center = np.ascontiguousarray(center, dtype=np.float64)  # one layout: one compiled kernel
        self.warnings: list[str] = []
        known = previous._meshes if previous is not None else {}
        analysed: dict[int, _MeshScene] = {}  # by mesh index in the scene
        dropped = 0
        kept = []  # (instance index, mesh index, matrices)
        for k, inst in enumerate(scene.instances):
            mesh = scene.meshes[inst.mesh]
            if len(mesh.triangles) == 0:
                continue
            if inst.mesh not in analysed:
                ms = known.get(id(mesh))
                analysed[inst.mesh] = ms if ms is not None and ms.mesh is mesh else _analyse(mesh)
            ms = analysed[inst.mesh]
            if not np.isfinite(inst.matrices).all():
                dropped += len(mesh.triangles)
                continue
            dropped += ms.bad
            flat = (np.linalg.det(inst.matrices[:, :3, :3]) == 0).all()  # scaled to nothing: no area to hit
            if len(ms.kept) and not flat:
                kept.append((k, inst.mesh, inst.matrices))
        if dropped:
            self.warnings.append(f"{dropped} triangles with NaN or infinite vertex coordinates were left out")
        self._motion_steps(kept)
        self._mesh_scenes(kept, analysed, known)
        self.shadow_linking = any(i.blocker_shadow_set for i in scene.instances) or any(
            e.shadow_set_membership != LIGHT_SETS_ALL for e in (*scene.instances, *scene.lights))
        """Some emitter's shadows are cast by some objects alone (shadow linking): every object's
        mask then holds the shadow bit of its blocker set (core.geometry.visibility)."""
        masks = [instance_mask(scene.instances[k], self.shadow_linking) for k, _, _ in kept]
        self.masked = any(mask != EVERY for mask in masks)
        """Some object is hidden from some ray kind: rays then carry their kind's mask."""
        self.shadow_mask = (shadow_ray_mask(LIGHT_SETS_ALL) if self.shadow_linking else SHADOW) if self.masked \
            else EVERY
        """The Embree mask of shadow rays (of emitters whose shadows every object casts)."""
        self._instances(kept, masks)
        self._triangle_tables(kept)
        self.tables = self._tables()

    # -- construction helpers ------------------------------------------------------
    def _motion_steps(self, kept):
        """Per instance: its transform at mid-shutter and, for a moving one, the rows of its steps
        in the motion tables (translation, quaternion, upper-triangular factor: Embree's split)."""
        n = len(kept)
        self._frames = np.zeros((n, 3, 4))
        self._steps = np.zeros((n, 2), np.int64)  # first row and count in the motion tables (0: still)
        motion, rows = [[np.zeros((0, 3))], [np.zeros((0, 4))], [np.zeros((0, 3, 3))]], 0
        for j, (_, _, matrices) in enumerate(kept):
            if moves(matrices):
                quat, upper = embree.quaternion_decomposition(matrices[:, :3])
                translation = np.ascontiguousarray(matrices[:, :3, 3])  # frame_at's one compiled layout
                for table, step in zip(motion, (translation, quat, upper)):
                    table.append(step)
                self._steps[j] = rows, len(matrices)
                rows += len(matrices)
                frame_at(translation, quat, upper, 0.5, self._frames[j])
            else:
                self._frames[j] = matrices[0, :3]
        self._motion = [np.concatenate(table) for table in motion]

    def _mesh_scenes(self, kept, analysed, known):
        """An Embree scene per mesh the kept instances show (a previous geometry's when the mesh
        and its pivot are the same), in the order of first use: the rows of the mesh tables."""
        self._meshes: dict[int, _MeshScene] = {}  # by id(mesh), for the next update
        self._mesh_list: list[_MeshScene] = []
        self._inst_mesh = np.zeros(len(kept), np.int64)
        order: dict[int, int] = {}
        for j, (_, index, _) in enumerate(kept):
            order.setdefault(index, len(order))
            self._inst_mesh[j] = order[index]
        for index, row in order.items():
            ms = analysed[index]
            pivot = _pivot(ms, self._frames[self._inst_mesh == row], self.center)
            ms = known.get(id(ms.mesh), ms)
            if ms.mesh is not analysed[index].mesh or ms.scene is None or not np.array_equal(ms.pivot, pivot):
                ms = _build(analysed[index], pivot)
            self._meshes[id(ms.mesh)] = ms
            self._mesh_list.append(ms)
        self._moving = any(len(ms.steps) > 1 for ms in self._mesh_list) or bool(self._steps[:, 1].any())

    def _instances(self, kept, masks):
        """The top-level Embree scene: each instance with the centre taken off its transforms and
        its ray visibility as its mask."""
        n = len(kept)
        self._top = embree.InstanceScene() if n else None
        self._base = np.zeros(n + 1, np.int64)
        self._inverses = np.zeros((n, 3, 4))
        for j, (_, _, matrices) in enumerate(kept):
            ms = self._mesh_list[self._inst_mesh[j]]
            self._base[j + 1] = self._base[j] + len(ms.kept)
            placed = matrices.copy()
            placed[:, :3, 3] -= self.center  # Embree works relative to the centre
            self._top.add(ms.scene, placed if self._steps[j, 1] else placed[0], ms.pivot, masks[j])
            invert_frame(self._frames[j], self._inverses[j])
        if self._top is not None:
            self._top.commit()

    def _triangle_tables(self, kept):
        """Per mesh row, what materials, lights and attributes ask of a triangle (its material, its
        index in the mesh, its mid-shutter vertices); per instance its index in the scene and
        whether it mirrors. Nothing here grows with the instances' triangles: a global id is
        resolved through its instance (``locate``)."""
        rows = self._mesh_list
        self._tri_first = np.cumsum([0] + [len(ms.kept) for ms in rows], dtype=np.int64)
        self._mid_first = np.cumsum([0] + [len(ms.mid) for ms in rows], dtype=np.int64)
        self._tri_material = (np.concatenate([ms.mesh.material_indices[ms.kept] for ms in rows]) if rows
                              else np.zeros(0, np.int32))
        self._tri_source = np.concatenate([ms.kept for ms in rows]) if rows else np.zeros(0, np.int64)
        self._mid = np.concatenate([ms.mid for ms in rows]) if rows else np.zeros((0, 3))
        self._scene_index = np.array([k for k, _, _ in kept], np.int64)
        self._flip = np.linalg.det(self._frames[:, :, :3]) < 0

    def _tables(self):
        """Everything the hit kernels read, as one tuple of flat arrays (see ``hit_surface``).

        Per mesh row: first vertex row, time steps, vertex count, first triangle row, first row of
        its mid-shutter vertices. Per instance: mesh row, first global id (and the total after the
        last), still frame (mid-shutter for a moving one) and inverse, rows of its motion steps."""
        verts, tris, ng, ns, info = [], [], [], [], np.zeros((max(len(self._mesh_list), 1), 5), np.int64)
        rows = 0
        smooth = any(ms.mesh.corner_normals is not None for ms in self._mesh_list)
        for r, ms in enumerate(self._mesh_list):
            s, v = ms.steps.shape[:2]
            info[r] = rows, s, v, self._tri_first[r], self._mid_first[r]
            verts.append(ms.steps.reshape(-1, 3))
            tris.append(ms.mesh.triangles[ms.kept])
            ng.append(ms.ng)
            rows += s * v
            if smooth:
                ns.append(_corner_normals(ms))
        return (np.concatenate(verts) if verts else np.zeros((0, 3)),
                np.concatenate(tris) if tris else np.zeros((0, 3), np.int32),
                np.concatenate(ng) if ng else np.zeros((0, 3)),
                np.concatenate(ns) if ns else np.zeros((0, 3, 3)),
                info, self._inst_mesh, self._base, self._frames, self._inverses, self._steps,
                self._motion[0], self._motion[1], self._motion[2], self.center, self._mid)

    # -- triangles by global id --------------------------------------------------------
    def locate(self, prim: np.ndarray):
        """(instance row, row in the mesh triangle tables) of global triangles ``prim``."""
        j = np.searchsorted(self._base, prim, side="right") - 1
        return j, self._tri_first[self._inst_mesh[j]] + prim - self._base[j]

    def material_of(self, prim: np.ndarray) -> np.ndarray:
        return self._tri_material[self.locate(prim)[1]]

    def of_triangles(self, per_material: np.ndarray) -> np.ndarray:
        """A value per material as one per row of the mesh triangle tables (what kernels index)."""
        return np.ascontiguousarray(per_material[self._tri_material])

    def materials_used(self) -> np.ndarray:
        """The materials of the triangles rays can hit, each once."""
        return np.unique(self._tri_material)

    def source_of(self, prim: np.ndarray) -> np.ndarray:
        """(N, 2): per triangle its instance's index in the scene and its index in the mesh."""
        j, row = self.locate(prim)
        return np.stack([self._scene_index[j], self._tri_source[row]], axis=1)

    def world_corners(self, prim: np.ndarray) -> np.ndarray:
        """(N, 3, 3) float64 world corners of triangles ``prim`` at mid-shutter."""
        j, row = self.locate(prim)
        p = self._mid[self.tables[1][row] + self._mid_first[self._inst_mesh[j]][:, None]]
        f = self._frames[j]
        return np.einsum("nkj,nij->nki", p, f[:, :, :3]) + f[:, None, :, 3]

    def world_normals(self, prim: np.ndarray, corners: np.ndarray | None = None):
        """(unit world normals outward under mirroring too, areas) of triangles ``prim`` at
        mid-shutter (from their ``corners`` when the caller has them)."""
        p = self.world_corners(prim) if corners is None else corners
        n, length = _cross_normals(p)
        side = np.where(self._flip[self.locate(prim)[0]], -1.0, 1.0)
        return n / np.maximum(length, 1e-300)[:, None] * side[:, None], 0.5 * length

    def triangles_with(self, materials) -> np.ndarray:
        """Global ids, ascending, of every triangle whose material is one of ``materials``."""
        sel = np.isin(self._tri_material, np.asarray(materials, np.int64))
        local = [np.flatnonzero(sel[a:b]) for a, b in zip(self._tri_first[:-1], self._tri_first[1:])]
        shown = np.flatnonzero([len(local[r]) > 0 for r in self._inst_mesh]) if len(self._inst_mesh) else []
        parts = [self._base[j] + local[self._inst_mesh[j]] for j in shown]
        return np.concatenate(parts) if parts else np.zeros(0, np.int64)

    # -- queries ---------------------------------------------------------------------
    @property
    def triangle_count(self) -> int:
        return int(self._base[-1])

    @property
    def moving(self) -> bool:
        return self._moving

    @property
    def instance_scene(self) -> "embree.InstanceScene | None":
        """The top-level Embree scene (None when there is nothing to hit)."""
        return self._top

    @property
    def handle(self) -> int:
        """The top-level Embree scene's handle for kernels (``blocked``); 0 when there is nothing to hit."""
        return 0 if self._top is None else self._top.handle

    @property
    def local_scenes(self) -> tuple[np.ndarray, np.ndarray]:
        """Per mesh row, its own Embree scene's handle and the object-space pivot its vertices are
        relative to: rays against one object alone (the Ambient Occlusion node's Only Local, the Bevel
        node; ``object_ray`` carries a world ray there)."""
        handles = np.array([ms.scene.handle for ms in self._mesh_list], np.int64)
        pivots = np.array([ms.pivot for ms in self._mesh_list], np.float64).reshape(-1, 3)
        return handles, pivots

    def ray_times(self, time) -> RayTimes:
        """The times as a RayTimes (None when nothing moves)."""
        if isinstance(time, RayTimes):
            return time
        return RayTimes(None if time is None else np.asarray(time, dtype=np.float64))

    def intersect(self, origins, directions, tmax, time=None, masks=None) -> Hits:
        """Closest hits; ``masks``: each ray's Embree mask (geometry.visibility; None: every object)."""
        n = len(origins)
        hits = Hits(np.full(n, np.inf), np.full(n, -1, np.int64), np.zeros(n), np.zeros(n))
        if self._top is not None and n:
            _intersects(self._top.handle, self.tables, np.asarray(origins, np.float64),
                        np.asarray(directions, np.float64), np.asarray(tmax, np.float64), self.time_values(time),
                        _EVERY_RAY if masks is None else masks, hits.t, hits.prim, hits.u, hits.v)
        return hits

    def occluded(self, origins, directions, tmax, time=None) -> np.ndarray:
        n = len(origins)
        blocked = np.zeros(n, dtype=bool)
        if self._top is not None and n:
            _occludeds(self._top.handle, np.asarray(origins, np.float64), np.asarray(directions, np.float64),
                       np.asarray(tmax, np.float64), self.time_values(time), self.center, self.shadow_mask, blocked)
        return blocked

    def surface(self, hits: Hits, index: np.ndarray, time=None):
        """Float64 world position, geometric and shading normal of hits[index]."""
        n = len(index)
        out = np.empty((n, 9))
        _surfaces(self.tables, hits.prim, hits.u, hits.v, self.time_values(time), np.asarray(index), out)
        return out[:, 0:3], out[:, 3:6], out[:, 6:9]

    def smooth_offset(self, hits: Hits, index: np.ndarray, time=None) -> np.ndarray:
        """World vector from hits[index] to the smooth surface its corner normals describe (see
        ``lift``); zero on flat triangles."""
        out = np.zeros((len(index), 3))
        if len(self.tables[3]) == 0 or len(index) == 0:
            return out
        _lifts(self.tables, hits.prim, hits.u, hits.v, self.time_values(time), np.asarray(index), out)
        return out

    def time_values(self, time) -> np.ndarray:
        """Each ray's shutter time for the kernels; empty when nothing moves (they then use 0.5)."""
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


def _corner_normals(ms: _MeshScene) -> np.ndarray:
    """Unit object-space corner normals of a mesh's kept triangles (the triangle's normal where
    the mesh has none or one is unusable)."""
    flat = np.repeat(ms.ng[:, None, :], 3, axis=1)
    if ms.mesh.corner_normals is None:
        return flat
    n = ms.mesh.corner_normals[ms.kept].astype(np.float64)
    length = np.linalg.norm(n, axis=2, keepdims=True)
    good = (length > 1e-12) & np.isfinite(length)
    return np.where(good, n / np.where(good, length, 1.0), flat)


# -- kernels: one hit, one ray -----------------------------------------------------------
@kernel(inline="always")  # a call would pass (and count references to) all of geo
def instance_of(geo, prim):
    """The instance (its row in the instance tables) whose triangles include global id ``prim``."""
    return np.searchsorted(geo[6], prim, side="right") - 1


@kernel(inline="always")  # a call would pass (and count references to) all of geo
def instance_frame(geo, i, time, frame):
    """Object-to-world transform of instance i at shutter fraction ``time`` into frame[0] (3, 4), its
    inverse into frame[1]. Copied element by element: array views cost more than the copy."""
    count = geo[9][i, 1]
    if count == 0:
        still, inverse = geo[7], geo[8]
        for r in range(3):
            for c in range(4):
                frame[0, r, c] = still[i, r, c]
                frame[1, r, c] = inverse[i, r, c]
    else:
        _moving_frame(geo[10], geo[11], geo[12], geo[9][i, 0], count, time, frame)


@kernel(inline="always")
def object_ray(frame, pivots, row, ox, oy, oz, dx, dy, dz):
    """A world ray carried into the object whose world-to-object transform is ``frame[1]``, in its
    mesh's own Embree scene (vertices relative to ``pivots[row]``, see ``Geometry.local_scenes``):
    origin and direction there, distances along it the same as in the world."""
    m = frame[1]
    px = m[0, 0] * ox + m[0, 1] * oy + m[0, 2] * oz + m[0, 3] - pivots[row, 0]
    py = m[1, 0] * ox + m[1, 1] * oy + m[1, 2] * oz + m[1, 3] - pivots[row, 1]
    pz = m[2, 0] * ox + m[2, 1] * oy + m[2, 2] * oz + m[2, 3] - pivots[row, 2]
    ex = m[0, 0] * dx + m[0, 1] * dy + m[0, 2] * dz
    ey = m[1, 0] * dx + m[1, 1] * dy + m[1, 2] * dz
    ez = m[2, 0] * dx + m[2, 1] * dy + m[2, 2] * dz
    return px, py, pz, ex, ey, ez


@kernel
def _moving_frame(translation, quat, upper, first, count, time, frame):
    """instance_frame of a moving instance (apart: its slices cost every caller ~40 ns a hit when inlined)."""
    frame_at(translation[first:first + count], quat[first:first + count], upper[first:first + count], time, frame[0])
    invert_frame(frame[0], frame[1])


@kernel(inline="always")  # a call would pass (and count references to) all of geo
def _corners(geo, i, prim, time):
    """Object-space corners (9 coordinates) of global triangle ``prim`` of instance i at ``time``
    (a deforming mesh's vertices interpolated linearly between its steps, as Embree does), its
    row in the mesh tables, and whether it deforms."""
    vertices, triangles, info = geo[0], geo[1], geo[4]
    r = geo[5][i]
    first, steps, count = info[r, 0], info[r, 1], info[r, 2]
    row = info[r, 3] + prim - geo[6][i]
    i0, i1, i2 = triangles[row, 0], triangles[row, 1], triangles[row, 2]
    if steps == 1:
        return (vertices[first + i0, 0], vertices[first + i0, 1], vertices[first + i0, 2],
                vertices[first + i1, 0], vertices[first + i1, 1], vertices[first + i1, 2],
                vertices[first + i2, 0], vertices[first + i2, 1], vertices[first + i2, 2]), row, False
    x = min(max(time, 0.0), 1.0) * (steps - 1)
    s = min(int(x), steps - 2)
    f = x - s
    a = first + s * count
    b = a + count
    return ((1 - f) * vertices[a + i0, 0] + f * vertices[b + i0, 0], (1 - f) * vertices[a + i0, 1] + f * vertices[b + i0, 1],
            (1 - f) * vertices[a + i0, 2] + f * vertices[b + i0, 2], (1 - f) * vertices[a + i1, 0] + f * vertices[b + i1, 0],
            (1 - f) * vertices[a + i1, 1] + f * vertices[b + i1, 1], (1 - f) * vertices[a + i1, 2] + f * vertices[b + i1, 2],
            (1 - f) * vertices[a + i2, 0] + f * vertices[b + i2, 0], (1 - f) * vertices[a + i2, 1] + f * vertices[b + i2, 1],
            (1 - f) * vertices[a + i2, 2] + f * vertices[b + i2, 2]), row, True


@kernel
def _to_world_normal(f, x, y, z):
    """A normal carried to the world by the inverse transpose of frame f (outward under mirroring
    too), unit."""
    return unit(f[1, 0, 0] * x + f[1, 1, 0] * y + f[1, 2, 0] * z, f[1, 0, 1] * x + f[1, 1, 1] * y + f[1, 2, 1] * z,
                f[1, 0, 2] * x + f[1, 1, 2] * y + f[1, 2, 2] * z, 1e-300)


@kernel
def _to_world_point(f, x, y, z):
    """A point carried to the world by frame f."""
    return (f[0, 0, 0] * x + f[0, 0, 1] * y + f[0, 0, 2] * z + f[0, 0, 3],
            f[0, 1, 0] * x + f[0, 1, 1] * y + f[0, 1, 2] * z + f[0, 1, 3],
            f[0, 2, 0] * x + f[0, 2, 1] * y + f[0, 2, 2] * z + f[0, 2, 3])


@kernel(inline="always")  # see instance_of
def hit_surface(geo, prim, u, v, time, scratch):
    """World position, geometric and shading normal of the hit (prim, u, v) at ``time``.

    Positions are rebuilt in float64 from the barycentrics on the mesh's object-space
    triangle (at the ray's time if it deforms), carried to the world by the instance's
    transform at that time; normals by the inverse transpose, the corner normals each before
    they are blended. ``scratch`` is a (2, 3, 4) work array.
    """
    ng_all, ns_all = geo[2], geo[3]
    i = instance_of(geo, prim)
    instance_frame(geo, i, time, scratch)
    c, row, deforming = _corners(geo, i, prim, time)
    w = 1.0 - u - v
    px, py, pz = _to_world_point(scratch, w * c[0] + u * c[3] + v * c[6], w * c[1] + u * c[4] + v * c[7],
                                 w * c[2] + u * c[5] + v * c[8])
    if deforming:
        ex, ey, ez = c[3] - c[0], c[4] - c[1], c[5] - c[2]
        fx, fy, fz = c[6] - c[0], c[7] - c[1], c[8] - c[2]
        gx, gy, gz = _to_world_normal(scratch, ey * fz - ez * fy, ez * fx - ex * fz, ex * fy - ey * fx)
    else:
        gx, gy, gz = _to_world_normal(scratch, ng_all[row, 0], ng_all[row, 1], ng_all[row, 2])
    if len(ns_all):
        sx = sy = sz = 0.0
        bary = (w, u, v)
        for j in range(3):
            nx, ny, nz = _to_world_normal(scratch, ns_all[row, j, 0], ns_all[row, j, 1], ns_all[row, j, 2])
            sx += bary[j] * nx
            sy += bary[j] * ny
            sz += bary[j] * nz
        sx, sy, sz = unit(sx, sy, sz, 1e-300)
    else:
        sx, sy, sz = gx, gy, gz
    return px, py, pz, gx, gy, gz, sx, sy, sz


@kernel(inline="always")  # see instance_of
def lift(geo, prim, u, v, time, scratch):
    """World vector from the hit to the smooth surface its corner normals describe.

    Hanika's shadow-terminator fix (Ray Tracing Gems II, ch. 4), as Cycles applies it:
    the hit is moved, for each corner, onto that corner's tangent plane where it lies
    below it, and the moves are blended by the barycentrics. Zero on flat triangles.
    Worked in world space (corners and their normals carried there first).
    """
    ns = geo[3]
    if len(ns) == 0:
        return 0.0, 0.0, 0.0
    i = instance_of(geo, prim)
    instance_frame(geo, i, time, scratch)
    c, row, _ = _corners(geo, i, prim, time)
    bary = (1.0 - u - v, u, v)
    ax, ay, az = _to_world_point(scratch, c[0], c[1], c[2])
    bx, by, bz = _to_world_point(scratch, c[3], c[4], c[5])
    cx, cy, cz = _to_world_point(scratch, c[6], c[7], c[8])
    world = (ax, ay, az, bx, by, bz, cx, cy, cz)
    px = bary[0] * ax + bary[1] * bx + bary[2] * cx
    py = bary[0] * ay + bary[1] * by + bary[2] * cy
    pz = bary[0] * az + bary[1] * bz + bary[2] * cz
    ox = oy = oz = 0.0
    for j in range(3):
        nx, ny, nz = _to_world_normal(scratch, ns[row, j, 0], ns[row, j, 1], ns[row, j, 2])
        below = min((px - world[3 * j]) * nx + (py - world[3 * j + 1]) * ny + (pz - world[3 * j + 2]) * nz, 0.0)
        ox -= bary[j] * below * nx
        oy -= bary[j] * below * ny
        oz -= bary[j] * below * nz
    return ox, oy, oz


@kernel
def offset_scale(geo, prim, px, py, pz):
    """Distance that safely clears the surface of triangle ``prim`` at (px, py, pz): a bound
    on the float32 error of the hit, from the triangle's and the point's distance to the centre."""
    center = geo[13]
    local = max(abs(px - center[0]), abs(py - center[1]), abs(pz - center[2]))
    return _EPS_REL * max(_triangle_scale(geo, prim), local) + 1e-30


@kernel(inline="always")  # see instance_of
def _triangle_scale(geo, prim):
    """The larger of triangle ``prim``'s corners' distance from the centre and the float64 rounding
    of their world coordinates (the hit is rebuilt in them), at mid-shutter."""
    info, mid, center = geo[4], geo[14], geo[13]
    i = instance_of(geo, prim)
    f = geo[7][i]
    r = geo[5][i]
    row = info[r, 3] + prim - geo[6][i]
    near = far = 0.0
    for k in range(3):
        w = info[r, 4] + geo[1][row, k]
        for a in range(3):
            p = f[a, 0] * mid[w, 0] + f[a, 1] * mid[w, 1] + f[a, 2] * mid[w, 2] + f[a, 3]
            near, far = max(near, abs(p - center[a])), max(far, abs(p))
    return max(near, far * _EPS_ABS)


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
def _intersects(scene, geo, origins, directions, tmax, times, masks, t, prim, u, v):
    """Closest hits of rays from float64 world origins (made relative to the centre here, then
    float32 for Embree) among the objects each ray's mask sees (``masks`` empty: all); the hit's global triangle id is its instance's first id plus primID, its
    distance and barycentrics those of the float64 ray on the float64 triangle (``refine``)."""
    center, base = geo[13], geo[6]
    rayhit = embree.new_rayhit()
    scratch = np.empty((2, 3, 4))
    for r in range(len(origins)):
        time = _time_of(times, r)
        th, uh, vh, _, _, _, p, _, inst = embree.intersect1(
            scene, rayhit, origins[r, 0] - center[0], origins[r, 1] - center[1], origins[r, 2] - center[2],
            directions[r, 0], directions[r, 1], directions[r, 2], 0.0, min(tmax[r], _FAR), time,
            masks[r] if len(masks) else EVERY)
        if p >= 0:
            prim[r] = base[inst] + p
            t[r], u[r], v[r] = refine(geo, prim[r], origins[r, 0], origins[r, 1], origins[r, 2], directions[r, 0],
                                      directions[r, 1], directions[r, 2], time, th, uh, vh, scratch)


@kernel(inline="always")  # see instance_of
def refine(geo, prim, ox, oy, oz, dx, dy, dz, time, t, u, v, scratch):
    """(t, u, v) of the ray's hit on triangle ``prim`` in float64 (Moller-Trumbore on the world
    triangle at ``time``), clamped into the triangle; Embree's float32 (t, u, v) if the triangle
    is too thin to say. Embree's barycentrics can be off by 1e-3 on grazing hits, and differently
    for an instance than for the same triangles in one mesh; these are not."""
    i = instance_of(geo, prim)
    instance_frame(geo, i, time, scratch)
    c, _, _ = _corners(geo, i, prim, time)
    ax, ay, az = _to_world_point(scratch, c[0], c[1], c[2])
    bx, by, bz = _to_world_point(scratch, c[3], c[4], c[5])
    cx, cy, cz = _to_world_point(scratch, c[6], c[7], c[8])
    ex, ey, ez = bx - ax, by - ay, bz - az
    fx, fy, fz = cx - ax, cy - ay, cz - az
    px, py, pz = dy * fz - dz * fy, dz * fx - dx * fz, dx * fy - dy * fx
    det = ex * px + ey * py + ez * pz
    scale = math.sqrt((ex * ex + ey * ey + ez * ez) * (fx * fx + fy * fy + fz * fz) * (dx * dx + dy * dy + dz * dz))
    if not abs(det) > 1e-12 * scale:
        return t, u, v
    sx, sy, sz = ox - ax, oy - ay, oz - az
    qx, qy, qz = sy * ez - sz * ey, sz * ex - sx * ez, sx * ey - sy * ex
    u64 = max((sx * px + sy * py + sz * pz) / det, 0.0)
    v64 = max((dx * qx + dy * qy + dz * qz) / det, 0.0)
    total = u64 + v64
    if total > 1.0:
        u64, v64 = u64 / total, v64 / total
    return (fx * qx + fy * qy + fz * qz) / det, u64, v64


@kernel(inline="always")
def blocked(scene, center, rayhit, ox, oy, oz, dx, dy, dz, tmax, time, mask):
    """Whether geometry ``mask`` sees lies on the ray from the float64 world origin before tmax at
    ``time`` (the top-level scene ``scene``, 0 when there is none; rayhit from embree.new_rayhit)."""
    if scene == 0:
        return False
    return embree.occluded1(scene, rayhit, ox - center[0], oy - center[1], oz - center[2], dx, dy, dz, 0.0,
                            min(tmax, _FAR), time, mask)


@kernel
def _occludeds(scene, origins, directions, tmax, times, center, mask, out):
    rayhit = embree.new_rayhit()
    for r in range(len(origins)):
        out[r] = blocked(scene, center, rayhit, origins[r, 0], origins[r, 1], origins[r, 2], directions[r, 0],
                         directions[r, 1], directions[r, 2], tmax[r], _time_of(times, r), mask)


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


def _vertices_at(mesh, time: float) -> np.ndarray:
    """Object-space vertices of a deforming mesh at a shutter fraction (linear between steps)."""
    steps = mesh.motion_vertices
    x = np.clip(time, 0.0, 1.0) * (len(steps) - 1)
    i = min(int(x), len(steps) - 2)
    u = x - i
    return (1 - u) * steps[i] + u * steps[i + 1]
