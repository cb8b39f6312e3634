"""The Principled Hair BSDF's absorption from its parametrizations (core.bsdf.hair_absorption), against
hand values of svm/closure.h (Random Roughness and Random Color's spread, the melanin's map
-log(max(1 - m, 1e-4))) and bsdf_util.h (the reflectance fit, the melanin colours)."""
import math

import numpy as np
import pytest

from drt_engine.core.bsdf import hair_absorption as ha


def test_random_factor_spreads_about_one():
    assert ha.random_factor(0.75, 0.2) == pytest.approx(1.1)
    assert ha.random_factor(0.5, 1.0) == 1.0


def test_reflectance_gives_back_its_colour():
    """The colour's absorption gives back the colour through the albedo's roughness scale; black is infinite."""
    color = np.array([[0.8, 0.4, 0.1], [0.5, 0.5, 0.5]])
    radial = np.array([0.3, 0.9])
    sigma = ha.sigma_from_reflectance(color, radial)
    assert sigma.shape == (2, 3)
    np.testing.assert_allclose(np.exp(-np.sqrt(sigma) * ha.albedo_roughness_scale(radial)[:, None]), color)
    assert np.all(np.isinf(ha.sigma_from_reflectance((0.0, 1.0, 1.0), 0.5)[0]))
    # roughness 0.3: scale = 5.969 - 0.215 0.3 + 2.532 0.09 - 10.73 0.027 + 5.574 0.0081 + 0.245 0.00243
    scale = 5.969 - 0.0645 + 0.22788 - 0.28971 + 0.0451494 + 0.00059535
    assert np.allclose(ha.sigma_from_reflectance([0.5, 1.0, 0.0], 0.3), [(math.log(0.5) / scale) ** 2, 0.0, np.inf])


def test_melanin_and_tint_add_up():
    assert np.all(ha.melanin_sigma(0.0, 0.3, (1.0, 1.0, 1.0), 0.4, 1.0) == 0.0)
    melanin = -math.log(1.0 - 0.6 * 1.2)  # melanin times the random colour factor, then mapped
    expected = (melanin * 0.75 * np.array([0.506, 0.841, 1.653]) + melanin * 0.25 * np.array([0.343, 0.733, 1.924])
                + ha.sigma_from_reflectance((0.9, 0.7, 0.6), 0.4))
    np.testing.assert_allclose(ha.melanin_sigma(0.6, 0.25, (0.9, 0.7, 0.6), 0.4, 1.2), expected, rtol=1e-12)
    np.testing.assert_allclose(ha.melanin_sigma(1.0, 0.0, (1.0, 1.0, 1.0), 0.5),
                               -math.log(1e-4) * np.array([0.506, 0.841, 1.653]))  # clamped at 1e-4
