"""Denoising a finished render with OpenImageDenoise, and the error of the denoised image.

The film keeps two independent replicate halves of every pixel's samples (core.film.film). The
Combined image is denoised three times: the whole, and each half alone, all guided by the same
Denoising Albedo and Normal (traced over all the samples). The halves' denoised images differ by
the noise the denoiser leaves in an image of half the samples, so, as for the noisy image
(adaptive.image_error), the denoised image's squared error per pixel is estimated as

    (D_A - D_B)^2 n_A n_B / n^2

which is its variance if the denoiser's leftover noise falls as 1 / samples, as a linear
smoother's does. What this cannot see:

- **bias**: detail the denoiser blurs away, or invents, the same way in both halves (a texture
  smoothed flat, a thin shadow softened) cancels in D_A - D_B: the estimate measures noise, never
  blur of real detail. Against a reference the true error is the estimate plus that bias squared
  (docs/denoising.md measures how far apart they are);
- noise of the albedo and normal: the three denoisings share them;
- OIDN is not linear: it smooths a noisier image harder, so the halves' leftover noise may grow
  by less than the factor two the formula assumes.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..film.denoising import ALBEDO, NORMAL
from ..film.film import Film
from .adaptive import RELMSE_EPSILON, TRUE_FLOOR


@dataclass
class Denoised:
    rgb: np.ndarray  # (h, w, 3) float32, the denoised Combined RGB, rows from the bottom
    rmse: float  # its estimated RMSE over pixels and channels (inf while a pixel lacks a half)
    relmse: float  # ... and relMSE, as adaptive.image_error measures the noisy image's
    seconds: float  # the three denoisings' time


def denoise_film(film: Film, passes: dict, denoiser, prefilter: str, quality: str) -> Denoised:
    """The denoised Combined image of ``film`` and its estimated error; ``passes`` are the film's
    images (Denoising Albedo and Normal among them), ``denoiser`` a core.film.denoiser.Denoiser."""
    start = time.perf_counter()
    shape = (film.height, film.width, 3)
    n, na, total, total_a, total_b = film.halves()
    nb = n - na
    albedo, normal = passes.get(ALBEDO), passes.get(NORMAL)

    def run(sums, count):
        return denoiser.denoise((sums / np.maximum(count, 1)[:, None]).reshape(shape), albedo, normal,
                                prefilter=prefilter, quality=quality)

    full = run(total, n)
    half_a, half_b = run(total_a, na), run(total_b, nb)
    rmse, relmse = denoised_error(full, half_a, half_b, n, na)
    return Denoised(full, rmse, relmse, time.perf_counter() - start)


def denoised_variance(half_a, half_b, n, na) -> np.ndarray:
    """Per pixel and channel (flat (pixels, 3)), the estimated squared error of the image denoised
    from all n samples, from the images denoised from each half (n_A and n - n_A samples); inf
    where a pixel has no sample in one half."""
    n = np.asarray(n, float).reshape(-1)
    na = np.asarray(na, float).reshape(-1)
    nb = n - na
    d = np.asarray(half_a, float).reshape(-1, 3) - np.asarray(half_b, float).reshape(-1, 3)
    var = d * d * (na * nb / np.maximum(n, 1) ** 2)[:, None]
    var[~((na > 0) & (nb > 0))] = np.inf
    return var


def denoised_error(full, half_a, half_b, n, na) -> tuple[float, float]:
    """(RMSE, relMSE) of the denoised image ``full``, estimated from its halves' denoised images
    (see the module docstring); the true value squared is estimated as for the noisy image: the
    image's square less the variance, at least TRUE_FLOOR of it."""
    var = denoised_variance(half_a, half_b, n, na)
    if var.size == 0:
        return 0.0, 0.0
    if not np.isfinite(var).all():
        return math.inf, math.inf
    square = np.asarray(full, float).reshape(-1, 3) ** 2
    true_square = np.maximum(square - var, TRUE_FLOOR * square)
    return float(np.sqrt(var.mean())), float((var / (true_square + RELMSE_EPSILON)).mean())
