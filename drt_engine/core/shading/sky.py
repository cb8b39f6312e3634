"""The Sky Texture node as Cycles' svm sky.h evaluates it, in linear Rec.709: a precomputed sky
texture (the Multiple Scattering model's, sky_scattering, or the Single Scattering one's and Blender
4's Nishita, sky_single) looked up per direction, plus the sun disc with limb darkening; Preetham
and Hosek / Wilkie as functions of the direction.

The node's parameters arrive as Blender shows them (``params``); ``settings`` wraps the sun's
elevation and rotation as Cycles' SkyTextureNode::simplify_settings does before anything else.
``sky_sun`` tells the world's importance sampling where the disc is, which a table of cells can
otherwise miss (the disc is about half a degree across).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..scene import TextureImage
from . import sky_hosek, sky_preetham, sky_scattering, sky_single
from .colornodes import XYZ_TO_REC709
from .textures import Texture

TABLE_WIDTH = sky_scattering.TABLE_WIDTH
"""Columns of the precomputed sky; the world's sampling table takes as many."""
MIN_SUN_SIZE = 0.0005
"""Cycles' clamp of the disc's angular diameter (SkyTextureNode::get_sun_size)."""
SCATTERING_TYPES = ("MULTIPLE_SCATTERING", "SINGLE_SCATTERING", "NISHITA")
"""Sky types of a precomputed texture and a sun disc (NISHITA: Blender 4's name and layout)."""
SKY_TYPES = SCATTERING_TYPES + ("PREETHAM", "HOSEK_WILKIE")
"""Sky types DRT computes: every one Blender 4.2 to 5.x offers."""


@dataclass(frozen=True)
class Settings:
    """The node's settings as Cycles' kernel receives them."""

    sky_type: str
    sun_disc: bool
    sun_size: float
    sun_intensity: float
    sun_elevation: float  # wrapped into [-pi/2, pi/2]
    sun_rotation: float  # Cycles' stored form: 2 pi minus the rotation wrapped into [0, 2 pi)
    altitude: float  # metres
    air: float
    aerosol: float
    ozone: float


def settings(params: dict) -> Settings:
    """Cycles' simplify_settings: an elevation past the zenith or nadir turns the sun round (so a
    daylight cycle can be animated), the rotation wrapped; the disc no smaller than MIN_SUN_SIZE."""
    elevation = math.fmod(params["sun_elevation"], 2 * math.pi)
    rotation = params["sun_rotation"]
    if abs(elevation) >= math.pi:
        elevation -= math.copysign(2.0, elevation) * math.pi
    if elevation >= math.pi / 2 or elevation <= -math.pi / 2:
        elevation = math.copysign(math.pi, elevation) - elevation
        rotation += math.pi
    rotation = math.fmod(rotation, 2 * math.pi)
    if rotation < 0.0:
        rotation += 2 * math.pi
    return Settings(params["sky_type"], bool(params["sun_disc"]), max(params["sun_size"], MIN_SUN_SIZE),
                    params["sun_intensity"], elevation, 2 * math.pi - rotation, params["altitude"],
                    params["air_density"], params["aerosol_density"], params["ozone_density"])


@lru_cache(maxsize=8)
def _texture(s: Settings) -> Texture:
    """The precomputed sky as an image Cycles looks up with Linear interpolation and Extend."""
    make = {"MULTIPLE_SCATTERING": sky_scattering.sky_table, "SINGLE_SCATTERING": sky_single.sky_table,
            "NISHITA": sky_single.nishita_table}[s.sky_type]
    table = make(s.sun_elevation, s.altitude, s.air, s.aerosol, s.ozone)
    return Texture(TextureImage("sky", pixels=table, colorspace="Non-Color"))


@lru_cache(maxsize=8)
def _sun_pixels(s: Settings) -> tuple[np.ndarray, np.ndarray]:
    if s.sky_type == "MULTIPLE_SCATTERING":
        return sky_scattering.sun_pixels(s.sun_elevation, s.sun_size, s.altitude, s.air, s.aerosol, s.ozone)
    return sky_single.sun_pixels(s.sun_elevation, s.sun_size, s.altitude, s.air, s.aerosol)


def _to_rgb(xyz: np.ndarray) -> np.ndarray:
    return np.maximum(xyz @ XYZ_TO_REC709.T, 0.0)


def sun_direction(s: Settings) -> np.ndarray:
    """The disc's centre (Cycles: spherical_to_direction(elevation - pi/2, rotation - pi/2))."""
    phi = s.sun_rotation - math.pi / 2
    c = math.cos(s.sun_elevation)
    return np.array([-c * math.cos(phi), -c * math.sin(phi), math.sin(s.sun_elevation)])


