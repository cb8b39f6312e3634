"""Nodes that read the hit's object, triangle and camera, as Cycles' SVM computes them:
Displacement and Vector Displacement (svm/displace.h), Camera Data (svm/camera.h),
Wireframe (svm/wireframe.h) and Tangent (svm/tex_coord.h). Arrays over hits: scalars (N,),
vectors (N, 3), transforms (N, 4, 4).
"""
from __future__ import annotations

import numpy as np

from ..base import vectors as vec


def _unit(v):
    length = vec.norm(v)[:, None]
    return np.where(length > 0, v / np.where(length > 0, length, 1.0), 0.0)


def to_object_normal(matrix, n):
    """Cycles' object_inverse_normal_transform: a world normal into object space, normalised."""
    return _unit(np.einsum("nji,nj->ni", matrix[:, :3, :3], n))


def to_world_normal(matrix, n):
    """Cycles' object_normal_transform: an object-space normal into the world (inverse transpose), normalised."""
    return _unit(np.einsum("nji,nj->ni", np.linalg.inv(matrix[:, :3, :3]), n))


def to_world_direction(matrix, v):
    return np.einsum("nij,nj->ni", matrix[:, :3, :3], v)


def displacement(space, height, midlevel, scale, normal, matrix):
    """Cycles' svm_node_displacement: the normal scaled by (height - midlevel) * scale, in object
    space (the normal taken there and the offset carried back, so it scales with the object) or
    in world space. ``matrix`` None: no object (world space either way)."""
    amount = ((height - midlevel) * scale)[:, None]
    if space == "OBJECT" and matrix is not None:
        return to_world_direction(matrix, to_object_normal(matrix, normal) * amount)
    return normal * amount


def vector_displacement(space, vector, midlevel, scale, normal, tangent, sign, matrix):
    """Cycles' svm_node_vector_displacement: (vector - midlevel) * scale, its x along the
    object-space tangent, y along the object-space normal and z along their bitangent in tangent
    space; tangent and object space carried to the world by the object's transform."""
    d = (vector - midlevel[:, None]) * scale[:, None]
    if matrix is None:
        return d
    if space == "TANGENT":
        n = to_object_normal(matrix, normal)
        b = _unit(np.cross(n, tangent)) * sign[:, None]
        d = tangent * d[:, :1] + n * d[:, 1:2] + b * d[:, 2:]
    return d if space == "WORLD" else to_world_direction(matrix, d)


def camera_data(pos, camera_matrix):
    """Cycles' svm_node_camera: the point in camera space (z looking forward): its direction
    (View Vector), z (View Z Depth) and length (View Distance)."""
    inverse = np.linalg.inv(camera_matrix)
    p = pos @ inverse[:3, :3].T + inverse[:3, 3]
    return _unit(p), p[:, 2].copy(), vec.norm(p)


def wireframe(pos, corners, size, pixel_width=None):
    """Cycles' wireframe: 1 within half of ``size`` of an edge of the hit's triangle (``corners``
    (N, 3, 3), world space), the size in world units, or in pixels with ``pixel_width`` (the
    pixel's footprint across the ray at the hit)."""
    half = 0.5 * size * (1.0 if pixel_width is None else pixel_width)
    limit = half * half
    out = np.zeros(len(pos))
    for i in range(3):
        edge = corners[:, i] - corners[:, i - 1]
        cross = np.cross(edge, pos - corners[:, i])
        out = np.where(vec.dot(cross, cross) < vec.dot(edge, edge) * limit, 1.0, out)
    return out


RADIAL_AXES = {"X": (1, 2), "Y": (0, 2), "Z": (0, 1)}


def radial_tangent(axis, generated):
    """Cycles' radial tangent in object space: around ``axis`` through the centre of the
    Generated coordinates (the other two components, turned a quarter)."""
    a, b = RADIAL_AXES[axis]
    t = np.zeros_like(generated)
    t[:, a] = -(generated[:, b] - 0.5)
    t[:, b] = generated[:, a] - 0.5
    return t


def surface_tangent(tangent, normal, matrix):
    """Cycles' svm_node_tangent after its direction: the object-space tangent carried to the world as
    a normal, then made perpendicular to the shading normal (zero where it has no direction)."""
    world = to_world_normal(matrix, tangent)
    return np.cross(normal, _unit(np.cross(world, normal)))
