"""The Principled Hair BSDF's absorption coefficient (sigma, per unit length inside the fibre) from
its parametrizations, as Cycles' svm/closure.h and closure/bsdf_util.h compute it for both models:
Direct Coloring (a colour as the hair's reflectance, Chiang et al.'s fit), Melanin Concentration
(eu- and pheomelanin, plus a tint's absorption) and Absorption Coefficient (sigma itself). Host side:
per closure or per hit, over NumPy arrays."""
from __future__ import annotations

import numpy as np

EUMELANIN = (0.506, 0.841, 1.653)
PHEOMELANIN = (0.343, 0.733, 1.924)
"""Absorption per unit concentration (bsdf_principled_hair_sigma_from_concentration)."""


def albedo_roughness_scale(x):
    """bsdf_principled_hair_albedo_roughness_scale: a polynomial in the azimuthal roughness."""
    return (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969


def random_factor(random, randomization):
    """The svm's 1 + 2 (Random - 0.5) randomization (Random Roughness, Random Color)."""
    return 1.0 + 2.0 * (np.asarray(random, np.float64) - 0.5) * randomization


def sigma_from_concentration(eumelanin, pheomelanin):
    """RGB absorption (last axis 3) of the two melanin concentrations."""
    eu = np.asarray(eumelanin, dtype=np.float64)[..., None]
    pheo = np.asarray(pheomelanin, dtype=np.float64)[..., None]
    return eu * np.array(EUMELANIN) + pheo * np.array(PHEOMELANIN)


def sigma_from_reflectance(color_rgb, radial_roughness):
    """RGB absorption giving about ``color_rgb`` (last axis 3) as the hair's colour; infinite for 0."""
    scale = albedo_roughness_scale(np.asarray(radial_roughness, dtype=np.float64)[..., None])
    with np.errstate(divide="ignore"):
        sigma = np.log(np.maximum(np.asarray(color_rgb, dtype=np.float64), 0.0)) / scale
    return sigma * sigma


def melanin_sigma(melanin, melanin_redness, tint_rgb, radial_roughness, random_color_factor=1.0):
    """RGB absorption of the Melanin parametrization: melanin scaled by the random colour factor
    (``random_factor`` of Random with Random Color clamped to [0, 1]), mapped from 0..1 to 0..inf,
    split by redness into eu- and pheomelanin, plus the tint's absorption."""
    m = np.asarray(melanin, dtype=np.float64) * random_color_factor
    m = -np.log(np.maximum(1.0 - m, 0.0001))
    redness = np.asarray(melanin_redness, dtype=np.float64)
    return (sigma_from_concentration(m * (1.0 - redness), m * redness)
            + sigma_from_reflectance(tint_rgb, radial_roughness))
