"""Choosing which light to sample at a shading point, by estimated contribution.

Apart from the lights themselves (pbrt-v4's light samplers): with very many lights each
next-event slot picks one light per point with probability proportional to its power over
its squared distance (clamped by its size; suns by power alone), with no visibility or
orientation terms, so no light that can contribute is ever given zero probability (the
estimate stays unbiased). The weights are recomputed per point from the light table rather
than stored, so nothing (points x lights) is ever allocated.
"""
from __future__ import annotations

from ..base.jit import kernel
from .table import KIND, PX, PY, PZ, SEL_POWER, SEL_SIZE2, SUN

FLOOR = 1e-12
"""Smallest weight relative to the largest at a point (keeps every light's probability > 0)."""


@kernel(inline="always")
def selection_weight(table, j, px, py, pz):
    if table[j, KIND] == SUN:
        return table[j, SEL_POWER]
    dx, dy, dz = px - table[j, PX], py - table[j, PY], pz - table[j, PZ]
    d2 = max(dx * dx + dy * dy + dz * dz, table[j, SEL_SIZE2] + 1e-12)
    return table[j, SEL_POWER] / d2


@kernel(inline="always")
def _floor_and_total(table, px, py, pz):
    largest = 0.0
    for j in range(table.shape[0]):
        largest = max(largest, selection_weight(table, j, px, py, pz))
    floor = FLOOR * largest + 1e-300
    total = 0.0
    for j in range(table.shape[0]):
        total += max(selection_weight(table, j, px, py, pz), floor)
    return floor, total


@kernel(inline="always")
def pick_probability(table, i, px, py, pz):
    """Chance that one slot picks light i at p."""
    floor, total = _floor_and_total(table, px, py, pz)
    return max(selection_weight(table, i, px, py, pz), floor) / total


@kernel(inline="always")
def pick_light(table, px, py, pz, u):
    """(light index, its probability) for the sample u in [0, 1): inverting the cumulative sum."""
    floor, total = _floor_and_total(table, px, py, pz)
    n = table.shape[0]
    acc = 0.0
    for j in range(n):
        p = max(selection_weight(table, j, px, py, pz), floor) / total
        acc += p
        if u < acc:
            return j, p
    return n - 1, max(selection_weight(table, n - 1, px, py, pz), floor) / total
