"""Blender 5's Single Scattering sky (Blender 2.90 to 4.x's Nishita, intern/sky/): Rayleigh and
Mie single scattering with ozone absorption over 21 wavelengths, tabulated once per setting as
Cycles' SkyLoader does, and the two sun-disc colours.

Only the upper half of the table is computed (the lower stays black: Cycles fades the ground
from the horizon row instead, in sky.py). Step counts, constants and the Gauss-Laguerre
quadrature of the optical depth towards the sun are Blender's, so the table equals Cycles'
texture up to float32 rounding.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..base.jit import kernel

RAYLEIGH_SCALE = 8e3  # m
MIE_SCALE = 1.2e3  # m
MIE_COEFF = 2e-5  # 1/m
MIE_G = 0.76
EARTH_RADIUS = 6360e3  # m
ATMOSPHERE_RADIUS = 6420e3  # m
STEPS = 32
STEP_LAMBDA = 20.0  # nm, 380 to 780
TABLE_WIDTH, TABLE_HEIGHT = 512, 256
NISHITA_HEIGHT = 128
IRRADIANCE = np.array([
    1.45756829855592995315, 1.56596305559738380175, 1.65148449067670455293, 1.71496242737209314555,
    1.75797983805020541226, 1.78256407885924539336, 1.79095108475838560302, 1.78541550133410664714,
    1.76815554864306845317, 1.74122069647250410362, 1.70647127164943679389, 1.66556087452739887134,
    1.61993437242451854274, 1.57083597368892080581, 1.51932335059305478886, 1.46628494965214395407,
    1.41245852740172450623, 1.35844961970384092709, 1.30474913844739281998, 1.25174963272610817455,
    1.19975998755420620867])
"""The sun's irradiance at the top of the atmosphere, W m^-2 nm^-1, 380 to 780 nm."""
RAYLEIGH_COEFF = np.array([
    5.424820087636473e-05, 4.418549866505454e-05, 3.635151910165377e-05, 3.017929012024763e-05,
    2.526320226989157e-05, 2.130859310621843e-05, 1.809838025320633e-05, 1.547057129129042e-05,
    1.330284977336850e-05, 1.150184784075764e-05, 9.99557429990163e-06, 8.72799973630707e-06,
    7.65513700977967e-06, 6.74217203751443e-06, 5.96134125832052e-06, 5.29034598065810e-06,
    4.71115687557433e-06, 4.20910481110487e-06, 3.77218381260133e-06, 3.39051255477280e-06,
    3.05591531679811e-06])
OZONE_COEFF = np.array([
    3.25126849861e-09, 5.85395365047e-09, 1.977191155085e-08, 7.309568762914e-08, 2.0084561514287e-07,
    4.0383958096161e-07, 6.3551335912363e-07, 9.6707041180970e-07, 1.54797400424410e-06,
    2.09038647223331e-06, 2.46128056164565e-06, 2.73551299461512e-06, 2.15125863128643e-06,
    1.59051840791988e-06, 1.12356197979857e-06, 7.3527551487574e-07, 4.6450130357806e-07,
    3.3096079921048e-07, 2.2512612292678e-07, 1.4879129266490e-07, 1.6828623364192e-07])
CMF_XYZ = np.array([
    [0.00136800000, 0.00003900000, 0.00645000100], [0.01431000000, 0.00039600000, 0.06785001000],
    [0.13438000000, 0.00400000000, 0.64560000000], [0.34828000000, 0.02300000000, 1.74706000000],
    [0.29080000000, 0.06000000000, 1.66920000000], [0.09564000000, 0.13902000000, 0.81295010000],
    [0.00490000000, 0.32300000000, 0.27200000000], [0.06327000000, 0.71000000000, 0.07824999000],
    [0.29040000000, 0.95400000000, 0.02030000000], [0.59450000000, 0.99500000000, 0.00390000000],
    [0.91630000000, 0.87000000000, 0.00165000100], [1.06220000000, 0.63100000000, 0.00080000000],
    [0.85444990000, 0.38100000000, 0.00019000000], [0.44790000000, 0.17500000000, 0.00002000000],
    [0.16490000000, 0.06100000000, 0.00000000000], [0.04677000000, 0.01700000000, 0.00000000000],
    [0.01135916000, 0.00410200000, 0.00000000000], [0.00289932700, 0.00104700000, 0.00000000000],
    [0.00069007860, 0.00024920000, 0.00000000000], [0.00016615050, 0.00006000000, 0.00000000000],
    [0.00004150994, 0.00001499000, 0.00000000000]])
