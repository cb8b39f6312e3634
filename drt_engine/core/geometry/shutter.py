"""Shutter times of camera samples, as Cycles' camera_sample draws them.

The shutter curve (Render > Motion Blur > Shutter Curve: how open the shutter is over its time)
becomes Cycles' table of shutter times at evenly spaced sample values, the curve's inverse CDF
(scene/camera.cpp: shutter_curve_eval, util_cdf_inverted); a sample value is read from it with
linear interpolation (lookup_table_read). A rolling shutter then moves each row's time: the top
row opens first and the bottom one last.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel

TABLE_SIZE = 256
"""Cycles' SHUTTER_TABLE_SIZE (and the curve's RAMP_TABLE_SIZE samples)."""


def _curve_at(curve: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Cycles' shutter_curve_eval: the curve's samples read at x * size - 1, between neighbours
    (below the first sample, the line through the first two; Cycles reads before its array at x = 0,
    here the first sample)."""
    n = len(curve)
    x = np.clip(x, 0.0, 1.0) * n - 1.0
    index = np.trunc(x).astype(np.int64)
    frac = x - index
    index = np.maximum(index, 0)
    inside = index < n - 1
    nxt = np.minimum(index + 1, n - 1)
    return np.where(inside, curve[index] + frac * (curve[nxt] - curve[index]), curve[n - 1])


def shutter_table(curve: np.ndarray) -> np.ndarray:
    """Shutter times (TABLE_SIZE, 0 to 1) at evenly spaced sample values for the curve's samples
    ``curve`` (at 0 to 1 evenly spaced). A flat curve's times run from 0.002 to 0.994, not 0 to 1."""
    curve = np.asarray(curve, np.float64)
    steps = TABLE_SIZE - 1
    cdf = np.zeros(steps + 1)
    cdf[1:] = np.cumsum(np.abs(_curve_at(curve, np.arange(steps) / (steps - 1))))
    cdf = cdf / cdf[-1] if cdf[-1] > 0.0 else np.zeros_like(cdf)
    cdf[-1] = 1.0
    x = (np.arange(TABLE_SIZE) + 0.5) / TABLE_SIZE
    index = np.searchsorted(cdf, x, side="right") - 1
    last = index >= steps
    below = np.minimum(index, steps - 1)
    t = np.where(last, 0.0, (x - cdf[below]) / np.maximum(cdf[below + 1] - cdf[below], 1e-30))
    return (np.where(last, TABLE_SIZE, index) + t) / TABLE_SIZE


@kernel
def _times(table, rolling, duration, height, u, rows, out):
    n = len(table)
    for i in range(len(u)):
        time = u[i]
        if n:
            x = min(max(time, 0.0), 1.0) * (n - 1)
            k = min(int(x), n - 1)
            t = x - k
            time = (1.0 - t) * table[k] + t * table[min(k + 1, n - 1)]
        if rolling:
            row = 1.0 - rows[i] / height  # 1 at the bottom row: the top is read first
            time = (time - 0.5) * duration + (row - 0.5) * (1.0 - duration) + 0.5 if duration != 0.0 else row
        out[i] = time


def shutter_times(table: np.ndarray | None, rolling: float | None, height: int, u: np.ndarray,
                  rows: np.ndarray) -> np.ndarray:
    """Shutter times (0 to 1) of samples with time values ``u`` in image rows ``rows`` (from the
    bottom, of an image ``height`` rows high): ``u`` itself without a curve or rolling shutter."""
    if table is None and rolling is None:
        return u
    out = np.empty(len(u))
    _times(np.zeros(0) if table is None else np.asarray(table, np.float64), rolling is not None,
           0.0 if rolling is None else float(rolling), float(height), np.asarray(u, np.float64),
           np.asarray(rows, np.float64), out)
    return out
