"""The Sky Texture's Preetham model ("A Practical Analytic Model for Daylight", Preetham, Shirley
and Smits) as Cycles computes it: the zenith's xyY and the Perez distribution's coefficients from
the turbidity and the sun's direction (SkyTextureNode's precompute), then per direction the
Perez function of the view's zenith angle and its angle to the sun (svm sky.h). No sun disc.
"""
from __future__ import annotations

import math

import numpy as np


def _perez(lam, theta, gamma):
    return (1.0 + lam[0] * np.exp(lam[1] / np.cos(theta))) * (1.0 + lam[2] * np.exp(lam[3] * gamma)
                                                               + lam[4] * np.cos(gamma) ** 2)


def sun_angles(sun_direction) -> tuple[float, float]:
    """(theta, phi) of the sun's direction as Cycles' sky_spherical_coordinates gives them (the
    direction normalised, as Blender hands it to Cycles); Hosek-Wilkie's sun too."""
    sx, sy, sz = np.asarray(sun_direction, float) / max(float(np.linalg.norm(sun_direction)), 1e-30)
    return math.acos(min(max(sz, -1.0), 1.0)), math.atan2(sx, sy)


def view_angles(d: np.ndarray, sun_theta: float, sun_phi: float) -> tuple[np.ndarray, np.ndarray]:
    """(theta, gamma) per direction: its zenith angle, held just above the horizon as Cycles holds
    it, and its angle to the sun (svm sky.h; Hosek-Wilkie's too)."""
    theta = np.arccos(np.clip(d[:, 2], -1.0, 1.0))
    phi = -np.arctan2(d[:, 1], d[:, 0]) + math.pi / 2
    cos_gamma = np.sin(theta) * math.sin(sun_theta) * np.cos(sun_phi - phi) + np.cos(theta) * math.cos(sun_theta)
    return np.minimum(theta, math.pi / 2 - 0.001), np.arccos(np.clip(cos_gamma, -1.0, 1.0))


def coefficients(sun_direction, turbidity: float):
    """(sun theta, sun phi, zenith (Y, x, y) over the Perez function at the zenith, Perez
    coefficients for Y, x and y)."""
    theta, phi = sun_angles(sun_direction)
    t = turbidity
    t2, th2, th3 = t * t, theta * theta, theta ** 3
    chi = (4.0 / 9.0 - t / 120.0) * (math.pi - 2.0 * theta)
    zenith_Y = ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192) * 0.06
    zenith_x = ((0.00166 * th3 - 0.00375 * th2 + 0.00209 * theta) * t2
                + (-0.02903 * th3 + 0.06377 * th2 - 0.03202 * theta + 0.00394) * t
                + (0.11693 * th3 - 0.21196 * th2 + 0.06052 * theta + 0.25886))
    zenith_y = ((0.00275 * th3 - 0.00610 * th2 + 0.00317 * theta) * t2
                + (-0.04214 * th3 + 0.08970 * th2 - 0.04153 * theta + 0.00516) * t
                + (0.15346 * th3 - 0.26756 * th2 + 0.06670 * theta + 0.26688))
    perez = (
        (0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251, 0.1206 * t - 2.5771, -0.0670 * t + 0.3703),
        (-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125, -0.0641 * t - 0.8989, -0.0033 * t + 0.0452),
        (-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102, -0.0441 * t - 1.6537, -0.0109 * t + 0.0529))
    zenith = [z / _perez(lam, 0.0, theta) for z, lam in zip((zenith_Y, zenith_x, zenith_y), perez)]
    return theta, phi, zenith, perez


def xyz(params: dict, d: np.ndarray) -> np.ndarray:
    """(N, 3) CIE XYZ of the sky along directions d."""
    sun_theta, sun_phi, zenith, perez = coefficients(params["sun_direction"], params["turbidity"])
    theta, gamma = view_angles(d, sun_theta, sun_phi)
    Y, x, y = (z * _perez(lam, theta, gamma) for z, lam in zip(zenith, perez))
    safe_y = np.where(y != 0.0, y, 1.0)
    X = np.where(y != 0.0, x / safe_y * Y, 0.0)
    Z = np.where((y != 0.0) & (Y != 0.0), (1.0 - x - y) / safe_y * Y, 0.0)
    return np.stack([X, Y, Z], axis=1)
