"""Cycles' Clamp Direct and Clamp Indirect (film_clamp_light): every contribution a sample adds
(emission or world a ray sees, one light strategy's light at a hit, a shadow ray through
transparent surfaces) is scaled down so that the sum of its |RGB| stays within three times the
setting (Cycles' integrator keeps the UI value x 3), one contribution at a time, so one firefly
does not dim the rest of its sample. Direct: what a path adds before its first bounce (Cycles'
bounce 0: the camera ray's emission and world, through transparent surfaces too, and the light
sampled at the hits it reaches); indirect: everything after, a BSDF ray's emission from the first
hit included. A setting of 0 is an infinite limit, which changes no value.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel


def limits(settings) -> tuple[float, float]:
    """(direct, indirect) limits on a contribution's |R| + |G| + |B|."""
    return tuple(3.0 * c if c > 0 else np.inf for c in (settings.sample_clamp_direct, settings.sample_clamp_indirect))


UNCLAMPED = np.zeros(0)
"""The kernels' limits when nothing is clamped: no array per ray (an 8K image's hits are 33M rows)."""


def row_limits(pair, direct: np.ndarray) -> np.ndarray:
    """Per row the limit of its contributions: ``direct`` rows (paths before their first bounce) and
    the rest; ``UNCLAMPED`` when neither limit is finite."""
    if not np.isfinite(pair).any():
        return UNCLAMPED
    return np.where(direct, pair[0], pair[1])


@kernel(inline="always")
def limit_at(limit, j):
    """Row j's limit of ``row_limits``' array (infinite where it is ``UNCLAMPED``)."""
    return limit[j] if limit.shape[0] > 0 else np.inf


@kernel(inline="always")
def clamped(c0, c1, c2, limit):
    """One contribution within ``limit``, and the factor it was scaled by."""
    total = abs(c0) + abs(c1) + abs(c2)
    if total > limit:
        s = limit / total
        return c0 * s, c1 * s, c2 * s, s
    return c0, c1, c2, 1.0


def clamp_rows(e: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """``clamped`` over rows of contributions (N, 3) and ``row_limits``' limits (``UNCLAMPED``: as they are)."""
    if len(limit) == 0:
        return e
    total = np.abs(e).sum(axis=1)
    over = total > limit
    if not over.any():
        return e
    return np.where(over[:, None], e * (limit / np.where(over, total, 1.0))[:, None], e)
