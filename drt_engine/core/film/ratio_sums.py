"""The film's side of the ratio estimator (core.integrator.ratio): the sums it keeps per pixel
and how Combined is read from them.

The integrator adds each sample's N, D and U to a wave output ``RATIO``; the film keeps them
as sums over all samples and over class A (the error estimate's half) and ``resolve``
replaces N by U N / D when the image is read. Kept here, not beside the estimator, because
the film and the farm's parts read these sums without any of the integrator.
"""
from __future__ import annotations

import numpy as np

RATIO = "Ratio"
"""Name of the film sums (and of the wave output) of N, D and U."""

NDU_CHANNELS = 9
"""N, D, U as RGB each."""

FILM_CHANNELS = 2 * NDU_CHANNELS
"""The film's sums: N, D, U over all samples, then over class A."""


def resolve(total: np.ndarray, ndu: np.ndarray) -> np.ndarray:
    """Summed RGB with the Monte Carlo diffuse direct part N replaced by U N / D (N where
    D = 0: nothing of these lights reached the pixel's samples)."""
    n, d, u = ndu[:, 0:3], ndu[:, 3:6], ndu[:, 6:9]
    seen = d > 0
    return total - n + np.where(seen, u * n / np.where(seen, d, 1.0), n)
