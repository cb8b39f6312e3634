"""Reconstruction filter, per-pixel accumulation and the error of every pixel's estimate.

The filter is importance sampled (as Cycles does): each camera sample's offset from
the pixel centre is drawn from the filter's distribution and the sample counts fully
for its own pixel, so every pixel estimate is a plain mean of its samples.

Why not the sample variance: stratified and Sobol samples are not independent, and
their mean converges faster than variance/N says (the plain sample variance
overestimates the error several times at a few hundred samples). The film instead
keeps a second sum over class A, half of every pixel's samples, and estimates the
error of the full mean from the difference of the two halves. That is unbiased when
the halves are independent: the renderer makes them two independently scrambled
replicates of the pattern (``replicate`` tells the film which one a wave belongs
to). Cycles instead splits one sequence by sample id (Christensen et al. 2018,
section 10.2.1); its halves are anticorrelated, and here that overestimated the
error of Sobol 1.5 to 2.3 times and of a complete jittered set 4 times, so the id
split is kept only for GRID, which has no randomness to replicate.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..settings import (CRYPTOMATTE_PASSES, FIRST_SAMPLE_PASSES, LIGHT_PASSES, WEIGHTED_PASSES, cryptomatte_passes,
                        pass_channels)
from .cryptomatte import add_slots, ranks, slot_count
from .ratio_sums import FILM_CHANNELS, NDU_CHANNELS, RATIO, resolve
from . import shadow_catcher as catcher

_TABLE = 1024
_BUCKETS = 1 << 14  # uniform cells over u that locate a sample's segment of the filter table
# pixels per block when the passes and the error estimate are read out: each block's float64
# temporaries (about seven of (block, 3)) are 6 MB at this size; at 1 << 20 they were the
# largest part of a 1920x1080 render's own peak memory (339 MB against 161 MB).
_IMAGE_BLOCK = 1 << 18
_ODD_BITS = 0xAAAAAAAA


def _filter_profile(kind: str, width: float, x: np.ndarray) -> np.ndarray:
    """Cycles' filter functions over [-width/2, width/2]."""
    if kind == "BOX":
        return np.ones_like(x)
    if kind == "GAUSSIAN":
        v = x * 6.0 / width
        return np.exp(-2.0 * v * v)
    v = 2.0 * np.pi * (x / width + 0.5)
    return 0.35875 - 0.48829 * np.cos(v) + 0.14128 * np.cos(2 * v) - 0.01168 * np.cos(3 * v)


class PixelFilter:
    """Separable filter sampled through an inverse CDF table.

    As in Cycles, Blackman-Harris spans twice the nominal width (measured: width 1.5
    gives a 3-pixel window), so its default looks as soft as Cycles'.
    """

    def __init__(self, kind: str, width: float):
        self.width = max(float(width), 1e-3) * (2.0 if kind == "BLACKMAN_HARRIS" else 1.0)
        x = np.linspace(-self.width / 2, self.width / 2, _TABLE + 1)
        f = np.maximum(_filter_profile(kind, self.width, x), 0.0)
        cdf = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]))])
        self._cdf = cdf / cdf[-1]
        self._x = x
        self._slope = np.diff(x) / np.diff(self._cdf)
        grid = np.arange(_BUCKETS + 1) / _BUCKETS
        self._first = np.clip(np.searchsorted(self._cdf, grid, side="right") - 1, 0, _TABLE - 1)
        self._steps = int(np.ceil(np.log2(np.diff(self._first).max() + 1)))

    def offset(self, u: np.ndarray) -> np.ndarray:
        """``np.interp(u, cdf, x)``, computed the same way (see ``filter_offset``)."""
        out = np.empty(u.shape)
        _offsets(self.table, u.reshape(-1), out.reshape(-1))
        return out

    @property
    def table(self):
        """What ``filter_offset`` takes before u (flat arrays and the bisection depth)."""
        return self._cdf, self._x, self._slope, self._first, self._steps