def _earth_angle(s: Settings) -> float:
    """Elevation below which the ground hides the sun, seen from the altitude (negative)."""
    r = sky_scattering.EARTH_RADIUS
    return -(math.pi / 2 - math.asin(r / (r + s.altitude / 1000.0)))


def _sun_disc(s: Settings, d: np.ndarray, elevation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The disc's radiance and where it shows: bottom to top colour by elevation, limb darkening of
    coefficient 0.6. Blender 5 hides it below the Earth's horizon seen from the altitude; Blender
    4's Nishita below the plane, and spreads a disc the horizon cuts over its part above."""
    sun = sun_direction(s)
    angle = 2 * np.arctan2(np.linalg.norm(d - sun, axis=1), np.linalg.norm(d + sun, axis=1))
    half = s.sun_size / 2
    nishita = s.sky_type == "NISHITA"
    inside = (angle < half) & ((d[:, 2] >= 0.0) if nishita else (elevation > _earth_angle(s)))
    out = np.zeros((len(d), 3))
    if inside.any():
        bottom, top = _sun_pixels(s)
        if nishita and s.sun_elevation - half <= 0.0:
            y = elevation[inside] / (s.sun_elevation + half)
        else:
            y = (elevation[inside] - s.sun_elevation) / s.sun_size + 0.5
        limb = 1.0 - 0.6 * (1.0 - np.sqrt(np.maximum(1.0 - (angle[inside] / half) ** 2, 0.0)))
        out[inside] = _to_rgb(bottom + y[:, None] * (top - bottom)) * limb[:, None]
    return out, inside


def sky_sun(params: dict) -> tuple[np.ndarray, float] | None:
    """(direction, angular radius) of the disc the node shows along unmapped directions, or None
    without a disc: what the world's sampling table must not miss."""
    if params["sky_type"] not in SCATTERING_TYPES:
        return None
    s = settings(params)
    if not s.sun_disc:
        return None
    return sun_direction(s), s.sun_size / 2


def _fade(d: np.ndarray) -> np.ndarray:
    """The ground of the Single Scattering and Nishita skies: the horizon's colour faded to black
    by 0.4 down."""
    return np.where(d[:, 2] < 0.0, np.where(d[:, 2] < -0.4, 0.0, (1.0 + 2.5 * d[:, 2]) ** 3), 1.0)


def evaluate(params: dict, d: np.ndarray) -> np.ndarray:
    """(N, 3) linear Rec.709 radiance of the sky along the (N, 3) directions d (as given:
    Cycles does not normalise a mapped vector). Single Scattering and Nishita have no ground and
    no sun below the horizon. Blender 4's Nishita shows the disc in place of the sky and keeps its
    texture to the upper hemisphere."""
    if params["sky_type"] == "PREETHAM":
        return _to_rgb(sky_preetham.xyz(params, d))
    if params["sky_type"] == "HOSEK_WILKIE":
        return _to_rgb(sky_hosek.xyz(params, d))
    s = settings(params)
    elevation = math.pi / 2 - np.arccos(np.clip(d[:, 2], -1.0, 1.0))
    phi = np.arctan2(d[:, 1], d[:, 0])
    sun, inside = _sun_disc(s, d, elevation) if s.sun_disc else (np.zeros((len(d), 3)), np.zeros(len(d), bool))
    sun *= s.sun_intensity
    x = np.mod((-phi - math.pi / 2 + s.sun_rotation) / (2 * math.pi), 1.0)
    below = d[:, 2] < 0.0
    if s.sky_type == "NISHITA":
        y = np.sqrt(np.maximum(elevation, 0.0) / (math.pi / 2))
    else:
        y = np.sqrt(np.abs(elevation) / (math.pi / 2)) * np.where(elevation < 0, -1.0, 1.0) * 0.5 + 0.5
    fade = np.ones(len(d))
    if s.sky_type == "SINGLE_SCATTERING":
        sun[below] = 0.0
        y = np.where(below, 0.508, y)
    if s.sky_type != "MULTIPLE_SCATTERING":
        fade = _fade(d)
    rgb = _to_rgb(_texture(s).lookup(np.stack([x, y], axis=1), None, "EXTEND", "Linear")[:, :3]) * fade[:, None]
    if s.sky_type == "NISHITA":
        rgb[inside] = 0.0
    return sun + rgb
