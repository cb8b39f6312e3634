"""The Vector pass's motion vectors, as Cycles' primitive_motion_vector writes them.

A surface point the camera sees is carried to where it was at the previous frame and will be at the
next (its object's transform there, ``Instance.motion_pass``) and projected by the camera of that
frame (``Camera.motion_pass``; the lens of this frame, as Cycles' perspective_pre/post keep the
current camera-to-raster). In pixels, x right and y up: (previous - now) in the first two channels,
(now - next) in the last two, so a point moving steadily gives the same vector twice, pointing
against its motion. On a mesh whose vertices move (``Mesh.motion_pass_vertices``) the point keeps its
barycentric place in its triangle, carried by the vertices there (Cycles' motion vertex attribute).
Panoramic cameras project through their own mapping scaled by the image size,
as Cycles does. Without either motion the vector is exactly 0 (with motion blur on, Cycles' pass is
0 everywhere: the export then gives no motion).

A camera ray that reaches the background writes no vector up to Cycles 5.0; Cycles 5.2's
camera_motion_vector_direction gives it one (``directions``), so edge pixels then average the
surface's vectors with the background's rather than keep the surface's alone.
"""
from __future__ import annotations

import numpy as np

from ..scene import Camera
from .camera import panorama_window


class MotionVectors:
    """The motion vectors of one camera's hits on ``instances`` (``SceneData.instances``)."""

    def __init__(self, camera: Camera, instances, meshes=()):
        self.camera = camera
        now = camera.matrix
        pre, post = camera.motion_pass if camera.motion_pass is not None else (now, now)
        self.placed = (now, pre, post)  # camera to world
        self.views = [np.linalg.inv(m)[:3] for m in self.placed]  # world to camera
        # per instance, this frame's world to the previous (0) and next (1) frame's: identity when still
        self.moves = np.repeat(np.eye(4)[None, None], 2, 0).repeat(len(instances), 1)
        for i, instance in enumerate(instances):
            if instance.motion_pass is not None:
                to_object = np.linalg.inv(instance.matrix)
                self.moves[:, i] = instance.motion_pass @ to_object
        # per mesh whose vertices move: its triangles and object-space vertices now, at the previous
        # and the next frame; per instance the mesh of it that moves (-1: none) and its placement at
        # the three frames. A hit's corners are placed when it is found: the instances of one mesh
        # (a crowd of one character) share its arrays rather than each holding world copies
        self.deformed = {}
        self.deforming = np.full(len(instances), -1, np.int64)
        for i, instance in enumerate(instances):
            mesh = meshes[instance.mesh] if instance.mesh < len(meshes) else None
            if mesh is not None and mesh.motion_pass_vertices is not None:
                self.deformed[instance.mesh] = (mesh.triangles, mesh.vertices, *mesh.motion_pass_vertices)
                self.deforming[i] = instance.mesh
        self.placements = np.stack([
            (inst.matrix, *(inst.motion_pass if inst.motion_pass is not None else (inst.matrix,) * 2))
            for inst in instances]) if self.deformed else None

    def vectors(self, points: np.ndarray, instance: np.ndarray, triangle: np.ndarray | None = None) -> np.ndarray:
        """(N, 4) motion vectors of world ``points`` (N, 3) on the instances ``instance`` (N,), in
        their meshes' triangles ``triangle`` (N,; needed where a mesh's vertices move)."""
        center = self.raster(points, 0)
        moves = self.moves[:, instance]
        carried = [_placed(moves[k], points) for k in (0, 1)]
        meshes = self.deforming[instance]
        for mesh, (triangles, now, pre, post) in self.deformed.items():
            rows = np.flatnonzero(meshes == mesh)
            if len(rows):
                corners = triangles[triangle[rows]]
                placed = self.placements[instance[rows]]
                weights = _barycentric(points[rows], _placed(placed[:, 0], now[corners]))
                for k, vertices in enumerate((pre, post)):  # the point's place, then where that frame put it
                    carried[k][rows] = _placed(placed[:, k + 1], np.einsum("nk,nki->ni", weights, vertices[corners]))
        pre, post = self.raster(carried[0], 1), self.raster(carried[1], 2)
        return np.concatenate([pre - center, center - post], axis=1)

    def directions(self, dirs: np.ndarray) -> np.ndarray:
        """(N, 4) motion vectors of camera rays of directions ``dirs`` (N, 3) that reach the
        background, as Cycles 5.2's camera_motion_vector_direction: the direction through each
        frame's camera, as the surface points are (only the camera's turning moves it)."""
        center, pre, post = (self.direction_raster(dirs, k) for k in range(3))
        return np.concatenate([pre - center, center - post], axis=1)

    def direction_raster(self, dirs: np.ndarray, frame: int) -> np.ndarray:
        """(N, 2) where world directions ``dirs`` fall through the camera of ``frame``, as Cycles has
        it: a perspective or orthographic camera's world-to-raster projection without its
        translation and without the division by depth (transform_perspective_direction), a
        panoramic camera's mapping of the direction."""
        w, h = self.camera.resolution
        if self.camera.type == "PANO":
            turned = self.placed[frame].copy()
            turned[:3, 3] = 0.0
            return panorama_window(self.camera, dirs, turned) * np.array([w, h])
        local = dirs @ self.views[frame][:, :3].T
        left, right, bottom, top = self.camera.frame
        scale = np.array([w / (right - left), h / (top - bottom)])
        if self.camera.type == "PERSP":  # the raster's origin at the frame's corner, times the depth
            return (local[:, :2] + local[:, 2:3] * np.array([left, bottom])) * scale
        return local[:, :2] * scale

    def raster(self, points: np.ndarray, frame: int) -> np.ndarray:
        """(N, 2) pixel coordinates of world ``points`` seen by the camera of ``frame`` (0 this
        frame, 1 the previous, 2 the next), up to an offset common to all three."""
        w, h = self.camera.resolution
        if self.camera.type == "PANO":
            return panorama_window(self.camera, points, self.placed[frame]) * np.array([w, h])
        view = self.views[frame]
        local = points @ view[:, :3].T + view[:, 3]
        plane = local[:, :2]
        if self.camera.type == "PERSP":  # onto the plane z = -1 the frame lies on
            depth = -local[:, 2:3]
            plane = plane / np.where(depth != 0.0, depth, np.finfo(float).tiny)
        left, right, bottom, top = self.camera.frame
        return plane * np.array([w / (right - left), h / (top - bottom)])


def _placed(matrices: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (N, ..., 3) placed by one matrix (N, 4, 4) each."""
    offset = matrices[:, :3, 3].reshape((len(matrices),) + (1,) * (points.ndim - 2) + (3,))
    return np.einsum("nij,n...j->n...i", matrices[:, :3, :3], points) + offset


def _barycentric(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(N, 3) barycentric weights of ``points`` (N, 3) in triangles ``corners`` (N, 3, 3)."""
    e1, e2, d = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], points - corners[:, 0]
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    p1, p2 = (d * e1).sum(1), (d * e2).sum(1)
    det = d11 * d22 - d12 * d12
    det = np.where(det != 0.0, det, 1.0)
    u, v = (d22 * p1 - d12 * p2) / det, (d11 * p2 - d12 * p1) / det
    return np.stack([1.0 - u - v, u, v], axis=1)
