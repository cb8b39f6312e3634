"""The scene camera, following Cycles' intern/cycles/blender/camera.cpp.

The image window (``Camera.frame``) is Cycles' view plane: sensor fit, pixel
aspect and shift folded in, scaled to the plane z = -1 for perspective cameras and
left in scene units for orthographic ones. Depth of field: aperture radius =
lens[mm]·1e-3 / (2·f-stop) for perspective (1 / (2·f-stop) for orthographic), in
scene units whatever the unit scale, and 0 when depth of field is off.
Panoramic cameras: the frame is the (u, v) square, shifted as Cycles shifts it, and
the projection's settings follow Cycles' blender_camera_sync. Motion blur's shutter curve and
Cycles' rolling shutter reach the camera as Cycles' blender_camera_sync reads them.
"""
from __future__ import annotations

import numpy as np

from ...core.errors import SceneError
from ...core.geometry.shutter import TABLE_SIZE, shutter_table
from ...core.scene import PANORAMA_TYPES, Camera


def resolution(render) -> tuple[int, int]:
    """Image size after the resolution percentage (integer arithmetic, as Blender)."""
    percent = render.resolution_percentage
    return render.resolution_x * percent // 100, render.resolution_y * percent // 100


def view_plane(cam, width: int, height: int, pixel_aspect: tuple[float, float]):
    """(left, right, bottom, top) of the image, as Cycles' ``blender_camera_viewplane``."""
    x_ratio = width * pixel_aspect[0]
    y_ratio = height * pixel_aspect[1]
    if cam.sensor_fit == "AUTO":
        horizontal, sensor = x_ratio > y_ratio, cam.sensor_width
    elif cam.sensor_fit == "HORIZONTAL":
        horizontal, sensor = True, cam.sensor_width
    else:
        horizontal, sensor = False, cam.sensor_height
    if horizontal:
        aspect_ratio = x_ratio / y_ratio
        half = np.array([aspect_ratio, 1.0])
    else:
        aspect_ratio = y_ratio / x_ratio
        half = np.array([1.0, aspect_ratio])
    if cam.type == "ORTHO":
        half *= cam.ortho_scale / (aspect_ratio * 2.0)
        aspect_ratio = cam.ortho_scale / 2.0
    offset = 2.0 * aspect_ratio * np.array([cam.shift_x, cam.shift_y])
    low, high = offset - half, offset + half
    if cam.type == "PERSP":
        tan_half_fov = 0.5 * sensor / cam.lens / aspect_ratio
        low, high = low * tan_half_fov, high * tan_half_fov
    return float(low[0]), float(high[0]), float(low[1]), float(high[1])


def border_window(render, width: int, height: int) -> tuple[int, int, int, int]:
    """Pixel rectangle of border render, as Blender's ``disprect``: border × size in
    single precision, truncated (render_init_from_main in render/intern/pipeline.cc)."""
    if not render.use_border:
        return 0, 0, width, height
    border = np.array(
        [render.border_min_x, render.border_min_y, render.border_max_x, render.border_max_y], np.float32
    )
    window = tuple(int(v) for v in border * np.array([width, height, width, height], np.float32))
    if window[2] <= window[0] or window[3] <= window[1]:
        raise SceneError("The render border is smaller than one pixel")
    return window


def without_scale(matrix) -> np.ndarray:
    matrix = np.array(matrix, dtype=np.float64)
    axes = np.linalg.norm(matrix[:3, :3], axis=0)
    matrix[:3, :3] /= np.where(axes > 0.0, axes, 1.0)
    return matrix


