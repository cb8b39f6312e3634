"""Blender 5's Multiple Scattering sky (Fernando García Liñán's spectral model, intern/sky/):
the atmosphere's in-scattered radiance per direction, tabulated once per setting as Cycles'
SkyLoader does, and the two sun-disc colours.

Four wavelengths (630, 560, 490, 430 nm) are ray-marched through an atmosphere of air
(Rayleigh), aerosols (Henyey-Greenstein g = 0.8) and ozone over a spherical Earth; multiple
scattering is an analytic fit plus ground bounce. The result is CIE XYZ; sky.py turns it into
Rec.709 and adds the sun disc. Constants and step counts are Blender's, so the table equals the
texture Cycles renders with (up to float32 rounding).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..base.jit import kernel

EARTH_RADIUS = 6371.0  # km
ATMOSPHERE_THICKNESS = 100.0  # km
ATMOSPHERE_RADIUS = EARTH_RADIUS + ATMOSPHERE_THICKNESS
TRANSMITTANCE_STEPS = 64
IN_SCATTERING_STEPS = 64
LUT_X, LUT_Y = 256, 64  # transmittance table: cos(sun zenith) by normalised altitude
TABLE_WIDTH, TABLE_HEIGHT = 512, 256  # Cycles' sky texture (SkyLoader)
G = 0.8
GROUND_ALBEDO = 0.3
SUN_SPECTRAL_IRRADIANCE = np.array([1.679, 1.828, 1.986, 1.307])
MOLECULAR_SCATTERING_BASE = np.array([6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2])
OZONE_CROSS_SECTION = np.array([3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27])
OZONE_MEAN_DOBSON = 334.5
AEROSOL_ABSORPTION_CROSS_SECTION = np.array([2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23])
AEROSOL_SCATTERING_CROSS_SECTION = np.array([1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22])
AEROSOL_BASE_DENSITY = 1.3681e20
AEROSOL_BACKGROUND_DENSITY = 2e6
AEROSOL_HEIGHT_SCALE = 0.73
MULTIPLE_SCATTERING_FIT = 0.02 * np.array([0.217, 0.347, 0.594, 1.0])
SPECTRAL_XYZ = np.array([[53.386917738564668023, 22.981337506691024754, 0.0],
                         [43.904844466369358263, 71.347795700053393866, 0.102506867965741307],
                         [1.6137278251608962005, 18.422960591455485011, 31.742921188390805758],
                         [20.762668673810577145, 2.3614213523314368527, 110.48009643252140334]])
"""Four-wavelength spectrum to CIE XYZ (rows: wavelengths)."""


def altitude_km(altitude_m: float) -> float:
    """The viewer's altitude as the model uses it: clamped to [1 m, 99,999 m], in km."""
    return min(max(altitude_m, 1.0), 99999.0) / 1000.0


@kernel(inline="always")
def _ray_sphere(ox, oy, oz, dx, dy, dz, radius):
    """Distance along a unit ray to a sphere about the origin; -1 when it misses or lies behind."""
    b = ox * dx + oy * dy + oz * dz
    c = ox * ox + oy * oy + oz * oz - radius * radius
    if c > 0.0 and b > 0.0:
        return -1.0
    d = b * b - c
    if d < 0:
        return -1.0
    if d >= b * b:
        return -b + math.sqrt(d)
    return -b - math.sqrt(d)


@kernel(inline="always")
def _densities(h, air, aerosol, ozone):
    """(aerosol, ozone, air) densities at altitude h km, times the user's multipliers."""
    aer = AEROSOL_BASE_DENSITY * (math.exp(-h / AEROSOL_HEIGHT_SCALE)
                                  + AEROSOL_BACKGROUND_DENSITY / AEROSOL_BASE_DENSITY) * aerosol
    log_h = math.log(max(h, 1e-4))
    ozn = OZONE_MEAN_DOBSON * 3.78547397e20 * math.exp(-(log_h - 3.22261) ** 2 * 5.55555555 - log_h) * ozone
    return aer, ozn, math.exp(-0.07771971 * h ** 1.16364243) * air


@kernel(inline="always")
def _coefficients(k, aer, ozn, mol, mol_base, ozone_cs, aer_abs, aer_sca):
    """(extinction, molecular scattering, aerosol scattering) of wavelength k."""
    msca = mol_base[k] * mol
    asca = aer_sca[k] * aer
    return aer_abs[k] * aer + asca + ozone_cs[k] * ozn + msca, msca, asca


