"""Primary rays: the pixel filter's offset, the image window, the thin lens (perspective,
orthographic and panoramic).

Rays start at the near clipping plane and stop at the far one, as Blender's camera
clips; ``depth_per_t`` converts distance along a ray into depth along the view axis
(panoramic cameras: distance from the eye, as Cycles' Depth pass). Panoramic projections
follow Cycles' kernel/camera/projection.h and camera_sample_panorama; an image point
outside a fisheye's circle or a mirror ball's disc has no ray (``valid`` false).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..base.jit import kernel
from ..base.vectors import unit
from ..base.warps import concentric_disk
from ..scene import PANORAMA_TYPES, Camera
from .motion import Motion, frame_at
from .shutter import shutter_times

FOCUS_MIN = 1e-5
"""Nearest focus distance, as Cycles clamps it: at 0 every lens ray would leave sideways."""

PANORAMA_CODE = {name: 2 + i for i, name in enumerate(PANORAMA_TYPES)}
"""``lens[0]`` of each panoramic projection (0 is perspective, 1 orthographic)."""
(EQUIRECTANGULAR, FISHEYE_EQUIDISTANT, FISHEYE_EQUISOLID, MIRRORBALL, CUBEMAP_FACE, FISHEYE_POLYNOMIAL,
 CENTRAL_CYLINDRICAL) = (PANORAMA_CODE[n] for n in PANORAMA_TYPES)


@dataclass
class CameraRays:
    origins: np.ndarray
    directions: np.ndarray
    tmax: np.ndarray
    t_start: np.ndarray  # distance from the eye to the near plane along the ray
    depth_per_t: np.ndarray
    valid: np.ndarray  # false where the image point has no ray (outside a fisheye's circle)


def lens_table(camera: Camera) -> np.ndarray:
    """The camera's numbers as one flat array for ``camera_ray`` (made once per call: a few floats)."""
    w, h = camera.resolution
    left, right, bottom, top = camera.frame
    kind = PANORAMA_CODE[camera.panorama] if camera.type == "PANO" else float(camera.type != "PERSP")
    (lat_min, lat_max), (lon_min, lon_max) = camera.latitude, camera.longitude
    u_min, u_max, v_min, v_max = camera.cylinder
    return np.array([kind, w, h, left, right, bottom, top, camera.aperture_radius,
                     max(camera.aperture_ratio, 1e-6), camera.blades, camera.blade_rotation,
                     max(camera.focus_distance, FOCUS_MIN), camera.clip_start, camera.clip_end,
                     # Cycles' equirectangular_range: longitude from u, polar angle from v
                     lon_min - lon_max, -lon_min, lat_min - lat_max, np.pi / 2 - lat_min,
                     camera.fisheye_fov, camera.fisheye_lens, camera.sensor[0], camera.sensor[1],
                     *camera.fisheye_polynomial,
                     # Cycles' central_cylindrical_range: the longitudes negated (positive to the left)
                     -u_min, -u_max, v_min, v_max], np.float64)


