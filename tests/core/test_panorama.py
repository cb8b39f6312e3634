"""Panoramic cameras (Cycles' kernel/camera/projection.h): each projection's rays against the
geometry that defines it, written here from the other side (image point from direction),
the equirectangular range's corners, the circle outside which a fisheye or mirror ball has
no ray, the lens focusing on a sphere, and a moving panoramic camera."""
from __future__ import annotations

import numpy as np
import pytest

from drt_engine.core.geometry import camera as camera_rays
from drt_engine.core.scene import PANORAMA_TYPES, Camera

W, H = 64, 32
LAT, LON = (-0.3, 0.8), (-1.0, 2.0)
POLYNOMIAL = (0.0, -0.09, 0.0, -2e-5, 0.0)  # the angle 0.09 r + 2e-5 r^3 at sensor radius r (mm)
CYLINDER = (-2.0, 1.5, -0.8, 1.2)


def _matrix():
    """A camera turned and moved, so that camera and world frames differ."""
    a, b = 0.7, -0.4
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rz @ rx, (1.0, -2.0, 3.0)
    return m


def _camera(panorama, **kw):
    settings = dict(latitude=LAT, longitude=LON, fisheye_fov=2.8, fisheye_lens=9.0, sensor=(36.0, 18.0),
                    fisheye_polynomial=POLYNOMIAL, cylinder=CYLINDER, clip_start=0.25, clip_end=40.0)
    settings.update(kw)
    return Camera(_matrix()[None], (0.0, 1.0, 0.0, 1.0), (W, H), type="PANO", panorama=panorama, **settings)


def _local(rays):
    """Ray directions in the camera's frame (looking down -z, y up)."""
    return rays.directions @ _matrix()[:3, :3]


def _image_point(cam, d):
    """(u, v) of camera-frame directions d, from each projection's definition."""
    x, y, z = d.T
    if cam.panorama == "EQUIRECTANGULAR":  # latitude up, longitude to the right
        lat, lon = np.arcsin(y), np.arctan2(x, -z)
        return (lon - LON[0]) / (LON[1] - LON[0]), (lat - LAT[0]) / (LAT[1] - LAT[0])
    if cam.panorama == "MIRRORBALL":  # the ball's normal bisects d and the view axis -z (Cycles': -reflect(I))
        n = np.stack([x, y, z - 1.0], axis=1)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        return 0.5 * (n[:, 0] + 1.0), 0.5 * (n[:, 1] + 1.0)
    if cam.panorama == "EQUIANGULAR_CUBEMAP_FACE":  # equal angles across the face ahead
        return 0.5 + np.arctan2(x, -z) / (np.pi / 2), 0.5 + np.arctan2(y, -z) / (np.pi / 2)
    if cam.panorama == "CENTRAL_CYLINDRICAL":  # longitude to the right, height on the unit cylinder up
        lon, height = np.arctan2(x, -z), y / np.hypot(x, z)
        return (lon - CYLINDER[0]) / (CYLINDER[1] - CYLINDER[0]), (height - CYLINDER[2]) / (CYLINDER[3] - CYLINDER[2])
    theta, rho = np.arccos(-z), np.hypot(x, y)
    if cam.panorama == "FISHEYE_LENS_POLYNOMIAL":  # the radius (mm) whose polynomial angle is theta
        r = np.array([min(t.real for t in np.roots([-POLYNOMIAL[4], -POLYNOMIAL[3], -POLYNOMIAL[2], -POLYNOMIAL[1],
                                                     -POLYNOMIAL[0] - a]) if abs(t.imag) < 1e-9 and t.real >= 0)
                      for a in theta])
        return 0.5 + r * x / rho / cam.sensor[0], 0.5 + r * y / rho / cam.sensor[1]
    if cam.panorama == "FISHEYE_EQUIDISTANT":  # radius proportional to the angle, fov across the circle
        r = theta / (0.5 * cam.fisheye_fov)
        return 0.5 + 0.5 * r * x / rho, 0.5 + 0.5 * r * y / rho
    r = 2.0 * cam.fisheye_lens * np.sin(0.5 * theta)  # equisolid, in mm on the sensor
    return 0.5 + r * x / rho / cam.sensor[0], 0.5 + r * y / rho / cam.sensor[1]


@pytest.mark.parametrize("panorama", PANORAMA_TYPES)
def test_each_image_point_maps_back_to_itself(panorama):
    cam = _camera(panorama)
    rng = np.random.default_rng(1)
    px, py = rng.random(4000) * W, rng.random(4000) * H
    rays = camera_rays.generate(cam, px, py, None)
    ok = rays.valid
    assert ok.mean() > 0.3
    d = _local(rays)[ok]
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    u, v = _image_point(cam, d)
    assert np.allclose(u, px[ok] / W, atol=1e-9) and np.allclose(v, py[ok] / H, atol=1e-9)
    # rays leave the near clip sphere and end on the far one
    eye = rays.origins[ok] - rays.directions[ok] * rays.t_start[ok, None]
    assert np.allclose(eye, _matrix()[:3, 3]) and np.allclose(rays.t_start[ok], 0.25)
    assert np.allclose(rays.tmax[ok], 40.0 - 0.25) and np.allclose(rays.depth_per_t[ok], 1.0)


