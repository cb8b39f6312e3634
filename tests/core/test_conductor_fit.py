"""The F82-tint fit of a conductor (Blender's Metallic BSDF in Physical Conductor mode): exact at
normal incidence and at the F82 angle, within 0.03 of the exact complex Fresnel at every angle
for measured metals (gold, copper, aluminium) and the node's defaults."""
import numpy as np
import pytest

from drt_engine.core.bsdf import microfacet as mf

METALS = {"gold": ((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)), "copper": ((0.27, 0.68, 1.32), (3.61, 2.62, 2.29)),
          "aluminium": ((1.35, 0.97, 0.62), (7.47, 6.40, 5.30)),
          "Metallic BSDF defaults": ((2.757, 2.513, 2.231), (3.867, 3.404, 3.009))}


def _exact(c, n, k):
    """Unpolarised Fresnel reflectance of a conductor n + ik (Born and Wolf), per channel."""
    eta = np.asarray(n) + 1j * np.asarray(k)
    cos_t = np.sqrt(1.0 - (1.0 - c * c) / eta ** 2)
    return 0.5 * (np.abs((c - eta * cos_t) / (c + eta * cos_t)) ** 2
                  + np.abs((eta * c - cos_t) / (eta * c + cos_t)) ** 2)


@pytest.mark.parametrize("metal", METALS)
def test_f82_tint_fit_of_a_conductor(metal):
    n, k = METALS[metal]
    f0, tint = mf.conductor_f82(n, k)
    fitted = lambda c: np.array([mf.fresnel_f82(c, f0[i], tint[i]) for i in range(3)])  # noqa: E731
    assert np.allclose(f0, _exact(1.0, n, k), rtol=0, atol=1e-12)
    assert np.allclose(fitted(1.0 / 7.0), _exact(1.0 / 7.0, n, k), rtol=0, atol=1e-9)
    worst = max(np.abs(fitted(c) - _exact(c, n, k)).max() for c in np.linspace(1e-3, 1.0, 200))
    assert worst < 0.03, worst
