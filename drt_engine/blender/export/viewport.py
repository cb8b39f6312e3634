"""The 3D viewport's own camera, for Rendered shading.

The viewport shows whatever its region's matrices say: free navigation, a locked
camera view with its zoom and offset, perspective or orthographic. As Cycles does for
the viewport (blender_camera_from_view in intern/cycles/blender/camera.cpp), the image
window and the clipping range are read off the region's projection
(``window_matrix``) and the camera placement off the inverse ``view_matrix``, so the
image lines up with the overlays drawn on top of it. The viewport renders with a
pinhole (no depth of field).
"""
from __future__ import annotations

import math

import numpy as np

from ...core.scene import Camera

MAX_PIXELS = 240 * 180
"""Pixels the viewport renders at most; the image is stretched to the region when drawn."""


def viewport_resolution(width: int, height: int, max_pixels: int = MAX_PIXELS) -> tuple[int, int]:
    """The region's size scaled down by one integer factor so it holds at most ``max_pixels``."""
    factor = max(1, math.ceil(math.sqrt(width * height / max_pixels)))
    return max(1, width // factor), max(1, height // factor)


def camera_from_matrices(view_matrix, window_matrix, resolution: tuple[int, int]) -> Camera:
    """A DRT camera seeing what an OpenGL view and projection matrix pair sees.

    Perspective projections give the window on the plane z = -1 and the clipping
    distances; orthographic ones give the window in scene units and a clipping range
    that may start behind the view point (Blender centres it on the view), so the
    camera is moved back to the near plane.
    """
    projection = np.array(window_matrix, dtype=np.float64)
    placement = np.linalg.inv(np.array(view_matrix, dtype=np.float64))
    sx, sy = projection[0, 0], projection[1, 1]
    if projection[3, 3] == 0.0:  # perspective: w = -z
        ox, oy = projection[0, 2], projection[1, 2]
        frame = ((ox - 1.0) / sx, (ox + 1.0) / sx, (oy - 1.0) / sy, (oy + 1.0) / sy)
        a, b = projection[2, 2], projection[2, 3]
        near, far = b / (a - 1.0), b / (a + 1.0)
        return Camera(matrices=placement[None], frame=frame, resolution=resolution, type="PERSP",
                      clip_start=near, clip_end=far)
    tx, ty = projection[0, 3], projection[1, 3]
    frame = ((-1.0 - tx) / sx, (1.0 - tx) / sx, (-1.0 - ty) / sy, (1.0 - ty) / sy)
    a, b = projection[2, 2], projection[2, 3]
    near, far = (b + 1.0) / a, (b - 1.0) / a
    placement[:3, 3] -= near * placement[:3, 2]  # the camera looks along -Z: move it to depth `near`
    return Camera(matrices=placement[None], frame=frame, resolution=resolution, type="ORTHO",
                  clip_start=0.0, clip_end=far - near)


def viewport_camera(region, region_data) -> Camera:
    """The camera of one 3D viewport region at the viewport's render resolution."""
    resolution = viewport_resolution(region.width, region.height)
    return camera_from_matrices(region_data.view_matrix, region_data.window_matrix, resolution)