@kernel
def transmittance(cos_theta, normalized_altitude, air, aerosol, ozone, mol_base, ozone_cs, aer_abs, aer_sca):
    """Transmittance (4 wavelengths) from a point at the normalised altitude towards a sun at
    cos(zenith) = cos_theta, marched to the top of the atmosphere."""
    sx, sz = -math.sqrt(max(1.0 - cos_theta * cos_theta, 0.0)), cos_theta
    r0 = EARTH_RADIUS + normalized_altitude * ATMOSPHERE_THICKNESS
    step = _ray_sphere(0.0, 0.0, r0, sx, 0.0, sz, ATMOSPHERE_RADIUS) / TRANSMITTANCE_STEPS
    depth = np.zeros(4)
    for i in range(TRANSMITTANCE_STEPS):
        t = (i + 0.5) * step
        px, pz = sx * t, r0 + sz * t
        aer, ozn, mol = _densities(max(math.sqrt(px * px + pz * pz) - EARTH_RADIUS, 0.0), air, aerosol, ozone)
        for k in range(4):
            depth[k] += _coefficients(k, aer, ozn, mol, mol_base, ozone_cs, aer_abs, aer_sca)[0] * step
    return np.exp(-depth)


@kernel
def _transmittance_lut(air, aerosol, ozone, mol_base, ozone_cs, aer_abs, aer_sca):
    lut = np.empty((LUT_Y, LUT_X, 4))
    for y in range(LUT_Y):
        for x in range(LUT_X):
            lut[y, x] = transmittance(x / (LUT_X - 1) * 2.0 - 1.0, y / (LUT_Y - 1), air, aerosol, ozone, mol_base,
                                      ozone_cs, aer_abs, aer_sca)
    return lut


@kernel(inline="always")
def _lut_lookup(lut, cos_theta, normalized_altitude, k):
    """Bilinear lookup of wavelength k in the transmittance table (no half-texel offset, as Blender's)."""
    x = (LUT_X - 1) * min(max(cos_theta * 0.5 + 0.5, 0.0), 1.0)
    y = (LUT_Y - 1) * min(max(normalized_altitude, 0.0), 1.0)
    x1, y1 = int(x), int(y)
    x2, y2 = min(x1 + 1, LUT_X - 1), min(y1 + 1, LUT_Y - 1)
    fx, fy = x - x1, y - y1
    bottom = lut[y1, x1, k] + fx * (lut[y1, x2, k] - lut[y1, x1, k])
    top = lut[y2, x1, k] + fx * (lut[y2, x2, k] - lut[y2, x1, k])
    return bottom + fy * (top - bottom)


@kernel(inline="always")
def _multiple_scattering(lut, k, cos_theta, normalized_altitude, omega):
    """Light reaching a point other than straight from the sun, wavelength k: the fit of the
    atmosphere's multiple scattering plus the sun's light bounced once off a Lambertian ground
    of solid angle omega."""
    to_ground = _lut_lookup(lut, cos_theta, 0.0, k)
    ground_to_sample = _lut_lookup(lut, 1.0, 0.0, k) / _lut_lookup(lut, 1.0, normalized_altitude, k)
    ground = (1.0 / (4 * math.pi)) * omega * (GROUND_ALBEDO / math.pi) * to_ground * ground_to_sample * cos_theta
    return MULTIPLE_SCATTERING_FIT[k] / (1.0 + 5.0 * math.exp(-17.92 * cos_theta)) + ground