@kernel
def panorama_direction(lens, u, v):
    """Unit direction in Cycles' panorama frame (x ahead, z up) of image point (u, v), or
    (0, 0, 0) outside the projection's circle."""
    kind = lens[0]
    if kind == EQUIRECTANGULAR:
        phi = lens[14] * u + lens[15]
        theta = lens[16] * v + lens[17]
        return math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)
    if kind == MIRRORBALL:  # the view reflected in a ball seen from -y
        bx, bz = 2.0 * u - 1.0, 2.0 * v - 1.0
        if bx * bx + bz * bz > 1.0:
            return 0.0, 0.0, 0.0
        by = -math.sqrt(max(1.0 - bx * bx - bz * bz, 0.0))
        c = -2.0 * by  # 2 (n . i) with i = (0, -1, 0)
        return c * bx, c * by + 1.0, c * bz
    if kind == CUBEMAP_FACE:  # the face ahead, equal angles per unit of u and v
        return unit(1.0, math.tan((0.5 - u) * 0.5 * math.pi), math.tan((v - 0.5) * 0.5 * math.pi))
    if kind == CENTRAL_CYLINDRICAL:  # a point of the cylinder about the up axis, seen from its centre
        phi = lens[27] + u * (lens[28] - lens[27])
        return unit(math.cos(phi), math.sin(phi), lens[29] + v * (lens[30] - lens[29]))
    if kind == FISHEYE_EQUIDISTANT:
        x, y = 2.0 * (u - 0.5), 2.0 * (v - 0.5)
        r = math.sqrt(x * x + y * y)
        if r > 1.0:
            return 0.0, 0.0, 0.0
        theta = 0.5 * r * lens[18]
    elif kind == FISHEYE_POLYNOMIAL:  # the angle a polynomial of the radius on the sensor, inside the fov
        x, y = (u - 0.5) * lens[20], (v - 0.5) * lens[21]
        r = math.sqrt(x * x + y * y)
        theta = -(lens[22] + r * (lens[23] + r * (lens[24] + r * (lens[25] + r * lens[26]))))
        if abs(theta) > 0.5 * lens[18]:
            return 0.0, 0.0, 0.0
    else:  # equisolid: r = 2 f sin(theta / 2) on the sensor, inside the circle of the fov
        x, y = (u - 0.5) * lens[20], (v - 0.5) * lens[21]
        r = math.sqrt(x * x + y * y)
        if r > 2.0 * lens[19] * math.sin(0.25 * lens[18]):
            return 0.0, 0.0, 0.0
        theta = 2.0 * math.asin(min(r / (2.0 * lens[19]), 1.0))
    if r == 0.0:  # Cycles' direction there (phi a quarter turn)
        return math.cos(theta), 0.0, math.sin(theta)
    s = math.sin(theta) / r
    return math.cos(theta), -x * s, y * s


@kernel
def panorama_point(lens, dx, dy, dz):
    """Image point (u, v) of unit direction d in Cycles' panorama frame, the inverse of
    ``panorama_direction``: Cycles' direction_to_panorama, which Texture Coordinate's Window reads."""
    kind = lens[0]
    if kind == EQUIRECTANGULAR:
        return ((math.atan2(dy, dx) - lens[15]) / lens[14],
                (math.acos(min(max(dz, -1.0), 1.0)) - lens[17]) / lens[16])
    if kind == MIRRORBALL:  # the ball's normal halfway between the view (0, -1, 0) and d
        dy -= 1.0
        div = 2.0 * math.sqrt(max(-0.5 * dy, 0.0))
        if div > 0.0:
            dx, dz = dx / div, dz / div
        return 0.5 * (dx + 1.0), 0.5 * (dz + 1.0)
    if kind == CUBEMAP_FACE:
        return 0.5 - math.atan2(dy, dx) * 2.0 / math.pi, math.atan2(dz, dx) * 2.0 / math.pi + 0.5
    if kind == CENTRAL_CYLINDRICAL:
        height = dz / math.sqrt(dx * dx + dy * dy)
        return ((math.atan2(dy, dx) - lens[27]) / (lens[28] - lens[27]),
                (height - lens[29]) / (lens[30] - lens[29]))
    across = math.sqrt(dy * dy + dz * dz)
    if across == 0.0:
        return 0.5, 0.5
    if kind == FISHEYE_EQUIDISTANT:
        r = math.atan2(across, dx) / lens[18]  # 0.5 on the circle (theta half the fov)
        return 0.5 - r * dy / across, 0.5 + r * dz / across
    if kind == FISHEYE_POLYNOMIAL:
        r = polynomial_radius(lens, -math.acos(min(max(dx, -1.0), 1.0)))
    else:
        r = 2.0 * lens[19] * math.sin(0.5 * math.acos(min(max(dx, -1.0), 1.0)))
    return 0.5 - r * dy / across / lens[20], 0.5 + r * dz / across / lens[21]