def export_camera(scene, camera_object) -> Camera:
    if camera_object is None:
        raise SceneError("No camera found in scene")
    if camera_object.type != "CAMERA":
        raise SceneError(f"The scene camera '{camera_object.name}' is not a camera object")
    cam = camera_object.data
    if cam.type == "PANO" and cam.panorama_type not in PANORAMA_TYPES:
        raise SceneError(f"Camera '{camera_object.name}': DRT does not render the panorama type "
                         f"{cam.panorama_type} (it renders {', '.join(PANORAMA_TYPES)})")
    render = scene.render
    width, height = resolution(render)
    if width < 1 or height < 1:
        raise SceneError(f"The image is empty ({width}x{height} pixels)")
    matrix = without_scale(camera_object.matrix_world)
    dof = cam.dof
    aperture = 0.0
    if dof.use_dof:
        fstop = max(dof.aperture_fstop, 1e-5)
        aperture = (1.0 if cam.type == "ORTHO" else cam.lens * 1e-3) / (2.0 * fstop)
    focus = dof.focus_distance
    if dof.focus_object is not None:
        to_focus = matrix[:3, 3] - np.array(dof.focus_object.matrix_world.translation)
        focus = abs(float(matrix[:3, 2] @ to_focus))
    pixel_aspect = (render.pixel_aspect_x, render.pixel_aspect_y)
    rolling = rolling_shutter(scene)
    return Camera(
        matrices=matrix[None],
        frame=(panorama_plane(cam) if cam.type == "PANO" else view_plane(cam, width, height, pixel_aspect)),
        resolution=(width, height),
        type=cam.type,
        clip_start=cam.clip_start,
        clip_end=cam.clip_end,
        window=border_window(render, width, height),
        aperture_radius=aperture,
        focus_distance=focus,
        blades=int(dof.aperture_blades),
        blade_rotation=float(dof.aperture_rotation),
        aperture_ratio=float(dof.aperture_ratio),
        shutter_table=shutter_curve(render, rolling),
        rolling_shutter=rolling,
        **(panorama_settings(cam, width, height, pixel_aspect) if cam.type == "PANO" else {}),
    )


def shutter_curve(render, rolling: float | None):
    """The shutter curve's table of shutter times, from the curve sampled as Cycles'
    curvemapping_to_array samples it; None without motion blur. Cycles reads its table for every
    curve, the flat default too, whose times run from 0.002 to 0.994 of the shutter: a sharp edge
    sliding across the view differed from Cycles' by 0.0090 with times uniform over the whole
    shutter (limit 0.0068)."""
    if not render.use_motion_blur:
        return None
    curves = render.motion_blur_shutter_curve
    curves.initialize()
    return shutter_table(np.array([curves.evaluate(curves.curves[0], i / (TABLE_SIZE - 1)) for i in range(TABLE_SIZE)]))


def rolling_shutter(scene):
    """Cycles' rolling shutter duration when its rolling shutter is on (a Cycles scene setting)."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None or not scene.render.use_motion_blur or cycles.rolling_shutter_type == "NONE":
        return None
    return float(cycles.rolling_shutter_duration)


def panorama_plane(cam) -> tuple[float, float, float, float]:
    """The panorama's (u, v) window: the unit square moved by the shift (a final render's,
    where Cycles' pano_aspectratio is 0)."""
    return cam.shift_x, 1.0 + cam.shift_x, cam.shift_y, 1.0 + cam.shift_y


def panorama_settings(cam, width: int, height: int, pixel_aspect) -> dict:
    """The projection's ``Camera`` fields; the equisolid sensor fitted to the image as Cycles
    fits it (the sensor fit's side kept, the other from the image's aspect)."""
    x_ratio, y_ratio = width * pixel_aspect[0], height * pixel_aspect[1]
    fit = cam.sensor_fit
    horizontal = x_ratio > y_ratio if fit == "AUTO" else fit == "HORIZONTAL"
    size = cam.sensor_height if fit == "VERTICAL" else cam.sensor_width
    sensor = (size, size * y_ratio / x_ratio) if horizontal else (size * x_ratio / y_ratio, size)
    settings = dict(panorama=cam.panorama_type, latitude=(cam.latitude_min, cam.latitude_max),
                    longitude=(cam.longitude_min, cam.longitude_max), fisheye_fov=cam.fisheye_fov,
                    fisheye_lens=cam.fisheye_lens, sensor=sensor,
                    fisheye_polynomial=tuple(getattr(cam, f"fisheye_polynomial_k{i}") for i in range(5)))
    if hasattr(cam, "central_cylindrical_radius"):  # Blender 4.3+
        radius = cam.central_cylindrical_radius
        settings["cylinder"] = (cam.central_cylindrical_range_u_min, cam.central_cylindrical_range_u_max,
                                cam.central_cylindrical_range_v_min / radius, cam.central_cylindrical_range_v_max / radius)
    return settings
