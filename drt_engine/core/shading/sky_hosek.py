"""The Sky Texture's Hosek / Wilkie model ("An Analytic Model for Full Spectral Sky-Dome Radiance",
Hosek and Wilkie 2012) as Cycles computes it: per channel of CIE XYZ, nine coefficients and a
radiance scale blended from the published table (sky_hosek_table) by ground albedo, turbidity and a
quintic Bezier curve over the sun's elevation (SkyTextureNode's precompute), then per direction the
model's function of the view's zenith angle and its angle to the sun (svm sky.h). No sun disc.
"""
from __future__ import annotations

import math

import numpy as np

from . import sky_preetham
from .sky_hosek_table import CONFIGURATIONS, RADIANCES

SCALE = 2 * math.pi / 683
"""Cycles' factor on the model's XYZ (its "adjust strength")."""
BERNSTEIN = np.array([1.0, 5.0, 10.0, 10.0, 5.0, 1.0])


def _blend(table: np.ndarray, turbidity: float, albedo: float, elevation: float) -> np.ndarray:
    """The table's entries for these settings: linear in albedo and turbidity, the elevation's
    cube root (of its share of a right angle) along the Bezier curve of the six control points."""
    t = (elevation / (math.pi / 2)) ** (1.0 / 3.0)
    k = np.arange(6)
    weights = BERNSTEIN * (1.0 - t) ** (5 - k) * t ** k
    low = int(turbidity)
    rem = turbidity - low
    out = 0.0
    for index, share in ((low - 1, 1.0 - rem), (low, rem)):
        if index > 9 or share == 0.0:
            continue
        for a, albedo_share in ((0, 1.0 - albedo), (1, albedo)):
            out = out + albedo_share * share * np.tensordot(weights, table[:, a, index], axes=([0], [1]))
    return out


def coefficients(params: dict):
    """(sun theta, sun phi, (3, 9) coefficients, (3,) radiance scales): the sun held at or above
    the horizon and the turbidity within [1, 10], as Cycles clamps them."""
    sun_theta, sun_phi = sky_preetham.sun_angles(params["sun_direction"])
    sun_theta = min(max(sun_theta, 0.0), math.pi / 2)
    turbidity = min(max(float(params["turbidity"]), 1.0), 10.0)
    albedo = min(max(float(params["ground_albedo"]), 0.0), 1.0)
    elevation = math.pi / 2 - sun_theta
    return (sun_theta, sun_phi, _blend(CONFIGURATIONS, turbidity, albedo, elevation),
            _blend(RADIANCES, turbidity, albedo, elevation))


def xyz(params: dict, d: np.ndarray) -> np.ndarray:
    """(N, 3) CIE XYZ of the sky along directions d, Cycles' scale included."""
    sun_theta, sun_phi, config, radiance = coefficients(params)
    theta, gamma = sky_preetham.view_angles(d, sun_theta, sun_phi)
    cos_theta, cos_gamma = np.cos(theta)[:, None], np.cos(gamma)[:, None]
    a, b, c, dd, e, f, g, h, i = (config[:, j] for j in range(9))
    mie = (1.0 + cos_gamma ** 2) / (1.0 + i * i - 2.0 * i * cos_gamma) ** 1.5
    value = ((1.0 + a * np.exp(b / (cos_theta + 0.01)))
             * (c + dd * np.exp(e * gamma[:, None]) + f * cos_gamma ** 2 + g * mie + h * np.sqrt(cos_theta)))
    return value * radiance * SCALE