@kernel
def _table(lut, sun_elevation, altitude, air, aerosol, ozone, mol_base, ozone_cs, aer_abs, aer_sca, sun_irr,
           spectral_xyz):
    """The sky texture in XYZ, rows from nadir to zenith with the elevation squeezed towards the
    horizon (elevation = sign(l) l^2 pi/2), columns over azimuth with the sun at azimuth pi."""
    out = np.empty((TABLE_HEIGHT, TABLE_WIDTH, 3))
    cz = math.cos(math.pi / 2 - sun_elevation)
    sx, sz = -math.sqrt(max(1.0 - cz * cz, 0.0)), cz
    r0 = EARTH_RADIUS + altitude
    for y in range(TABLE_HEIGHT):
        ell = (y + 0.5) / TABLE_HEIGHT * 2.0 - 1.0
        elev = math.copysign(ell * ell, ell) * math.pi / 2
        for x in range(TABLE_WIDTH // 2):
            azimuth = 2 * math.pi * (x + 0.5) / TABLE_WIDTH
            dx, dy, dz = math.cos(elev) * math.cos(azimuth), math.cos(elev) * math.sin(azimuth), math.sin(elev)
            ground = _ray_sphere(0.0, 0.0, r0, dx, dy, dz, EARTH_RADIUS)
            t_d = _ray_sphere(0.0, 0.0, r0, dx, dy, dz, ATMOSPHERE_RADIUS) if ground < 0.0 else ground
            cos_view_sun = -(dx * sx + dz * sz)
            mol_phase = (3.0 / 16.0) / math.pi * (1.0 + cos_view_sun * cos_view_sun)
            den = 1.0 + G * G + 2.0 * G * cos_view_sun
            aer_phase = (1.0 - G * G) / (4 * math.pi * den * math.sqrt(den))
            dt = t_d / IN_SCATTERING_STEPS
            radiance = np.zeros(4)
            trans = np.ones(4)
            for i in range(IN_SCATTERING_STEPS):
                t = (i + 0.5) * dt
                px, py, pz = dx * t, dy * t, r0 + dz * t
                dist = math.sqrt(px * px + py * py + pz * pz)
                h = max(dist - EARTH_RADIUS, 0.0)
                hn = h / ATMOSPHERE_THICKNESS
                cos_sun = (px * sx + pz * sz) / dist
                omega = 2 * math.pi * (1.0 - math.sqrt(max(1.0 - (EARTH_RADIUS / dist) ** 2, 0.0)))
                aer, ozn, mol = _densities(h, air, aerosol, ozone)
                for k in range(4):
                    ext, msca, asca = _coefficients(k, aer, ozn, mol, mol_base, ozone_cs, aer_abs, aer_sca)
                    to_sun = _lut_lookup(lut, cos_sun, hn, k)
                    ms = _multiple_scattering(lut, k, cos_sun, hn, omega)
                    s = sun_irr[k] * (msca * (mol_phase * to_sun + ms) + asca * (aer_phase * to_sun + ms))
                    step_trans = math.exp(-dt * ext)
                    radiance[k] += trans[k] * (s - s * step_trans) / max(ext, 1e-7)
                    trans[k] *= step_trans
            for c in range(3):
                v = 0.0
                for k in range(4):
                    v += radiance[k] * spectral_xyz[k, c]
                out[y, x, c] = v
                out[y, TABLE_WIDTH - 1 - x, c] = v
    return out


def _constants():
    return (MOLECULAR_SCATTERING_BASE, OZONE_CROSS_SECTION, AEROSOL_ABSORPTION_CROSS_SECTION,
            AEROSOL_SCATTERING_CROSS_SECTION)


@lru_cache(maxsize=8)
def _lut(air: float, aerosol: float, ozone: float) -> np.ndarray:
    return _transmittance_lut(air, aerosol, ozone, *_constants())


@lru_cache(maxsize=8)
def sky_table(sun_elevation: float, altitude_m: float, air: float, aerosol: float, ozone: float) -> np.ndarray:
    """The (256, 512, 3) XYZ texture Cycles precomputes for these settings (cached: a world
    program is evaluated once per wave)."""
    table = _table(_lut(air, aerosol, ozone), sun_elevation, altitude_km(altitude_m), air, aerosol, ozone,
                   *_constants(), SUN_SPECTRAL_IRRADIANCE, SPECTRAL_XYZ)
    table.setflags(write=False)
    return table


def sun_pixels(sun_elevation: float, angular_diameter: float, altitude_m: float, air: float, aerosol: float,
               ozone: float) -> tuple[np.ndarray, np.ndarray]:
    """XYZ radiance of the disc's lowest and highest points: the sun's irradiance through the
    atmosphere along that elevation, spread over the disc's solid angle."""
    solid_angle = 2 * math.pi * (1.0 - math.cos(angular_diameter / 2))
    normalized = altitude_km(altitude_m) / ATMOSPHERE_THICKNESS

    def xyz(elevation):
        t = transmittance(math.cos(math.pi / 2 - elevation), normalized, air, aerosol, ozone, *_constants())
        return (SUN_SPECTRAL_IRRADIANCE * t / solid_angle) @ SPECTRAL_XYZ

    return xyz(sun_elevation - angular_diameter / 2), xyz(sun_elevation + angular_diameter / 2)