@kernel
def filter_offset(cdf, x, slope, first, steps, u):
    """Offset from the pixel centre for the value u: the filter's inverse CDF, interpolated.

    Each u finds its table segment from a uniform grid over u and a few bisection steps
    inside its cell (bisecting all 1024 segments, as np.interp does, cost 9% of a diffuse
    scene's render time in NumPy)."""
    k = min(int(u * _BUCKETS), _BUCKETS - 1)
    lo, hi = first[k], first[k + 1]
    for _ in range(steps):
        mid = (lo + hi + 1) >> 1
        if u >= cdf[mid]:
            lo = mid
        else:
            hi = mid - 1
    return slope[lo] * (u - cdf[lo]) + x[lo]


@kernel
def _offsets(table, u, out):
    cdf, x, slope, first, steps = table
    for i in range(len(u)):
        out[i] = filter_offset(cdf, x, slope, first, steps, u[i])


@kernel
def sample_is_class_a(sample):
    """Cycles' split of sample ids into two classes: odd parity of the odd-position bits.

    Ids 0..4k-1 hold exactly 2k of each class, and each class of a (0, 2)-sequence
    stays stratified, so a half estimate is nearly as good as a full one of half size.
    """
    x = sample & _ODD_BITS
    x ^= x >> 16
    x ^= x >> 8
    x ^= x >> 4
    x ^= x >> 2
    x ^= x >> 1
    return (x & 1) == 1


@kernel
def _splat(pixel, values, total):
    """Add each sample's values to its pixel's sums, in wave order (a fixed order for any
    thread count, so the sums are bit-identical)."""
    for i in range(len(pixel)):
        for c in range(values.shape[1]):
            total[pixel[i], c] += values[i, c]


@kernel
def _splat_first(pixel, sample, values, replicate, total):
    """Set each pixel's value to its first sample's (id 0 of replicate 0, or of the only sequence):
    exactly one sample of a pixel, in whichever wave or part it is traced, so parts still add."""
    for i in range(len(pixel)):
        if sample[i] == 0 and replicate <= 0:
            for c in range(values.shape[1]):
                total[pixel[i], c] += values[i, c]


@kernel
def _splat_counts(pixel, sample, combined, replicate, count, count_a, sum_a):
    """Sample counts, and the count and Combined RGB sums of class A: the samples of replicate 1,
    or (replicate < 0: GRID, nothing to replicate) the class of each sample id."""
    for i in range(len(pixel)):
        p = pixel[i]
        count[p] += 1.0
        if sample_is_class_a(int(sample[i])) if replicate < 0 else replicate == 1:
            count_a[p] += 1.0
            for c in range(3):
                sum_a[p, c] += combined[i, c]


@kernel
def _splat_ratio(pixel, sample, ndu, replicate, total):
    """The ratio estimator's N, D, U (core.integrator.ratio) into the first columns of ``total`` for every
    sample and into the last ones for class A (chosen as ``_splat_counts`` chooses)."""
    k = ndu.shape[1]
    for i in range(len(pixel)):
        p = pixel[i]
        a = sample_is_class_a(int(sample[i])) if replicate < 0 else replicate == 1
        for c in range(k):
            total[p, c] += ndu[i, c]
            if a:
                total[p, k + c] += ndu[i, c]


@kernel
def _splat_class_a(pixel, sample, values, replicate, total):
    """Add the values of class A's samples (chosen as ``_splat_counts`` chooses) to their pixels' sums."""
    for i in range(len(pixel)):
        if sample_is_class_a(int(sample[i])) if replicate < 0 else replicate == 1:
            for c in range(values.shape[1]):
                total[pixel[i], c] += values[i, c]


@kernel
def _extend_range(pixel, combined, lo, hi):
    for i in range(len(pixel)):
        for c in range(3):
            lo[pixel[i], c] = min(lo[pixel[i], c], combined[i, c])
            hi[pixel[i], c] = max(hi[pixel[i], c], combined[i, c])