@kernel
def polynomial_radius(lens, theta):
    """The sensor radius whose lens-polynomial angle is ``theta``: Newton's method from the linear
    term's answer, as Cycles' direction_to_fisheye_lens_polynomial (at most 20 steps)."""
    k0, k1, k2, k3, k4 = lens[22], lens[23], lens[24], lens[25], lens[26]
    r = (theta - k0) / k1
    for _ in range(20):
        f = theta - (k0 + r * (k1 + r * (k2 + r * (k3 + r * k4))))
        step = f / (k1 + r * (2.0 * k2 + r * (3.0 * k3 + r * 4.0 * k4)))
        r += step
        if abs(step) < 1e-6:
            break
    return r


@kernel
def _panorama_points(lens, m, points, out):
    """``panorama_point`` of each world point seen from the camera (``m``: world to camera, 3 x 4)."""
    for i in range(len(points)):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        cx = m[0, 0] * px + m[0, 1] * py + m[0, 2] * pz + m[0, 3]
        cy = m[1, 0] * px + m[1, 1] * py + m[1, 2] * pz + m[1, 3]
        cz = m[2, 0] * px + m[2, 1] * py + m[2, 2] * pz + m[2, 3]
        # the camera's frame (looking down -z, y up) into Cycles' panorama frame (x ahead, z up;
        # the mirror ball's looks down -y), as panorama_ray turns it the other way
        if lens[0] == MIRRORBALL:
            x, y, z = unit(cx, cz, cy)
        else:
            x, y, z = unit(-cz, -cx, cy)
        out[i, 0], out[i, 1] = panorama_point(lens, x, y, z)


def panorama_window(camera: Camera, points: np.ndarray, matrix: np.ndarray | None = None) -> np.ndarray:
    """(N, 2) image points (0 to 1 over the unshifted image) of world ``points`` through a
    panoramic camera at mid-shutter (or placed by camera-to-world ``matrix``), as Cycles'
    camera_world_to_ndc has them."""
    out = np.empty((len(points), 2))
    view = np.linalg.inv(camera.matrix if matrix is None else matrix)[:3]
    _panorama_points(lens_table(camera), np.ascontiguousarray(view), np.ascontiguousarray(points, np.float64), out)
    return out


@kernel
def aperture_sample(lens, u0, u1):
    """Uniform point on the aperture: a disk, or a regular polygon with ``blades`` sides."""
    blades = int(lens[9])
    if blades >= 3:
        k = min(int(u0 * blades), blades - 1)
        su = math.sqrt(u0 * blades - k)  # reuse the leftover of the choice, keeping stratification
        a0 = lens[10] + 2 * math.pi * k / blades
        a1 = a0 + 2 * math.pi / blades
        b1, b2 = su * (1 - u1), su * u1  # uniform in the triangle (centre, corner k, corner k+1)
        x, y = b1 * math.cos(a0) + b2 * math.cos(a1), b1 * math.sin(a0) + b2 * math.sin(a1)
    else:
        x, y = concentric_disk(u0, u1)
    return x * lens[7] / lens[8], y * lens[7]


