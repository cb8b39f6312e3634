"""Primary rays: the pixel filter's offset, the image window, the thin lens (perspective
and orthographic).

Rays start at the near clipping plane and stop at the far one, as Blender's camera
clips; ``depth_per_t`` converts distance along a ray into depth along the view axis.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import microfacet as mf
from .motion import Motion
from .scene import Camera


FOCUS_MIN = 1e-5
"""Nearest focus distance, as Cycles clamps it: at 0 every lens ray would leave sideways."""


@dataclass
class CameraRays:
    origins: np.ndarray
    directions: np.ndarray
    tmax: np.ndarray
    t_start: np.ndarray  # distance from the eye to the near plane along the ray
    depth_per_t: np.ndarray


def aperture_point(camera: Camera, u: np.ndarray) -> np.ndarray:
    """Uniform point on the aperture: a disk, or a regular polygon with ``blades`` sides."""
    if camera.blades >= 3:
        n = camera.blades
        k = np.minimum((u[:, 0] * n).astype(np.int64), n - 1)
        u0 = u[:, 0] * n - k  # reuse the leftover of the choice, keeping stratification
        a0 = camera.blade_rotation + 2 * np.pi * k / n
        a1 = a0 + 2 * np.pi / n
        su = np.sqrt(u0)
        b1, b2 = su * (1 - u[:, 1]), su * u[:, 1]  # uniform in the triangle (centre, corner k, corner k+1)
        p = (b1[:, None] * np.stack([np.cos(a0), np.sin(a0)], 1) + b2[:, None] * np.stack([np.cos(a1), np.sin(a1)], 1))
    else:
        p = mf.concentric_disk(u)
    p = p * camera.aperture_radius
    p[:, 0] /= max(camera.aperture_ratio, 1e-6)
    return p


def moves(camera: Camera) -> bool:
    return Motion(camera.matrices).moving


def generate(camera: Camera, px: np.ndarray, py: np.ndarray, lens: np.ndarray | None,
             time: np.ndarray | None = None) -> CameraRays:
    """Rays through continuous image coordinates (px, py) in pixels, y from the bottom,
    at shutter fractions ``time`` when the camera moves."""
    w, h = camera.resolution
    left, right, bottom, top = camera.frame
    sx = left + (px / w) * (right - left)
    sy = bottom + (py / h) * (top - bottom)
    n = len(px)
    if camera.type == "PERSP":
        d = np.stack([sx, sy, -np.ones(n)], axis=1)
        d = mf.normalize(d)
        o = np.zeros((n, 3))
        if lens is not None and camera.aperture_radius > 0:
            disk = aperture_point(camera, lens)
            focus = d * (max(camera.focus_distance, FOCUS_MIN) / -d[:, 2])[:, None]
            o = np.concatenate([disk, np.zeros((n, 1))], axis=1)
            d = mf.normalize(focus - o)
        axial = -d[:, 2]
        t_start = camera.clip_start / axial
        t_end = camera.clip_end / axial
    else:
        o = np.stack([sx, sy, np.zeros(n)], axis=1)
        d = np.tile([0.0, 0.0, -1.0], (n, 1))
        if lens is not None and camera.aperture_radius > 0:
            # as Cycles: the ray leaves a point of the aperture around its own image point
            # and passes where the pinhole ray crosses the plane in focus
            focus = o + d * max(camera.focus_distance, FOCUS_MIN)
            o = o + np.concatenate([aperture_point(camera, lens), np.zeros((n, 1))], axis=1)
            d = mf.normalize(focus - o)
        axial = -d[:, 2]
        t_start = camera.clip_start / axial
        t_end = camera.clip_end / axial
    if time is not None and moves(camera):
        linear, translation = Motion(camera.matrices).at(time)
        linear = linear / np.linalg.norm(linear, axis=1, keepdims=True)  # drop any scale
        o_w = np.einsum("nij,nj->ni", linear, o) + translation
        d_w = mf.normalize(np.einsum("nij,nj->ni", linear, d))
    else:
        m = camera.matrix
        o_w = mf.transform(o, m[:3, :3]) + m[:3, 3]
        d_w = mf.normalize(mf.transform(d, m[:3, :3]))
    return CameraRays(o_w + d_w * t_start[:, None], d_w, np.maximum(t_end - t_start, 0.0), t_start, axial)


def pixel_spread(camera: Camera) -> tuple[float, float]:
    """A pixel's footprint width as a + b t at distance t along a camera ray: (a, b).

    Perspective: b is the pixel's angle; orthographic: a is its size. Texture lookups
    filter over this footprint (projected onto the surface)."""
    w = camera.resolution[0]
    left, right, _, _ = camera.frame
    size = abs(right - left) / w
    return (0.0, size) if camera.type == "PERSP" else (size, 0.0)