class Film:
    """Sums per pixel of the window: samples, every pass, and Combined RGB over class A; the
    ``FIRST_SAMPLE_PASSES`` hold only their pixel's first sample, read as it is; the
    ``WEIGHTED_PASSES`` sum one more channel, their weight, and are read over it; the
    ``CRYPTOMATTE_PASSES`` keep (id, weight) slots for ``cryptomatte_levels`` and are read as their
    rank passes (core.film.cryptomatte).

    With ``track_range`` it also keeps each pixel's smallest and largest sample RGB
    (contrast-driven refinement needs them); with ``ratio`` the ratio estimator's sums
    (core.integrator.ratio), and Combined is read resolved: its diffuse direct part of the lights
    with a closed form is U N / D. The passes ``halved`` are also summed over class A (``sums_a``):
    a denoiser guided by them denoises each half with its own half's features (core.render.denoise).
    ``aovs``: the shader AOVs among the passes (``RenderSettings.aovs``).
    """

    def __init__(self, width: int, height: int, passes: tuple[str, ...], track_range: bool = False,
                 ratio: bool = False, halved: tuple[str, ...] = (), aovs: tuple = (), cryptomatte_levels: int = 6):
        self.width, self.height = width, height
        self.n = width * height
        self.passes = passes
        self.cryptomatte_levels = cryptomatte_levels
        slots = 2 * slot_count(cryptomatte_levels)
        self.channels = {name: slots if name in CRYPTOMATTE_PASSES else len(pass_channels(name, aovs))
                         for name in passes}
        self.count = np.zeros(self.n)
        self.sums = {name: np.zeros((self.n, self.channels[name] + (name in WEIGHTED_PASSES)))
                     for name in passes if name not in ("Sample Count", "Noise", catcher.PASS)}
        if ratio:
            self.sums[RATIO] = np.zeros((self.n, FILM_CHANNELS))
        self.count_a = np.zeros(self.n)
        self.sum_a = np.zeros((self.n, 3))
        self.sums_a = {name: np.zeros_like(self.sums[name]) for name in halved}
        self.lo = np.full((self.n, 3), np.inf) if track_range else None
        self.hi = np.full((self.n, 3), -np.inf) if track_range else None

    def add(self, pixel: np.ndarray, values: dict[str, np.ndarray], sample: np.ndarray, replicate=None):
        """Accumulate one wave of camera samples; ``values`` per pass, Combined as (N, 4);
        ``replicate`` the samples' replicate (0 or 1); None splits them by sample id (GRID)."""
        if len(pixel) == 0:
            return
        pixel = pixel if pixel.dtype == np.int64 else pixel.astype(np.int64)
        sample = np.asarray(sample, dtype=np.int64)
        replicate = -1 if replicate is None else int(replicate)
        for name, total in self.sums.items():
            if name == RATIO:
                _splat_ratio(pixel, sample, values[name], replicate, total)
            elif name in FIRST_SAMPLE_PASSES:
                _splat_first(pixel, sample, values[name], replicate, total)
            elif name in CRYPTOMATTE_PASSES:
                add_slots(pixel, values[name], total)
            else:
                _splat(pixel, values[name], total)
        for name, total in self.sums_a.items():
            _splat_class_a(pixel, sample, values[name], replicate, total)
        combined = values["Combined"]
        _splat_counts(pixel, sample, combined, replicate, self.count, self.count_a, self.sum_a)
        if self.lo is not None:
            _extend_range(pixel, combined, self.lo, self.hi)

    @property
    def ratio(self) -> bool:
        return RATIO in self.sums

    def halves(self, span: slice = slice(None)):
        """(count, count A, Combined RGB summed over all samples, over class A, over class B) of
        the pixels ``span``, each read resolved with the ratio estimator: the full image's ratio
        over all its samples, each half's over its own (so the halves stay independent)."""
        n, na = self.count[span], self.count_a[span]
        total, total_a = self.sums["Combined"][span, :3], self.sum_a[span]
        if not self.ratio:
            return n, na, total, total_a, total - total_a
        ndu = self.sums[RATIO][span]
        ndu_a = ndu[:, NDU_CHANNELS:]
        ndu_all = ndu[:, :NDU_CHANNELS]
        return (n, na, resolve(total, ndu_all), resolve(total_a, ndu_a),
                resolve(total - total_a, ndu_all - ndu_a))

    def half_images(self, names) -> tuple[dict, dict]:
        """The ``halved`` passes ``names`` as ``images`` gives them, over class A and over class B:
        ({name: (height, width, channels) float32}, the same of B)."""
        out = ({}, {})
        for name in names:
            images = [np.empty((self.n, self.sums[name].shape[1]), np.float32) for _ in range(2)]
            for span in self.blocks():
                na = self.count_a[span]
                total, total_a = self.sums[name][span], self.sums_a[name][span]
                images[0][span] = total_a / np.maximum(na, 1)[:, None]
                images[1][span] = (total - total_a) / np.maximum(self.count[span] - na, 1)[:, None]
            for half, image in zip(out, images):
                half[name] = image.reshape(self.height, self.width, -1)
        return out

    def rgb(self, span: slice = slice(None)) -> np.ndarray:
        """The Combined RGB mean of the pixels ``span`` (resolved)."""
        n, _, total, _, _ = self.halves(span)
        return total / np.maximum(n, 1)[:, None]

    def variance(self, span: slice = slice(None)) -> np.ndarray:
        """Per-pixel, per-channel estimate of the squared error of the Combined RGB mean
        (see ``_variance``), of every pixel or of the pixels ``span``."""
        return self.rgb_error(span)[1]

    def rgb_error(self, span: slice = slice(None)) -> tuple[np.ndarray, np.ndarray]:
        """(``rgb``, ``variance``) of the pixels ``span``, read once."""
        n, na, total, total_a, total_b = self.halves(span)
        return total / np.maximum(n, 1)[:, None], _variance(n, na, total_a, total_b)

    def blocks(self):
        """Slices covering the film a bounded block of pixels at a time."""
        return [slice(a, a + _IMAGE_BLOCK) for a in range(0, self.n, _IMAGE_BLOCK)]

    def images(self, names=None) -> dict[str, np.ndarray]:
        """Each enabled pass (or those of ``names``) as (height, width, channels) float32, rows
        from the bottom.

        Computed a block of pixels at a time into the float32 result, so no float64 copy
        of a whole pass is ever held (an 8K Combined pass is 1 GB in float64).
        """
        out = {}
        for name in self.passes if names is None else [n for n in self.passes if n in names]:
            if name in CRYPTOMATTE_PASSES:
                out.update(self._cryptomatte_images(name))
                continue
            img = np.empty((self.n, self.channels[name]), np.float32)
            for span in self.blocks():
                img[span] = self._pass_block(name, span)
            out[name] = img.reshape(self.height, self.width, -1)
        return out

    def _cryptomatte_images(self, name: str) -> dict[str, np.ndarray]:
        """Cryptomatte pass ``name`` as its rank passes, (height, width, 4) float32 each."""
        img = np.empty((self.n, self.channels[name]), np.float32)
        for span in self.blocks():
            img[span] = ranks(self.sums[name][span], self.count[span])
        img = img.reshape(self.height, self.width, -1)
        return {rank: img[..., 4 * i:4 * i + 4] for i, rank in enumerate(cryptomatte_passes(name, self.cryptomatte_levels))}

    def _pass_block(self, name: str, span: slice) -> np.ndarray:
        count = self.count[span]
        if name == "Sample Count":
            return count[:, None]
        if name == "Noise":
            mean, var = self.rgb_error(span)
            unknown = ~np.isfinite(var)
            var[unknown] = mean[unknown] ** 2
            return np.sqrt(var)
        if name == catcher.PASS:
            return self._catcher_ratio(span)
        if name in FIRST_SAMPLE_PASSES:
            return self.sums[name][span]
        if name in WEIGHTED_PASSES:  # over the samples that wrote it (its last channel counts them)
            total = self.sums[name][span]
            return total[:, :-1] / np.maximum(total[:, -1:], 1e-12)
        mean = self.sums[name][span] / np.maximum(count, 1)[:, None]
        if name == "Combined" and self.ratio:
            mean[:, :3] = self.rgb(span)
        if name == "Combined" and catcher.MATTE in self.sums:
            return self._catcher_combined(span, mean)
        if name in LIGHT_PASSES:  # read out as Cycles: over its colour pass
            return divide_even_color(mean, self.sums[LIGHT_PASSES[name]][span] / np.maximum(count, 1)[:, None])
        return mean

    def _means(self, name: str, span: slice) -> np.ndarray:
        return self.sums[name][span] / np.maximum(self.count[span], 1)[:, None]

    def _catcher_ratio(self, span: slice, combined=None) -> np.ndarray:
        """The Shadow Catcher pass of the pixels ``span`` (1 without catchers, core.film.shadow_catcher)."""
        if catcher.SPLITS not in self.sums:
            return np.ones((len(self.count[span]), 3))
        if combined is None:
            combined = self._means("Combined", span)
            if self.ratio:
                combined[:, :3] = self.rgb(span)
        return catcher.catcher_ratio(combined, self._means(catcher.MATTE, span), self._means(catcher.PATHS, span),
                                     self.sums[catcher.SPLITS][span, 0])

    def _catcher_combined(self, span: slice, combined: np.ndarray) -> np.ndarray:
        """Combined of the pixels ``span`` as Cycles reads it with catchers in the scene (its matte)."""
        ratio = None if catcher.PASS in self.passes else self._catcher_ratio(span, combined)
        background = self._means(catcher.BACKGROUND, span) if catcher.BACKGROUND in self.sums else None
        return catcher.combined_read(self._means(catcher.MATTE, span), ratio, background)


