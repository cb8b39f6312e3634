"""The 3D viewport's own camera, for Rendered shading.

The viewport shows whatever its region's matrices say: free navigation, a locked
camera view with its zoom and offset, perspective or orthographic. As Cycles does for
the viewport (blender_camera_from_view in intern/cycles/blender/camera.cpp), the image
window and the clipping range are read off the region's projection
(``window_matrix``) and the camera placement off the inverse ``view_matrix``, so the
image lines up with the overlays drawn on top of it. The viewport renders with a
pinhole (no depth of field), at the region's size in pixels (HiDPI included: Blender gives
the region in pixels), after one coarse image at a fraction of it.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ...core.scene import Camera

COARSE_DIVISOR = 8
"""A new view first shows one sample at this fraction of the region's size, drawn stretched, then
the full size, as Cycles' viewport does (render_scheduler.cpp: its start resolution divider is 8
times the pixel size, and once the view holds still it goes to the full resolution at once).
Halving steps between the two (1/4, 1/2, as DRT drew before) delayed the Cornell box's first
full-resolution image in a 1280x720 region by about 0.4 s (the GUI test's worker events, in
out/ui/viewport_times.json)."""
COARSE_MIN_AXIS = 128
"""The coarse image's long side keeps at least this many pixels (Cycles' preferred minimum); a
region too small for that has no coarse image."""


def coarse_divisor(resolution: tuple[int, int]) -> int:
    """The divisor of the coarse image for a region of ``resolution`` pixels; 1: none."""
    return max(1, min(COARSE_DIVISOR, max(resolution) // COARSE_MIN_AXIS))


def level_cameras(camera: Camera, divisor: int | None = None) -> list[Camera]:
    """``camera`` at its resolution divided by ``divisor`` (default: coarse_divisor's; at least
    one pixel a side), then itself: the same window of the scene at a coarser pixel grid first."""
    width, height = camera.resolution
    divisor = coarse_divisor(camera.resolution) if divisor is None else divisor
    if divisor <= 1:
        return [camera]
    return [dataclasses.replace(camera, resolution=(max(1, width // divisor), max(1, height // divisor)), window=None),
            camera]


def edited_geometry(updates) -> set[str]:
    """Names of the datablocks whose geometry ``depsgraph.updates`` reports changed (an edited
    mesh: its object and its mesh; a moved object reports a transform alone): the meshes the
    viewport's export must read again (export.geometry.MeshCache.forget)."""
    return {update.id.name for update in updates if update.is_updated_geometry}


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
    """The camera of one 3D viewport region at the region's full resolution."""
    return camera_from_matrices(region_data.view_matrix, region_data.window_matrix, (region.width, region.height))
