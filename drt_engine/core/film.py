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

from .settings import PASS_CHANNELS

_TABLE = 1024
_BUCKETS = 1 << 14  # uniform cells over u that locate a sample's segment of the filter table
_IMAGE_BLOCK = 1 << 20  # pixels per block when the passes are read out
_ODD_BITS = np.uint32(0xAAAAAAAA)


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
        """``np.interp(u, cdf, x)``, computed the same way, but each u finds its table segment
        from a uniform grid over u and a few bisection steps inside its cell (np.interp bisects
        all 1024 segments: 9% of a diffuse scene's render time)."""
        k = np.minimum((u * _BUCKETS).astype(np.intp), _BUCKETS - 1)
        lo, hi = self._first[k], self._first[k + 1]
        for _ in range(self._steps):
            mid = (lo + hi + 1) >> 1
            up = u >= self._cdf[mid]
            lo, hi = np.where(up, mid, lo), np.where(up, hi, mid - 1)
        return self._slope[lo] * (u - self._cdf[lo]) + self._x[lo]


def sample_is_class_a(sample: np.ndarray) -> np.ndarray:
    """Cycles' split of sample ids into two classes: odd parity of the odd-position bits.

    Ids 0..4k-1 hold exactly 2k of each class, and each class of a (0, 2)-sequence
    stays stratified, so a half estimate is nearly as good as a full one of half size.
    """
    return _popcount_parity(np.asarray(sample, dtype=np.uint32) & _ODD_BITS)


def _popcount_parity(x: np.ndarray) -> np.ndarray:
    x = x ^ (x >> np.uint32(16))
    x = x ^ (x >> np.uint32(8))
    x = x ^ (x >> np.uint32(4))
    x = x ^ (x >> np.uint32(2))
    x = x ^ (x >> np.uint32(1))
    return (x & np.uint32(1)).astype(bool)


class Film:
    """Sums per pixel of the window: samples, every pass, and Combined RGB over class A.

    With ``track_range`` it also keeps each pixel's smallest and largest sample RGB
    (contrast-driven refinement needs them).
    """

    def __init__(self, width: int, height: int, passes: tuple[str, ...], track_range: bool = False):
        self.width, self.height = width, height
        self.n = width * height
        self.passes = passes
        self.count = np.zeros(self.n)
        self.sums = {name: np.zeros((self.n, len(PASS_CHANNELS[name])))
                     for name in passes if name not in ("Sample Count", "Noise")}
        self.count_a = np.zeros(self.n)
        self.sum_a = np.zeros((self.n, 3))
        self.lo = np.full((self.n, 3), np.inf) if track_range else None
        self.hi = np.full((self.n, 3), -np.inf) if track_range else None

    def add(self, pixel: np.ndarray, values: dict[str, np.ndarray], sample: np.ndarray, replicate=None):
        """Accumulate one wave of camera samples; ``values`` per pass, Combined as (N, 4);
        ``replicate`` the samples' replicate (0 or 1), or None to split them by id.

        Sums run over the pixel range the wave touches (a wave of a large image covers a
        band of it), so the cost follows the wave, not the image.
        """
        if len(pixel) == 0:
            return
        lo = int(pixel.min())
        span = slice(lo, int(pixel.max()) + 1)
        m = span.stop - lo
        local = pixel - lo
        self.count[span] += np.bincount(local, minlength=m)
        for name, total in self.sums.items():
            v = values[name]
            for c in range(v.shape[1]):
                total[span, c] += np.bincount(local, weights=v[:, c], minlength=m)
        a = sample_is_class_a(sample) if replicate is None else np.full(len(pixel), replicate == 1)
        la = local[a]
        self.count_a[span] += np.bincount(la, minlength=m)
        rgb = values["Combined"][a, :3]
        for c in range(3):
            self.sum_a[span, c] += np.bincount(la, weights=rgb[:, c], minlength=m)
        if self.lo is not None:
            np.minimum.at(self.lo, pixel, values["Combined"][:, :3])
            np.maximum.at(self.hi, pixel, values["Combined"][:, :3])

    def mean(self, name: str) -> np.ndarray:
        return self.sums[name] / np.maximum(self.count, 1)[:, None]

    def variance(self, span: slice = slice(None)) -> np.ndarray:
        """Per-pixel, per-channel estimate of the squared error of the Combined RGB mean
        (see ``_variance``), of every pixel or of the pixels ``span``."""
        return _variance(self.count[span], self.count_a[span], self.sums["Combined"][span, :3], self.sum_a[span])

    def blocks(self):
        """Slices covering the film a bounded block of pixels at a time."""
        return [slice(a, a + _IMAGE_BLOCK) for a in range(0, self.n, _IMAGE_BLOCK)]

    def images(self) -> dict[str, np.ndarray]:
        """Each enabled pass as (height, width, channels) float32, rows from the bottom.

        Computed a block of pixels at a time into the float32 result, so no float64 copy
        of a whole pass is ever held (an 8K Combined pass is 1 GB in float64).
        """
        out = {}
        for name in self.passes:
            img = np.empty((self.n, len(PASS_CHANNELS[name])), np.float32)
            for span in self.blocks():
                img[span] = self._pass_block(name, span)
            out[name] = img.reshape(self.height, self.width, -1)
        return out

    def _pass_block(self, name: str, span: slice) -> np.ndarray:
        count = self.count[span]
        if name == "Sample Count":
            return count[:, None]
        if name == "Noise":
            return _standard_error(count, self.count_a[span], self.sums["Combined"][span, :3], self.sum_a[span])
        return self.sums[name][span] / np.maximum(count, 1)[:, None]


def _variance(n, na, total, total_a):
    """With n_a samples in class A and n_b in class B, the full mean minus the class A
    mean has variance Var(mean) * n_b / n_a if the halves are independent estimates;
    pixels without both classes yet get an infinite estimate."""
    nb = n - na
    full = total / np.maximum(n, 1)[:, None]
    half = total_a / np.maximum(na, 1)[:, None]
    known = (na > 0) & (nb > 0)
    var = (full - half) ** 2 * (na / np.maximum(nb, 1))[:, None]
    var[~known] = np.inf
    return var


def _standard_error(n, na, total, total_a):
    var = _variance(n, na, total, total_a)
    unknown = ~np.isfinite(var)
    var[unknown] = (total / np.maximum(n, 1)[:, None])[unknown] ** 2
    return np.sqrt(var)