def divide_even_color(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cycles' safe_divide_even_color over rows (util/color.h): a / b per channel, 0 where b is 0, and
    a channel of b that is 0 takes the others' quotient (their mean where two are left), so that a
    light pass over a colour without, say, blue stays grey rather than turning yellow."""
    b0 = b == 0.0
    q = np.where(b0, 0.0, a / np.where(b0, 1.0, b))
    x, y, z = q[:, 0], q[:, 1], q[:, 2]
    zx, zy, zz = b0[:, 0], b0[:, 1], b0[:, 2]
    out = q.copy()
    out[:, 0] = np.where(zx & zy, z, np.where(zx & zz, y, np.where(zx, 0.5 * (y + z), x)))
    out[:, 1] = np.where(zx & zy, z, np.where(~zx & zy & zz, x, np.where(~zx & zy, 0.5 * (x + z), y)))
    out[:, 2] = np.where(zx & zz, y, np.where(~zx & zy & zz, x, np.where(~zx & ~zy & zz, 0.5 * (x + y), z)))
    return out


def _variance(n, na, total_a, total_b):
    """With n_a samples in class A and n_b in class B, independent halves, the full mean
    (n_a A + n_b B) / n has variance (A - B)^2 n_a n_b / n^2 in expectation (for the ratio
    estimator to first order); pixels without both classes yet get an infinite estimate."""
    nb = n - na
    half_a = total_a / np.maximum(na, 1)[:, None]
    half_b = total_b / np.maximum(nb, 1)[:, None]
    known = (na > 0) & (nb > 0)
    var = (half_a - half_b) ** 2 * (na * nb / np.maximum(n, 1) ** 2)[:, None]
    var[~known] = np.inf
    return var
