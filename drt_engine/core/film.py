"""Reconstruction filter and per-pixel accumulation.

The filter is importance sampled (as Cycles does): each camera sample's offset from
the pixel centre is drawn from the filter's distribution and the sample counts fully
for its own pixel. Every pixel estimate is then a plain mean of independent-looking
samples, which keeps per-pixel statistics (sample count, standard error) simple.
"""
from __future__ import annotations

import numpy as np

from .settings import PASS_CHANNELS

_TABLE = 1024


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

    def offset(self, u: np.ndarray) -> np.ndarray:
        return np.interp(u, self._cdf, self._x)


class Film:
    """Sums per pixel of the window: samples, Combined RGBA, its squares, other passes."""

    def __init__(self, width: int, height: int, passes: tuple[str, ...]):
        self.width, self.height = width, height
        self.n = width * height
        self.passes = passes
        self.count = np.zeros(self.n)
        self.sums = {name: np.zeros((self.n, len(PASS_CHANNELS[name])))
                     for name in passes if name not in ("Sample Count", "Noise")}
        self.sum_sq = np.zeros((self.n, 3))

    def add(self, pixel: np.ndarray, values: dict[str, np.ndarray]):
        """Accumulate one wave of samples; ``values`` per pass, Combined as (N, 4)."""
        self.count += np.bincount(pixel, minlength=self.n)
        for name, total in self.sums.items():
            v = values[name]
            for c in range(v.shape[1]):
                total[:, c] += np.bincount(pixel, weights=v[:, c], minlength=self.n)
        rgb = values["Combined"][:, :3]
        for c in range(3):
            self.sum_sq[:, c] += np.bincount(pixel, weights=rgb[:, c] * rgb[:, c], minlength=self.n)

    def mean(self, name: str) -> np.ndarray:
        return self.sums[name] / np.maximum(self.count, 1)[:, None]

    def standard_error(self) -> np.ndarray:
        """Per-pixel standard error of the Combined mean, per channel."""
        n = np.maximum(self.count, 1)[:, None]
        mean = self.sums["Combined"][:, :3] / n
        var = np.maximum(self.sum_sq / n - mean * mean, 0.0) * n / np.maximum(n - 1, 1)
        return np.sqrt(var / n)

    def images(self) -> dict[str, np.ndarray]:
        """Each enabled pass as (height, width, channels) float32, rows from the bottom."""
        out = {}
        for name in self.passes:
            if name == "Sample Count":
                img = self.count[:, None]
            elif name == "Noise":
                img = self.standard_error()
            else:
                img = self.mean(name)
            out[name] = np.ascontiguousarray(img.reshape(self.height, self.width, -1), dtype=np.float32)
        return out