"""CIE 1931 colour matching functions at the 21 wavelengths (Blender's table)."""
QUADRATURE_NODES = np.array([0.006811185292, 0.03614807107, 0.09004346519, 0.1706680068, 0.2818362161,
                             0.4303406404, 0.6296271457, 0.9145252695])
QUADRATURE_WEIGHTS = np.array([0.01750893642, 0.04135477391, 0.06678839063, 0.09507698807, 0.1283416365,
                               0.1707430204, 0.2327233347, 0.3562490486])
"""8-point Gauss-Laguerre quadrature along a ray to the top of the atmosphere (nodes scaled so the
last falls inside; weights with exp(x) folded in)."""


def altitude_m(altitude: float) -> float:
    """The viewer's altitude as this model clamps it (1 m to 59,999 m)."""
    return min(max(altitude, 1.0), 59999.0)


@kernel
def _densities(h):
    """(Rayleigh, Mie, ozone) density factors at height h m above sea level."""
    return math.exp(-h / RAYLEIGH_SCALE), math.exp(-h / MIE_SCALE), max(0.0, 1.0 - abs(h - 25000.0) / 15000.0)


@kernel
def _atmosphere_distance(px, py, pz, dx, dy, dz):
    b = -2.0 * -(dx * px + dy * py + dz * pz)
    c = px * px + py * py + pz * pz - ATMOSPHERE_RADIUS * ATMOSPHERE_RADIUS
    return (-b + math.sqrt(b * b - 4.0 * c)) / 2.0


@kernel
def _optical_depth(px, py, pz, dx, dy, dz, nodes, weights):
    """(Rayleigh, Mie, ozone) optical depth factors from p to the top of the atmosphere along d."""
    length = _atmosphere_distance(px, py, pz, dx, dy, dz)
    r = m = o = 0.0
    for i in range(len(nodes)):
        t = nodes[i] * length
        qx, qy, qz = px + dx * t, py + dy * t, pz + dz * t
        dr, dm, do = _densities(math.sqrt(qx * qx + qy * qy + qz * qz) - EARTH_RADIUS)
        r += dr * weights[i]
        m += dm * weights[i]
        o += do * weights[i]
    return r * length, m * length, o * length


@kernel
def _earth_hides(px, py, pz, dx, dy, dz):
    """Whether the Earth's sphere lies along d from p (only rays going down can meet it)."""
    if dz >= 0:
        return False
    b = -2.0 * -(dx * px + dy * py + dz * pz)
    c = px * px + py * py + pz * pz - EARTH_RADIUS * EARTH_RADIUS
    return b * b - 4.0 * c >= 0.0


