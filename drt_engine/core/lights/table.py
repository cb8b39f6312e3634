"""The light table: one flat row of numbers per light, built once from ``scene.Light``, which
every light kernel reads (columns named here; each kind's module says what its row means).
"""
from __future__ import annotations

import math

import numpy as np

from ..base.colour import LUMINANCE
from ..scene import Light

INF = math.inf

# kinds
POINT, SPOT, SUN, RECT, DISK = 0, 1, 2, 3, 4
# columns of a light row
KIND = 0
PX, PY, PZ = 1, 2, 3  # position
DX, DY, DZ = 4, 5, 6  # where the light shines (local -Z)
EXX, EXY, EXZ = 7, 8, 9  # unit local X
EYX, EYY, EYZ = 10, 11, 12  # unit local Y
EZX, EZY, EZZ = 13, 14, 15  # unit local Z (area lights emit toward -Z: seen from the side ez points to)
SIZE_X, SIZE_Y, AREA = 16, 17, 18
RADIUS, SOFT = 19, 20
ER, EG, EB = 21, 22, 23  # intensity (point, spot), irradiance (sun), radiance (area)
COS_HALF, SMOOTH = 24, 25  # spot: cosine of the half cone, blend width in cosine; sun: cosine of half angle
SOLID, SUN_SCALE = 26, 27  # sun: solid angle of its disk, radiance per irradiance 1 / (pi sin^2 half)
SPREAD_MODE, SPREAD_TAN, SPREAD_NORM = 28, 29, 30  # area spread: 0 none, 1 narrowed, 2 zero
SEL_POWER, SEL_SIZE2 = 31, 32  # for choosing among many lights: power, squared size
VARYING = 33  # 1: a node tree scales each sample and hit (lights.programs), so no closed form
COLUMNS = 34

def _unit(v):
    return v / np.linalg.norm(v)


def light_row(light: Light) -> np.ndarray:
    """One light as a table row (everything a kernel needs, derived once)."""
    row = np.zeros(COLUMNS)
    m = light.matrix
    row[PX:PZ + 1] = m[:3, 3]
    row[EXX:EXZ + 1], row[EYX:EYZ + 1], row[EZX:EZZ + 1] = _unit(m[:3, 0]), _unit(m[:3, 1]), _unit(m[:3, 2])
    row[DX:DZ + 1] = -row[EZX:EZZ + 1]
    row[VARYING] = float(light.program is not None)
    if light.kind in ("POINT", "SPOT"):
        row[KIND] = POINT if light.kind == "POINT" else SPOT
        row[RADIUS], row[SOFT] = light.radius, float(light.soft_falloff)
        row[ER:EB + 1] = light.intensity
        cos_half = math.cos(min(light.spot_size, math.pi) / 2.0)
        row[COS_HALF], row[SMOOTH] = cos_half, (1.0 - cos_half) * light.spot_blend
        row[SEL_POWER], row[SEL_SIZE2] = light.intensity @ LUMINANCE, light.radius ** 2
    elif light.kind == "SUN":
        row[KIND] = SUN
        row[ER:EB + 1] = light.irradiance
        half = min(light.angle, math.pi) / 2.0
        row[COS_HALF] = math.cos(half)
        row[SOLID] = 2.0 * math.pi * (1.0 - math.cos(half))
        row[SUN_SCALE] = 1.0 / (math.pi * math.sin(half) ** 2) if half > 0 else 0.0
        row[SEL_POWER] = light.irradiance @ LUMINANCE
    else:
        disk = light.shape in ("DISK", "ELLIPSE")
        row[KIND] = DISK if disk else RECT
        sx, sy = light.size_x, light.size_y
        row[SIZE_X], row[SIZE_Y] = sx, sy
        row[AREA] = (math.pi / 4.0 if disk else 1.0) * sx * sy
        row[ER:EB + 1] = light.radiance
        row[SPREAD_MODE:SPREAD_NORM + 1] = _spread_terms(light.spread)
        row[SEL_POWER], row[SEL_SIZE2] = (light.radiance @ LUMINANCE) * row[AREA], 0.25 * (sx * sx + sy * sy)
    return row


def light_table(lights) -> np.ndarray:
    table = np.zeros((len(lights), COLUMNS))
    for i, light in enumerate(lights):
        table[i] = light_row(light)
    return table


def _spread_terms(spread: float):
    """Cycles' area light spread (area.h): emission narrowed to a cone of half angle h,
    normalised to keep power, factor max((tan h - tan a) / (tan h - h), 0) at emission angle a
    (3 / h^3 for tiny h). Returns (mode, tan h, normaliser): mode 0 when there is no spread
    (h = pi / 2), 2 when the spread is 0 (nothing leaves but along the normal)."""
    h = min(spread, math.pi) / 2.0
    if h >= math.pi / 2.0 - 1e-6:
        return 0.0, 0.0, 0.0
    if h <= 0:
        return 2.0, 0.0, 0.0
    return 1.0, math.tan(h), 3.0 / h ** 3 if h <= 0.05 else 1.0 / (math.tan(h) - h)
