"""When to stop sampling a pixel, and how wrong the image is.

Two modes decide which pixels keep receiving samples after the minimum:

- NOISE, with Cycles' semantics for its settings so they carry over
  (kernel/film/adaptive_sampling.h, scene/integrator.cpp): a pixel converges when the
  sum over RGB of its standard error, divided by sqrt(R+G+B) below 1 and by R+G+B
  above, is under 5 x threshold; threshold 0 means max(0.001, 1 / samples);
  unconverged pixels keep their neighbours sampling (a one-pixel dilation), and a
  converged pixel is tested again at every round. Three things differ from Cycles, all
  for the error of the image: the pixels still sampling do not get one more batch each
  but share a round in proportion to their estimated error per sample (``allocate``),
  since a threshold alone makes every pixel equally noisy, which for the image's mean
  squared error is barely better than sampling all pixels alike; automatic Min Samples
  is chosen for that sharing (``min_samples``); and the first test comes right after
  Min Samples (Cycles waits for the next multiple of 16, its GPU batch).
- CONTRAST, the classic refinement of Mitchell (1987): a pixel keeps sampling while
  the samples in its 3x3 neighbourhood differ, i.e. (max - min) / (max + min) of some
  channel exceeds Mitchell's thresholds (0.4, 0.3, 0.6 for R, G, B). It looks at
  sample values only, not at the error of the mean, so it never calls a pixel done
  because it has enough samples; the cap, time and target error end it.

The error of the whole image comes from the film's per-pixel variance estimate:
RMSE over pixels and RGB channels, and relMSE = mean of variance / (true value^2 + 0.01)
(Rousselle et al. 2011), the same measure the benchmark computes against a reference, with
true value^2 estimated without bias and each pixel's term pooled over its 5x5 neighbourhood
(``image_error``).
"""
from __future__ import annotations

import math

import numpy as np

from ..film.film import Film
from ..sampling.sampler import Sampler, hash_combine

ADAPTIVE_STEP = 16
"""Samples between two convergence tests (Cycles' adaptive_step)."""

THRESHOLD_SCALE = 5.0
"""Cycles multiplies the user's noise threshold by this before testing."""

MIN_ROUND = 1 << 14
"""Fewest camera samples worth a round between two checkpoints. A wave has a fixed cost
(measured on glossy_spheres, 1 thread: 0.07 s for a wave of 1.4k samples, 0.17 s for
22k, so about 0.06 s plus 5 us a sample), so rounds over a small image or a few active
pixels are lengthened until they hold this many samples: tracing stays efficient and
the tests get sparser."""

ROUND_GROWTH = 0.5
"""A NOISE round adds this fraction of the samples traced so far (at least MIN_ROUND): the
rounds grow geometrically, so their fixed costs stay a small share of the render and the
image is tested and logged at every 1.5-fold of its samples."""

DEFENSIVE = 0.25
"""Every pixel's share counts this fraction of the mean spread on top of its own, so a pixel
whose few samples all missed a rare bright path still gains samples (a defensive mixture
with uniform sampling, as in Hesterberg 1995)."""

MITCHELL_CONTRAST = np.array([0.4, 0.3, 0.6])
RELMSE_EPSILON = 1e-2
TRUE_FLOOR = 0.25
"""The relMSE estimate's true value squared is at least this times the pixel's mean squared."""

POOL_RADIUS = 2
"""The relMSE estimate pools each pixel's figure over its 5x5 neighbourhood: the smallest
square reaching past the 3x3 set the convergence test conditions a stop on
(``pooled_relative_error``)."""


