"""Bump shadowing (core.bsdf.bump_shadowing), both of Cycles' models: no shadowing without a bump
or with the light along the smooth normal, fading to nothing toward the smooth horizon, light
from below the smooth surface dropped, the uncorrected variants, bounds and degenerate input."""
from __future__ import annotations

import math

import numpy as np
import pytest

from drt_engine.core.bsdf.bump_shadowing import CHIANG, GGX, bump_shadowing, model_code

TILT = 0.5  # radians between the smooth normal and the bumped one (the local z)
SMOOTH = (-math.sin(TILT), 0.0, math.cos(TILT))  # the smooth normal, the bump tilted toward +x


def _toward(elevation):
    """A direction at ``elevation`` radians above the smooth surface, on the side the bump faces."""
    sx, _, sz = SMOOTH
    tx, tz = sz, -sx  # the smooth surface's tangent toward +x
    return (math.cos(elevation) * tx + math.sin(elevation) * sx, 0.0,
            math.cos(elevation) * tz + math.sin(elevation) * sz)


def _factors(code, wi):
    return bump_shadowing(*SMOOTH, code, *wi)


def test_model_codes():
    assert model_code("CHIANG", True) == CHIANG and model_code("CHIANG", False) == CHIANG + 1
    assert model_code("GGX", True) == GGX and model_code("GGX", False) == GGX + 1


@pytest.mark.parametrize("code", [0, CHIANG, CHIANG + 1, GGX, GGX + 1])
def test_no_bump_and_light_along_the_smooth_normal_are_not_shadowed(code):
    assert bump_shadowing(0.0, 0.0, 1.0, 0, 0.3, 0.1, 0.9) == (1.0, 1.0)
    assert _factors(code, SMOOTH) == (1.0, 1.0)


@pytest.mark.parametrize("code", [CHIANG, GGX])
def test_diffuse_fades_out_toward_the_smooth_horizon(code):
    elevations = np.radians([60.0, 30.0, 15.0, 8.0, 4.0, 2.0, 1.0, 0.1])
    diffuse = [_factors(code, _toward(e))[0] for e in elevations]
    assert all(a >= b for a, b in zip(diffuse, diffuse[1:])), diffuse
    assert diffuse[-1] < 0.05 and diffuse[2] < 0.9, diffuse
    assert all(_factors(code, _toward(e))[1] == 1.0 for e in elevations)  # other lobes keep their light


def test_ggx_term_value():
    """Conty Estevez et al.: GGX shadowing G1 at the light's smooth cosine, with alpha^2 =
    tan^2(tilt) / 8: tilt 0.5, light 30 degrees from the smooth normal."""
    wi = _toward(math.radians(60.0))
    alpha2 = 0.125 * math.tan(TILT) ** 2
    lam = 0.5 * (math.sqrt(1.0 + alpha2 * math.tan(math.radians(30.0)) ** 2) - 1.0)
    assert _factors(GGX, wi)[0] == pytest.approx(1.0 / (1.0 + lam), rel=1e-9)


def test_light_from_below_the_smooth_surface():
    """Above the bumped normal, below the smooth surface: Chiang's term gives the diffuse lobes
    nothing, Cycles 5 drops every lobe's light, with or without the correction."""
    wi = _toward(math.radians(-5.0))
    assert wi[2] > 0.0  # the bumped normal still sees it
    assert _factors(CHIANG, wi)[0] == 0.0 and _factors(CHIANG + 1, wi)[0] == 0.0
    assert _factors(GGX, wi) == (0.0, 0.0) and _factors(GGX + 1, wi) == (0.0, 0.0)


def test_without_correction_no_smoothing():
    wi = _toward(math.radians(4.0))
    assert _factors(CHIANG, wi)[0] < 0.5 and _factors(GGX, wi)[0] < 0.9
    assert _factors(CHIANG + 1, wi) == (1.0, 1.0) and _factors(GGX + 1, wi) == (1.0, 1.0)


@pytest.mark.parametrize("code", [CHIANG, CHIANG + 1, GGX, GGX + 1])
def test_bounded_and_finite(code):
    rng = np.random.default_rng(3)
    for _ in range(2000):
        s = rng.normal(size=3)
        w = rng.normal(size=3)
        s, w = s / np.linalg.norm(s), w / np.linalg.norm(w)
        for value in bump_shadowing(*s, code, *w):
            assert 0.0 <= value <= 1.0
    for s, w in (((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)), ((0.6, 0.0, 0.8), (1.0, 0.0, 0.0)),
                 ((0.6, 0.0, 0.8), (0.0, 1.0, 0.0))):
        for value in bump_shadowing(*s, code, *w):
            assert math.isfinite(value) and 0.0 <= value <= 1.0