@kernel
def camera_ray(lens, m, px, py, u0, u1, use_lens):
    """The ray through image point (px, py) (pixels, y from the bottom), through lens point (u0, u1)
    when ``use_lens``, carried to the world by m (3, 4).

    Returns origin on the near plane, unit direction, the distance to the far plane, the
    distance from the eye to the near plane, depth per unit distance along the ray, and
    whether the image point has a ray at all.
    """
    sx = lens[3] + (px / lens[1]) * (lens[4] - lens[3])
    sy = lens[5] + (py / lens[2]) * (lens[6] - lens[5])
    focus = lens[11]
    if lens[0] >= 2.0:
        return panorama_ray(lens, m, sx, sy, u0, u1, use_lens)
    if lens[0] == 0.0:  # perspective: from the eye (or a point of the lens) toward the plane in focus
        ox, oy, oz = 0.0, 0.0, 0.0
        dx, dy, dz = unit(sx, sy, -1.0)
        if use_lens:
            ox, oy = aperture_sample(lens, u0, u1)
            f = focus / -dz
            dx, dy, dz = unit(dx * f - ox, dy * f - oy, dz * f)
    else:
        # as Cycles: the ray leaves a point of the aperture around its own image point
        # and passes where the pinhole ray crosses the plane in focus
        ox, oy, oz = sx, sy, 0.0
        dx, dy, dz = 0.0, 0.0, -1.0
        if use_lens:
            ax, ay = aperture_sample(lens, u0, u1)
            ox, oy = sx + ax, sy + ay
            dx, dy, dz = unit(sx - ox, sy - oy, -focus)
    axial = -dz
    t_start = lens[12] / axial
    t_end = lens[13] / axial
    return to_world(m, ox, oy, oz, dx, dy, dz, t_start, t_end, axial)


@kernel(inline="always")
def to_world(m, ox, oy, oz, dx, dy, dz, t_start, t_end, depth_per_t):
    """``camera_ray``'s result from a camera-space ray: origin moved to the near plane, t_start
    along it, and carried to the world by m."""
    wx = m[0, 0] * ox + m[0, 1] * oy + m[0, 2] * oz + m[0, 3]
    wy = m[1, 0] * ox + m[1, 1] * oy + m[1, 2] * oz + m[1, 3]
    wz = m[2, 0] * ox + m[2, 1] * oy + m[2, 2] * oz + m[2, 3]
    vx, vy, vz = unit(m[0, 0] * dx + m[0, 1] * dy + m[0, 2] * dz, m[1, 0] * dx + m[1, 1] * dy + m[1, 2] * dz,
                      m[2, 0] * dx + m[2, 1] * dy + m[2, 2] * dz)
    return (wx + vx * t_start, wy + vy * t_start, wz + vz * t_start, vx, vy, vz,
            max(t_end - t_start, 0.0), t_start, depth_per_t, True)


@kernel
def panorama_ray(lens, m, u, v, u0, u1, use_lens):
    """``camera_ray`` of a panoramic camera at image point (u, v), as Cycles' camera_sample_panorama:
    the lens shifts the origin across the ray and aims it back at the point ``focus`` along it
    (focus on a sphere); clipping is by distance from the eye."""
    dx, dy, dz = panorama_direction(lens, u, v)
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
    ox, oy, oz = 0.0, 0.0, 0.0
    if use_lens:
        ax, ay = aperture_sample(lens, u0, u1)
        ux, uy, uz = unit(1.0 - dx * dx, -dx * dy, -dx * dz)  # across the ray, toward the frame's x
        vx, vy, vz = dy * uz - dz * uy, dz * ux - dx * uz, dx * uy - dy * ux
        ox, oy, oz = ux * ax + vx * ay, uy * ax + vy * ay, uz * ax + vz * ay
        f = lens[11]
        dx, dy, dz = unit(dx * f - ox, dy * f - oy, dz * f - oz)
    # Cycles' panorama frame into the camera's (looking down -z, y up); the mirror ball's
    # frame looks down -y
    if lens[0] == MIRRORBALL:
        ox, oy, oz, dx, dy, dz = ox, oz, oy, dx, dz, dy
    else:
        ox, oy, oz, dx, dy, dz = -oy, oz, -ox, -dy, dz, -dx
    return to_world(m, ox, oy, oz, dx, dy, dz, lens[12], lens[13], 1.0)