@pytest.mark.parametrize("panorama", PANORAMA_TYPES)
def test_the_centre_looks_down_the_cameras_minus_z(panorama):
    cam = _camera(panorama, latitude=(-np.pi / 2, np.pi / 2), longitude=(-np.pi, np.pi), cylinder=(-1.0, 1.0, -1.0, 1.0))
    rays = camera_rays.generate(cam, np.array([W / 2]), np.array([H / 2]), None)
    assert rays.valid[0] and np.allclose(_local(rays)[0], [0.0, 0.0, -1.0], atol=1e-12)


def test_equirectangular_corners_are_the_ranges_corners():
    rays = camera_rays.generate(_camera("EQUIRECTANGULAR"), np.array([0.0, W, 0.0, W]), np.array([0.0, 0.0, H, H]),
                                None)
    lat, lon = np.array([LAT[0], LAT[0], LAT[1], LAT[1]]), np.array([LON[0], LON[1], LON[0], LON[1]])
    expected = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], axis=1)
    assert rays.valid.all() and np.allclose(_local(rays), expected, atol=1e-12)


def _polynomial_angle(r):
    return -sum(k * r ** i for i, k in enumerate(POLYNOMIAL))


@pytest.mark.parametrize("panorama, inside", [("FISHEYE_EQUIDISTANT", lambda u, v: np.hypot(2 * u - 1, 2 * v - 1) <= 1),
                                              ("MIRRORBALL", lambda u, v: np.hypot(2 * u - 1, 2 * v - 1) <= 1),
                                              ("FISHEYE_EQUISOLID", lambda u, v: np.hypot(
                                                  (u - 0.5) * 36.0, (v - 0.5) * 18.0) <= 18.0 * np.sin(0.7)),
                                              ("FISHEYE_LENS_POLYNOMIAL", lambda u, v: _polynomial_angle(np.hypot(
                                                  (u - 0.5) * 36.0, (v - 0.5) * 18.0)) <= 1.4)])
def test_no_ray_outside_the_circle(panorama, inside):
    rng = np.random.default_rng(2)
    px, py = rng.random(4000) * W, rng.random(4000) * H
    rays = camera_rays.generate(_camera(panorama), px, py, None)
    expected = inside(px / W, py / H)
    assert 0.1 < expected.mean() < 0.9 and (rays.valid == expected).all()


@pytest.mark.parametrize("panorama", PANORAMA_TYPES)
def test_lens_rays_of_one_image_point_meet_at_the_focus_distance_along_it(panorama):
    cam = _camera(panorama, aperture_radius=0.2, focus_distance=3.0, blades=5)
    n = 2000
    px, py = np.full(n, 0.37 * W), np.full(n, 0.58 * H)
    pinhole = camera_rays.generate(cam, px[:1], py[:1], None)
    rays = camera_rays.generate(cam, px, py, np.random.default_rng(3).random((n, 2)))
    lens = rays.origins - rays.directions * rays.t_start[:, None]
    offset = lens - _matrix()[:3, 3]
    axis = pinhole.directions[0]
    assert np.allclose(offset @ axis, 0.0, atol=1e-12)  # the lens is across the central ray
    radius = np.linalg.norm(offset, axis=1)
    assert radius.max() <= 0.2 + 1e-12 and radius.max() > 0.15
    focus = _matrix()[:3, 3] + 3.0 * axis
    to_focus = focus - lens
    assert np.allclose(rays.directions, to_focus / np.linalg.norm(to_focus, axis=1, keepdims=True), atol=1e-12)


def test_a_moving_panoramic_camera_turns_its_rays_with_it():
    turned = _matrix() @ np.array([[0.0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])  # 90 degrees about z
    cam = Camera(np.array([_matrix(), turned]), (0.0, 1.0, 0.0, 1.0), (W, H), type="PANO", panorama="EQUIRECTANGULAR")
    px, py = np.array([20.0, 20.0]), np.array([11.0, 11.0])
    rays = camera_rays.generate(cam, px, py, None, np.array([0.0, 1.0]))
    still = camera_rays.generate(_camera("EQUIRECTANGULAR", latitude=(-np.pi / 2, np.pi / 2),
                                         longitude=(-np.pi, np.pi), clip_start=0.1), px[:1], py[:1], None)
    d = still.directions[0] @ _matrix()[:3, :3]
    assert np.allclose(rays.directions[0], _matrix()[:3, :3] @ d, atol=1e-12)
    assert np.allclose(rays.directions[1], turned[:3, :3] @ d, atol=1e-9)


@pytest.mark.parametrize("panorama", PANORAMA_TYPES)
def test_window_of_a_point_on_a_ray_is_its_image_point(panorama):
    """Texture Coordinate's Window under a panorama: the image point whose ray reaches the point."""
    cam = _camera(panorama)
    rng = np.random.default_rng(4)
    px, py = rng.random(3000) * W, rng.random(3000) * H
    rays = camera_rays.generate(cam, px, py, None)
    ok = rays.valid
    points = rays.origins[ok] + rays.directions[ok] * rng.uniform(0.5, 30.0, ok.sum())[:, None]
    u, v = camera_rays.panorama_window(cam, points).T
    assert np.allclose(u, px[ok] / W, atol=1e-9) and np.allclose(v, py[ok] / H, atol=1e-9)