def replicate_samplers(pattern: str, cap: int, seed: int) -> list[Sampler] | None:
    """Two independently scrambled samplers of half the samples each (None for GRID).

    A pixel's sample k is sample k // 2 of replicate k % 2, so both replicates grow
    together and each stays a stratified prefix of its own sequence; the two
    replicate means are independent, which makes the film's error estimate unbiased.
    """
    if pattern == "GRID":
        return None
    half = -(-cap // 2)
    return [Sampler(pattern, half, int(hash_combine(*(np.full(1, v) for v in (seed, r, 0x4E91)))[0])) for r in (0, 1)]


def effective_threshold(threshold: float, samples: int) -> float:
    """The user's threshold; 0 means automatic, max(0.001, 1 / samples) as in Cycles."""
    return max(0.001, 1.0 / samples) if threshold == 0 else threshold


AUTO_MIN_SAMPLES = 16
"""Most samples the automatic Min Samples gives every pixel before the first test."""

AUTO_MIN_SHARE = 8
"""... and at most the cap over this: the rest of the budget is the allocation's to share."""


def min_samples(requested: int, cap: int) -> int:
    """Samples every pixel takes before the first test; 0 = automatic, min(16, cap / 8), at least 4.

    Cycles' automatic rule, max(4, ceil(16 / threshold^0.3)), waits for an error estimate good
    enough to stop a pixel at the threshold: 64 samples at the default 0.01, 104 at 0.002, so at
    64 samples adaptive sampling never starts. Sharing the samples (``allocate``) needs less: a
    rough estimate of each pixel's error per sample, which the 3x3 pooling of ``sample_spread``
    steadies from a few samples; every sample spent before the first test is one the allocation
    cannot place. Measured on the sample scenes and a soft-shadow scene (bench/adaptive_study.py).
    """
    if requested == 0:
        return max(4, min(AUTO_MIN_SAMPLES, cap // AUTO_MIN_SHARE))
    return max(4, requested)


def checkpoints(cap: int, first_test: int) -> list[int]:
    """Per-pixel sample counts at which the driver stops to log, test and check the stop rules.

    Doubling up to ``first_test`` (the log gets points early on, and small images get
    large waves), then every ADAPTIVE_STEP up to ``cap``; without adaptive sampling
    ``first_test`` is ``cap`` and the counts simply double.
    """
    first_test = min(first_test, cap)
    points = {first_test, cap}
    points.update(1 << k for k in range(first_test.bit_length()) if 1 << k < first_test)
    points.update(range(first_test + ADAPTIVE_STEP, cap, ADAPTIVE_STEP))
    return sorted(points)


def next_checkpoint(points: list[int], done: int, active: int, first: int) -> int:
    """The checkpoint the next round ends at, from ``done`` samples with ``active`` pixels sampling.

    The next of ``points``, or a later one when ``active`` pixels would take fewer than
    MIN_ROUND samples in all before it; the first test and the last point are never
    passed over.
    """
    later = [p for p in points if p > done]
    for p in later:
        if active * (p - done) >= MIN_ROUND or p == first or p == later[-1]:
            return p
    return points[-1]


def first_test(min_count: int) -> int:
    """Sample count of the first test: right after the minimum (see the module docstring)."""
    return min_count


def dilate(mask: np.ndarray) -> np.ndarray:
    """Grow a (h, w) boolean mask by one pixel in x and then y (Cycles' filter_x / filter_y)."""
    out = mask.copy()
    out[:, 1:] |= mask[:, :-1]
    out[:, :-1] |= mask[:, 1:]
    grown = out.copy()
    out[1:] |= grown[:-1]
    out[:-1] |= grown[1:]
    return out


def box_mean(x: np.ndarray, h: int, w: int, radius: int = 1) -> np.ndarray:
    """Flat per-pixel values averaged over each pixel's (2 radius + 1)^2 neighbourhood (edges
    repeated); a square box is a box along x then one along y."""
    k = 2 * radius + 1
    grid = np.pad(x.reshape(h, w), radius, mode="edge")
    rows = sum(grid[:, d:d + w] for d in range(k))
    return (sum(rows[d:d + h] for d in range(k)) / (k * k)).reshape(-1)


def _rgb_blocks(film: Film):
    """(span, variance of the mean, mean) of the Combined RGB as the image shows it (resolved
    with the ratio estimator), a block of pixels at a time: whole-film float64 temporaries
    of an 8K image are GBs."""
    for span in film.blocks():
        mean, var = film.rgb_error(span)
        yield span, var, mean


def noise_error(film: Film) -> np.ndarray:
    """Cycles' per-pixel error: summed RGB standard error over the tone-aware intensity."""
    out = np.empty(film.n)
    for span, var, mean in _rgb_blocks(film):
        intensity = mean.sum(axis=1)
        normalize = np.where(intensity < 1.0, np.sqrt(np.maximum(intensity, 0.0)), intensity)
        out[span] = np.sqrt(var).sum(axis=1) / (1e-4 + normalize)
    return out


def contrast(film: Film) -> np.ndarray:
    """Mitchell's contrast of the samples in each pixel's 3x3 neighbourhood, per channel / threshold."""
    h, w = film.height, film.width
    lo = film.lo.reshape(h, w, 3)
    hi = film.hi.reshape(h, w, 3)
    lo_pad = np.pad(lo, ((1, 1), (1, 1), (0, 0)), mode="edge")
    hi_pad = np.pad(hi, ((1, 1), (1, 1), (0, 0)), mode="edge")
    lo_n = np.full_like(lo, np.inf)
    hi_n = np.full_like(hi, -np.inf)
    for dy in range(3):
        for dx in range(3):
            lo_n = np.minimum(lo_n, lo_pad[dy:dy + h, dx:dx + w])
            hi_n = np.maximum(hi_n, hi_pad[dy:dy + h, dx:dx + w])
    lo_n = np.maximum(lo_n, 0.0)
    c = (hi_n - lo_n) / np.maximum(hi_n + lo_n, 1e-12)
    return (c / MITCHELL_CONTRAST).max(axis=2).reshape(-1)


def still_active(film: Film, mode: str, threshold: float) -> np.ndarray:
    """Flat boolean mask of the pixels that need more samples, dilated by one pixel."""
    if mode == "CONTRAST":
        need = contrast(film) > 1.0
    else:
        need = ~(noise_error(film) < THRESHOLD_SCALE * threshold)
    return dilate(need.reshape(film.height, film.width)).reshape(-1)


def image_error(film: Film) -> tuple[float, float]:
    """Estimated (RMSE, relMSE) of the Combined RGB image; inf until every pixel has an estimate.

    relMSE divides each squared error by the squared true value (+ 0.01). The pixel's own mean
    squared overestimates that by the error itself (E[mean^2] = true^2 + Var), which made the
    estimate read low where the error is large against the value (highlights: 0.52 of the
    true relMSE at 8 spp on glossy_spheres, 64 px); mean^2 - variance is an unbiased estimate
    of true^2 (with two equal replicate halves, their product), but where one half saw
    nothing it is 0 and one pixel's term explodes (2.2x the true relMSE at 4 spp on
    cornell_box), so it is kept at least TRUE_FLOOR x mean^2: the true value at least half
    the mean.

    Each pixel's relMSE is taken from its POOL_RADIUS neighbourhood (``pooled_relative_error``),
    not from the pixel alone: a pixel adaptive sampling stopped was stopped because its own
    one-degree-of-freedom estimate, and its neighbours', read low, so its own estimate is a
    biased one of the error it keeps.
    """
    if film.n == 0:
        return 0.0, 0.0
    squared = 0.0
    for _, var, _ in _rgb_blocks(film):
        if not np.isfinite(var).all():
            return math.inf, math.inf
        squared += float(var.sum())
    values = 3 * film.n
    relative = float(pooled_relative_error(film).sum())
    return float(np.sqrt(squared / values)), relative / values


def pooled_relative_error(film: Film) -> np.ndarray:
    """Per pixel, the estimated relMSE of its mean summed over RGB, pooled: the mean over its
    POOL_RADIUS neighbourhood of each pixel's variance of the mean / (true value^2 + 0.01),
    weighted by the pixels' sample counts.

    Equal counts (uniform sampling) give equal weights, which keep the image's sum (the
    estimate stays unbiased, up to the repeated edges). While adapting, the weights favour the
    pixels that kept sampling, whose estimates come from fresh samples, over those stopped on
    a low one: the convergence test stops a pixel only when its whole 3x3 neighbourhood (the
    one-pixel dilation) reads converged, so a 3x3 mean is as selected as the pixel itself,
    while 16 of the 25 pixels of a 5x5 lie outside that set.
    """
    r = np.empty(film.n)
    for span, var, mean in _rgb_blocks(film):
        square = mean * mean
        true_square = np.maximum(square - var, TRUE_FLOOR * square)
        r[span] = (var / (true_square + RELMSE_EPSILON)).sum(axis=1) * film.count[span]
    h, w = film.height, film.width
    return box_mean(r, h, w, POOL_RADIUS) / box_mean(film.count, h, w, POOL_RADIUS)


def true_error(image: np.ndarray, reference: np.ndarray, reference_variance=None) -> tuple[float, float]:
    """(RMSE, relMSE) of an RGB image against a reference, less the reference's own variance."""
    d2 = (np.asarray(image, float) - np.asarray(reference, float)) ** 2
    if reference_variance is not None:
        d2 = d2 - np.asarray(reference_variance, float)
    denom = np.asarray(reference, float) ** 2 + RELMSE_EPSILON
    return float(np.sqrt(max(d2.mean(), 0.0))), float(max((d2 / denom).mean(), 0.0))


def sample_spread(film: Film) -> np.ndarray:
    """Per pixel, the relative error of one sample, regularised: the share to give it.

    A pixel's relMSE is r / n with r = n x the estimated variance of its mean over
    (value^2 + 0.01), summed over RGB; the image relMSE is the mean of those, so a given
    number of samples makes it least when pixel i holds samples in proportion to
    sqrt(r_i) (Neyman allocation). r comes from the film's two replicates, one degree
    of freedom a pixel: a low draw would starve a noisy pixel for good (its estimate
    changes only with new samples), so a pixel takes the larger of its own r and the
    mean over its 3x3 neighbourhood, plus the defensive share. Pixels without both
    replicates yet take the largest r seen.
    """
    h, w = film.height, film.width
    r = np.empty(film.n, np.float32)
    for span, var, mean in _rgb_blocks(film):
        r[span] = (var / (mean * mean + RELMSE_EPSILON)).sum(axis=1) * film.count[span]
    known = np.isfinite(r)
    r[~known] = r[known].max() if known.any() else 1.0
    spread = np.sqrt(np.maximum(r, box_mean(r, h, w)))
    return spread + DEFENSIVE * float(spread.mean()) + np.float32(1e-12)


def allocate(film: Film, active: np.ndarray, budget: int, cap: int) -> np.ndarray:
    """Samples each of the ``active`` pixels gets in the next round, about ``budget`` in all.

    Water-filling: the totals are raised toward lambda x sample_spread (no pixel loses
    samples or passes ``cap``), lambda found by bisection so the round holds ``budget``.
    """
    spread = sample_spread(film)[active].astype(np.float64)
    have = film.count[active]
    room = np.maximum(cap - have, 0.0)
    if room.sum() <= budget:
        return room.astype(np.int64)

    def given(lam):
        return np.clip(lam * spread - have, 0.0, room)

    lo, hi = 0.0, float(cap / spread.min())  # at hi every pixel reaches the cap
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if given(mid).sum() < budget else (lo, mid)
    return np.ceil(given(hi)).astype(np.int64)