@kernel
def _rays(lens, matrix, translation, quat, stretch, moving, px, py, u, use_lens, time, rays, depths, valid):
    """Camera rays into rays (2, N, 3: origins, directions), depths (3, N: tmax, t_start, depth per t)
    and valid (N,); a moving camera's frame at each ray's time, its scale dropped."""
    m = matrix.copy()
    for i in range(len(px)):
        if moving:
            frame_at(translation, quat, stretch, time[i], m)
            for c in range(3):
                length = math.sqrt(m[0, c] * m[0, c] + m[1, c] * m[1, c] + m[2, c] * m[2, c])
                for r in range(3):
                    m[r, c] /= length
        u0, u1 = (u[i, 0], u[i, 1]) if use_lens else (0.0, 0.0)
        (rays[0, i, 0], rays[0, i, 1], rays[0, i, 2], rays[1, i, 0], rays[1, i, 1], rays[1, i, 2], depths[0, i],
         depths[1, i], depths[2, i], valid[i]) = camera_ray(lens, m, px[i], py[i], u0, u1, use_lens)


@kernel
def _aperture_points(lens, u, out):
    for i in range(len(u)):
        out[i, 0], out[i, 1] = aperture_sample(lens, u[i, 0], u[i, 1])


def aperture_point(camera: Camera, u: np.ndarray) -> np.ndarray:
    """Uniform points on the aperture (N, 2) for sample values u (N, 2)."""
    out = np.empty((len(u), 2))
    _aperture_points(lens_table(camera), np.asarray(u, np.float64), out)
    return out


def shutter_time(camera: Camera, u: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Shutter times (0 to 1) of samples with time values ``u`` in pixel rows ``rows`` (from the
    bottom): through the camera's shutter curve and rolling shutter, as Cycles' camera_sample."""
    return shutter_times(camera.shutter_table, camera.rolling_shutter, camera.resolution[1], u, rows)


def moves(camera: Camera) -> bool:
    return Motion(camera.matrices).moving


def generate(camera: Camera, px: np.ndarray, py: np.ndarray, lens: np.ndarray | None,
             time: np.ndarray | None = None) -> CameraRays:
    """Rays through continuous image coordinates (px, py) in pixels, y from the bottom,
    at shutter fractions ``time`` when the camera moves."""
    n = len(px)
    motion = Motion(camera.matrices)
    moving = time is not None and motion.moving
    use_lens = lens is not None and camera.aperture_radius > 0
    # each quantity its own C-contiguous block: what later kernels take compiles for one layout
    rays, depths, valid = np.empty((2, n, 3)), np.empty((3, n)), np.empty(n, bool)
    _rays(lens_table(camera), np.ascontiguousarray(camera.matrix[:3]), *motion.table, moving,
          np.asarray(px, np.float64), np.asarray(py, np.float64),
          np.asarray(lens, np.float64) if use_lens else np.zeros((0, 2)), use_lens,
          np.asarray(time, np.float64) if moving else np.zeros(0), rays, depths, valid)
    return CameraRays(rays[0], rays[1], depths[0], depths[1], depths[2], valid)


def pixel_spread(camera: Camera) -> tuple[float, float]:
    """A pixel's footprint width as a + b t at distance t along a camera ray: (a, b).

    Perspective: b is the pixel's angle; orthographic: a is its size; panoramic: b is the
    pixel's angle at the image centre. Texture lookups filter over this footprint (projected
    onto the surface)."""
    w = camera.resolution[0]
    left, right, _, _ = camera.frame
    size = abs(right - left) / w
    if camera.type == "PANO":
        per_u = {"EQUIRECTANGULAR": abs(camera.longitude[1] - camera.longitude[0]),
                 "FISHEYE_EQUIDISTANT": camera.fisheye_fov, "FISHEYE_EQUISOLID": camera.sensor[0] / camera.fisheye_lens,
                 "MIRRORBALL": 4.0, "EQUIANGULAR_CUBEMAP_FACE": np.pi / 2,
                 "FISHEYE_LENS_POLYNOMIAL": abs(camera.fisheye_polynomial[1]) * camera.sensor[0],
                 "CENTRAL_CYLINDRICAL": abs(camera.cylinder[1] - camera.cylinder[0]),
                 }[camera.panorama]  # the direction's angle per unit of u there
        return 0.0, size * per_u
    return (0.0, size) if camera.type == "PERSP" else (size, 0.0)
