"""Denoising a finished render with OpenImageDenoise, and the error of the denoised image.

The film keeps two independent replicate halves of every pixel's samples (core.film.film): noisy
images N_A and N_B of n_A and n_B samples, N their mean over all n. Combined is denoised three
times: D from N, guided by the Denoising Albedo and Normal of all the samples, D_A from N_A and D_B
from N_B, each guided by its own half's albedo and normal (the film sums the features per half when
denoising is on). Features shared by the three would be correlated with both halves: where they are
noisy themselves (defocus and motion blur average many surfaces per pixel) both halves' denoisings
follow the same feature noise, it cancels in D_A - D_B, and on dof_row the estimate read 0.37 to
0.74 of the true error (docs/denoising.md). Two figures come from them, per pixel and channel:

- **the noise the denoiser leaves**, (D_A - D_B)^2 n_A n_B / n^2: the variance of D if that noise
  falls as 1 / samples, as a linear smoother's does (the same form as the noisy image's estimate,
  adaptive.image_error). It cannot see blur of real detail: a texture smoothed flat or a thin
  shadow softened the same way in both halves cancels in D_A - D_B. On the sample scenes it read
  0.4 to 0.8 of the true error (docs/denoising.md);
- **the error of a half's denoised image, blur included**, by cross-validation against the other
  half's noisy image, which is unbiased and independent of it:
  E[(D_A - N_B)^2] = MSE(D_A) + Var(N_B), with Var(N_B) = (N_A - N_B)^2 n_A / n in expectation, so
  MSE of a half ~ ((D_A - N_B)^2 + (D_B - N_A)^2 - (N_A - N_B)^2) / 2.

The estimate of D's squared error is that half's error less the noise of D (a half's bias taken
for D's: D, from twice the samples, is blurred no more than a half, so this leans high), and never
less than the noise alone. What it still cannot see, or sees wrongly:

- bias of the noisy image itself (clamping, the ratio estimator's): N_B is the reference it
  measures against;
- per pixel it is very noisy (a difference of squares of noisy images): only its image mean is
  reported.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..film.denoising import ALBEDO, NORMAL, PASSES as FEATURES
from ..film.film import Film
from ..settings import NOISY_IMAGE, pass_of
from .adaptive import RELMSE_EPSILON, TRUE_FLOOR


@dataclass
class Denoised:
    rgb: np.ndarray  # (h, w, 3) float32, the denoised Combined RGB, rows from the bottom
    error: dict  # estimated rmse and relmse of it, and rmse_noise and relmse_noise (``denoised_error``)
    seconds: float  # the denoisings' time


DENOISED_SHARE = 0.1
"""The denoised / noisy relMSE a render assumes before it has measured its own: below every ratio
measured on the sample scenes (docs/denoising.md), so ``Schedule`` skips no step that could have
met the target unless a scene denoises better still."""


class Schedule:
    """Which steps of a render under a target error are denoised (each costs nine OIDN runs): those
    whose noisy estimate times the denoised / noisy ratio of the last step denoised (DENOISED_SHARE
    before one) is under the target. That ratio grows with the samples (OIDN gains less as the noise
    falls: docs/denoising.md), so the prediction leans low and a step that could meet the target is
    not skipped; the stop itself is always on a denoised estimate (core.render.driver)."""

    def __init__(self, target: float):
        self.target, self.ratio = target, DENOISED_SHARE

    def due(self, relmse_noisy: float) -> bool:
        return relmse_noisy * self.ratio < self.target

    def measured(self, relmse_noisy: float, relmse_denoised: float) -> None:
        if 0 < relmse_noisy < math.inf and relmse_denoised < math.inf:
            self.ratio = relmse_denoised / relmse_noisy


ERROR_BLOCK = 1 << 20
"""Pixels whose error terms are computed at a time: float64 temporaries of a whole 8K image are GBs."""


def denoise_film(film: Film, denoiser, prefilter: str, quality: str) -> Denoised:
    """The denoised Combined image of ``film`` (its Denoising Albedo and Normal passes summed per
    half: Film's ``halved``) and its estimated error; ``denoiser`` a core.film.denoiser.Denoiser or,
    for repeated denoisings, its Filters."""
    start = time.perf_counter()
    shape = (film.height, film.width, 3)
    features = (film.images(FEATURES), *film.half_images(FEATURES))
    noisy = [image.reshape(shape) for image in noisy_images(film)]
    full, half_a, half_b = (denoiser.denoise(image, guide[ALBEDO], guide[NORMAL], prefilter, quality)
                            for image, guide in zip(noisy, features))
    error = denoised_error(full, half_a, half_b, noisy[1], noisy[2], film.count, film.count_a)
    return Denoised(full, error, time.perf_counter() - start)


def figures(denoised: Denoised) -> dict:
    """The denoised image's estimated error as the log, the stats and the report name it."""
    e = denoised.error
    return {"rmse_denoised": e["rmse"], "relmse_denoised": e["relmse"],
            "rmse_denoised_noise": e["rmse_noise"], "relmse_denoised_noise": e["relmse_noise"]}


def denoised_passes(passes: dict, denoised: Denoised, wanted) -> dict:
    """The passes of a denoised render: Combined denoised (alpha as rendered), the image as rendered
    kept as Noisy Image, the features the denoiser read dropped unless ``wanted`` names them."""
    noisy = passes["Combined"]
    combined = noisy.copy()
    combined[..., :3] = denoised.rgb
    out = {name: image for name, image in passes.items() if pass_of(name) in wanted}
    out["Combined"], out[NOISY_IMAGE] = combined, noisy
    return out


def noisy_images(film: Film) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flat (pixels, 3) float32 Combined RGB means of all the samples, of half A and of half B
    (resolved with the ratio estimator, core.film.film.Film.halves), read a block at a time."""
    images = tuple(np.empty((film.n, 3), np.float32) for _ in range(3))
    for span in film.blocks():
        n, na, total, total_a, total_b = film.halves(span)
        for image, sums, count in zip(images, (total, total_a, total_b), (n, na, n - na)):
            image[span] = sums / np.maximum(count, 1)[:, None]
    return images


def denoised_error(full, half_a, half_b, noisy_a, noisy_b, n, na) -> dict:
    """The estimated error of the denoised image ``full`` (see the module docstring) from its
    halves' denoised and noisy images: ``rmse`` and ``relmse``, and the part that is the noise the
    denoiser leaves, ``rmse_noise`` and ``relmse_noise``. relMSE divides by the true value squared,
    estimated as for the noisy image: the square less the noise, at least TRUE_FLOOR of it. All inf
    while some pixel lacks a sample in one half."""
    n = np.asarray(n, float).reshape(-1)
    na = np.asarray(na, float).reshape(-1)
    images = [np.asarray(x).reshape(-1, 3) for x in (full, half_a, half_b, noisy_a, noisy_b)]
    if len(n) == 0:
        return {"rmse": 0.0, "relmse": 0.0, "rmse_noise": 0.0, "relmse_noise": 0.0}
    if not ((na > 0) & (n - na > 0)).all():
        return {"rmse": math.inf, "relmse": math.inf, "rmse_noise": math.inf, "relmse_noise": math.inf}
    sums = np.zeros(4)  # noise, noise / true^2, error, error / true^2
    for a in range(0, len(n), ERROR_BLOCK):
        span = slice(a, a + ERROR_BLOCK)
        noise, error, weight = error_terms(*(image[span] for image in images), n[span], na[span])
        sums += [noise.sum(), (noise * weight).sum(), error.sum(), (error * weight).sum()]
    noise, relmse_noise, mse, relmse = sums / (3 * len(n))
    return {"rmse": math.sqrt(max(mse, noise)), "relmse": max(relmse, relmse_noise),
            "rmse_noise": math.sqrt(noise), "relmse_noise": relmse_noise}


def error_terms(full, half_a, half_b, noisy_a, noisy_b, n, na):
    """Per pixel and channel (flat (pixels, 3) float64): the noise left in the denoised image, its
    squared error (the half's cross-validated error less that noise; unbiased but very noisy per
    pixel), and the relMSE weight 1 / (true value^2 + 0.01) (see ``denoised_error``)."""
    d, da, db, xa, xb = (np.asarray(x, float).reshape(-1, 3) for x in (full, half_a, half_b, noisy_a, noisy_b))
    n, na = np.asarray(n, float).reshape(-1), np.asarray(na, float).reshape(-1)
    noise = (da - db) ** 2 * (na * (n - na) / np.maximum(n, 1) ** 2)[:, None]
    half = 0.5 * ((da - xb) ** 2 + (db - xa) ** 2 - (xa - xb) ** 2)
    square = d * d
    weight = 1.0 / (np.maximum(square - noise, TRUE_FLOOR * square) + RELMSE_EPSILON)
    return noise, half - noise, weight
