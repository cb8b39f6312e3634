"""Denoising a finished render with OpenImageDenoise, and the error of the denoised image.

The film keeps two independent replicate halves of every pixel's samples (core.film.film): noisy
images N_A and N_B of n_A and n_B samples, N their mean over all n. Combined is denoised three
times, all guided by the same Denoising Albedo and Normal (traced over all the samples): D from N,
D_A from N_A, D_B from N_B. Two figures come from them, per pixel and channel:

- **the noise the denoiser leaves**, (D_A - D_B)^2 n_A n_B / n^2: the variance of D if that noise
  falls as 1 / samples, as a linear smoother's does (the same form as the noisy image's estimate,
  adaptive.image_error). It cannot see blur of real detail: a texture smoothed flat or a thin
  shadow softened the same way in both halves cancels in D_A - D_B. On the sample scenes it read
  0.4 to 0.6 of the true error (docs/denoising.md);
- **the error of a half's denoised image, blur included**, by cross-validation against the other
  half's noisy image, which is unbiased and independent of it:
  E[(D_A - N_B)^2] = MSE(D_A) + Var(N_B), with Var(N_B) = (N_A - N_B)^2 n_A / n in expectation, so
  MSE of a half ~ ((D_A - N_B)^2 + (D_B - N_A)^2 - (N_A - N_B)^2) / 2.

The estimate of D's squared error is that half's error less the noise of D (a half's bias taken
for D's: D, from twice the samples, is blurred no more than a half, so this leans high), and never
less than the noise alone. What it still cannot see, or sees wrongly:

- bias of the noisy image itself (clamping, the ratio estimator's): N_B is the reference it
  measures against;
- noise of the albedo and normal: the three denoisings share them;
- per pixel it is very noisy (a difference of squares of noisy images): only its image mean is
  reported.
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
    error: dict  # estimated rmse and relmse of it, and rmse_noise and relmse_noise (``denoised_error``)
    seconds: float  # the denoisings' time


def denoise_film(film: Film, passes: dict, denoiser, prefilter: str, quality: str) -> Denoised:
    """The denoised Combined image of ``film`` and its estimated error; ``passes`` are the film's
    images (Denoising Albedo and Normal among them), ``denoiser`` a core.film.denoiser.Denoiser."""
    start = time.perf_counter()
    shape = (film.height, film.width, 3)
    n, na, total, total_a, total_b = film.halves()
    nb = n - na
    albedo, normal = passes.get(ALBEDO), passes.get(NORMAL)
    if prefilter == "ACCURATE":  # the three denoisings share the features: clean them once
        albedo, normal = denoiser.clean_features(albedo, normal, quality)
        prefilter = "NONE"
    noisy = [(sums / np.maximum(count, 1)[:, None]).reshape(shape)
             for sums, count in ((total, n), (total_a, na), (total_b, nb))]
    full, half_a, half_b = (denoiser.denoise(image, albedo, normal, prefilter=prefilter, quality=quality)
                            for image in noisy)
    error = denoised_error(full, half_a, half_b, noisy[1], noisy[2], n, na)
    return Denoised(full, error, time.perf_counter() - start)


def denoised_error(full, half_a, half_b, noisy_a, noisy_b, n, na) -> dict:
    """The estimated error of the denoised image ``full`` (see the module docstring) from its
    halves' denoised and noisy images: ``rmse`` and ``relmse``, and the part that is the noise the
    denoiser leaves, ``rmse_noise`` and ``relmse_noise``. relMSE divides by the true value squared,
    estimated as for the noisy image: the square less the noise, at least TRUE_FLOOR of it. All inf
    while some pixel lacks a sample in one half."""
    n = np.asarray(n, float).reshape(-1)
    na = np.asarray(na, float).reshape(-1)
    nb = n - na
    d, da, db, a, b = (np.asarray(x, float).reshape(-1, 3) for x in (full, half_a, half_b, noisy_a, noisy_b))
    if d.size == 0:
        return {"rmse": 0.0, "relmse": 0.0, "rmse_noise": 0.0, "relmse_noise": 0.0}
    if not ((na > 0) & (nb > 0)).all():
        return {"rmse": math.inf, "relmse": math.inf, "rmse_noise": math.inf, "relmse_noise": math.inf}
    noise = (da - db) ** 2 * (na * nb / n ** 2)[:, None]
    half = 0.5 * ((da - b) ** 2 + (db - a) ** 2 - (a - b) ** 2)
    square = d * d
    weight = 1.0 / (np.maximum(square - noise, TRUE_FLOOR * square) + RELMSE_EPSILON)
    mse_noise, relmse_noise = float(noise.mean()), float((noise * weight).mean())
    mse = max(float((half - noise).mean()), mse_noise)
    relmse = max(float(((half - noise) * weight).mean()), relmse_noise)
    return {"rmse": math.sqrt(mse), "relmse": relmse, "rmse_noise": math.sqrt(mse_noise), "relmse_noise": relmse_noise}
