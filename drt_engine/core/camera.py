"""Primary rays: the pixel filter's offset, the image window, the thin lens.

Rays start at the near clipping plane and stop at the far one, as Blender's camera
clips; ``depth_per_t`` converts distance along a ray into depth along the view axis.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import microfacet as mf
from .scene import Camera


@dataclass
class CameraRays:
    origins: np.ndarray
    directions: np.ndarray
    tmax: np.ndarray
    t_start: np.ndarray  # distance from the eye to the near plane along the ray
    depth_per_t: np.ndarray


def generate(camera: Camera, px: np.ndarray, py: np.ndarray, lens: np.ndarray | None) -> CameraRays:
    """Rays through continuous image coordinates (px, py) in pixels, y from the bottom."""
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
            disk = mf.concentric_disk(lens) * camera.aperture_radius
            focus = d * (camera.focus_distance / -d[:, 2])[:, None]
            o = np.concatenate([disk, np.zeros((n, 1))], axis=1)
            d = mf.normalize(focus - o)
        axial = -d[:, 2]
        t_start = camera.clip_start / axial
        t_end = camera.clip_end / axial
    else:
        o = np.stack([sx, sy, np.zeros(n)], axis=1)
        d = np.tile([0.0, 0.0, -1.0], (n, 1))
        axial = np.ones(n)
        t_start = np.full(n, camera.clip_start)
        t_end = np.full(n, camera.clip_end)
    m = camera.matrix
    o_w = o @ m[:3, :3].T + m[:3, 3]
    d_w = mf.normalize(d @ m[:3, :3].T)
    return CameraRays(o_w + d_w * t_start[:, None], d_w, np.maximum(t_end - t_start, 0.0), t_start, axial)