@kernel
def _rows(latitudes, sun_elevation, altitude, air, aerosol, ozone, irradiance, rayleigh, ozone_coeff, cmf, nodes,
          weights):
    """(len(latitudes), TABLE_WIDTH, 3) XYZ: a row of the table per view latitude."""
    out = np.zeros((len(latitudes), TABLE_WIDTH, 3))
    sx, sz = math.cos(sun_elevation), math.sin(sun_elevation)
    oz = EARTH_RADIUS + altitude
    g2 = MIE_G * MIE_G
    spectrum = np.empty(len(irradiance))
    for y in range(len(latitudes)):
        latitude = latitudes[y]
        for x in range(TABLE_WIDTH // 2):
            longitude = 2 * math.pi / TABLE_WIDTH * x - math.pi
            dx, dy, dz = (math.cos(latitude) * math.cos(longitude), math.cos(latitude) * math.sin(longitude),
                          math.sin(latitude))
            seg = _atmosphere_distance(0.0, 0.0, oz, dx, dy, dz) / STEPS
            mu = dx * sx + dz * sz
            phase_r = (0.1875 / math.pi) * (1.0 + mu * mu)
            phase_m = (3.0 * (1.0 - g2) * (1.0 + mu * mu)) / (8.0 * math.pi * (2.0 + g2)
                                                               * (1.0 + g2 - 2.0 * MIE_G * mu) ** 1.5)
            spectrum[:] = 0.0
            depth_r = depth_m = depth_o = 0.0
            for i in range(STEPS):
                t = (i + 0.5) * seg
                px, py, pz = dx * t, dy * t, oz + dz * t
                dr, dm, do = _densities(math.sqrt(px * px + py * py + pz * pz) - EARTH_RADIUS)
                dr, dm, do = dr * air, dm * aerosol, do * ozone
                depth_r += seg * dr
                depth_m += seg * dm
                depth_o += seg * do
                if _earth_hides(px, py, pz, sx, 0.0, sz):
                    continue
                lr, lm, lo = _optical_depth(px, py, pz, sx, 0.0, sz, nodes, weights)
                tr, tm, to = depth_r + lr * air, depth_m + lm * aerosol, depth_o + lo * ozone
                for k in range(len(irradiance)):
                    attenuation = math.exp(-(tr * rayleigh[k] + tm * 1.11 * MIE_COEFF + to * ozone_coeff[k]))
                    scattering = phase_r * dr * rayleigh[k] + phase_m * dm * MIE_COEFF
                    spectrum[k] += attenuation * scattering * irradiance[k] * seg
            for c in range(3):
                v = 0.0
                for k in range(len(irradiance)):
                    v += cmf[k, c] * spectrum[k]
                out[y, x, c] = v * STEP_LAMBDA
                out[y, TABLE_WIDTH - 1 - x, c] = v * STEP_LAMBDA
    return out


def _table(latitudes, sun_elevation, altitude, air, aerosol, ozone) -> np.ndarray:
    return _rows(np.asarray(latitudes, float), sun_elevation, altitude_m(altitude), air, aerosol, ozone, IRRADIANCE,
                 RAYLEIGH_COEFF, OZONE_COEFF, CMF_XYZ, QUADRATURE_NODES, QUADRATURE_WEIGHTS)


@lru_cache(maxsize=8)
def sky_table(sun_elevation: float, altitude: float, air: float, aerosol: float, ozone: float) -> np.ndarray:
    """The (256, 512, 3) XYZ texture Blender 5's Cycles precomputes for these settings (cached):
    rows above the middle one at latitude pi/2 times the square of their share of the upper half."""
    half_h = TABLE_HEIGHT // 2
    table = np.zeros((TABLE_HEIGHT, TABLE_WIDTH, 3))
    table[half_h + 1:] = _table([math.pi / 2 * (y / half_h - 1.0) ** 2 for y in range(half_h + 1, TABLE_HEIGHT)],
                                sun_elevation, altitude, air, aerosol, ozone)
    table.setflags(write=False)
    return table


@lru_cache(maxsize=8)
def nishita_table(sun_elevation: float, altitude: float, air: float, aerosol: float, ozone: float) -> np.ndarray:
    """The (128, 512, 3) XYZ texture Blender 4's Cycles precomputes for its Nishita sky (cached): the
    upper hemisphere only, row y at latitude (pi/2 plus half a row's step) times (y / 128)^2."""
    height = NISHITA_HEIGHT
    step = math.pi / 2 / height
    table = _table([(math.pi / 2 + step / 2) * (y / height) ** 2 for y in range(height)], sun_elevation, altitude,
                   air, aerosol, ozone)
    table.setflags(write=False)
    return table


def sun_pixels(sun_elevation: float, angular_diameter: float, altitude: float, air: float,
               aerosol: float) -> tuple[np.ndarray, np.ndarray]:
    """XYZ radiance of the disc's lowest and highest points (black once the disc is below the
    horizon; ozone does not dim the disc in this model)."""
    half = angular_diameter / 2
    solid_angle = 2 * math.pi * (1.0 - math.cos(half))
    if sun_elevation + half <= 0.0:
        return np.zeros(3), np.zeros(3)
    oz = EARTH_RADIUS + altitude_m(altitude)

    def xyz(elevation):
        elevation = max(elevation, 0.0)
        r, m, _ = _optical_depth(0.0, 0.0, oz, math.cos(elevation), 0.0, math.sin(elevation), QUADRATURE_NODES,
                                 QUADRATURE_WEIGHTS)
        spectrum = IRRADIANCE * np.exp(-(RAYLEIGH_COEFF * r * air + 1.11 * MIE_COEFF * m * aerosol)) / solid_angle
        return spectrum @ CMF_XYZ * STEP_LAMBDA

    return xyz(sun_elevation - half), xyz(sun_elevation + half)
