"""Multiple importance sampling: the power heuristic, and the one path by which emission that a
BSDF-sampled ray finds reaches the image, whatever the emitter (lights hit, the world, suns,
emissive triangles), as Mitsuba's path integrator has it."""
from __future__ import annotations

import math

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from .clamp import UNCLAMPED, clamp_rows


@kernel(inline="always")
def power(a, b):
    """Power heuristic weight of strategy a against b (densities per solid angle; a = inf: delta)."""
    if math.isinf(a):
        return 1.0
    a2 = a * a
    return a2 / max(a2 + b * b, TINY)


@kernel
def power_heuristic(a, b):
    """``power`` over arrays of densities."""
    out = np.empty(len(a))
    for i in range(len(a)):
        out[i] = power(a[i], b[i])
    return out


def add_emitted(out, path, throughput, emitted, prev_pdf, light_pdf, limit=UNCLAMPED, group=None):
    """Emission a BSDF-sampled ray found, any emitter: weighted by the power heuristic against
    light sampling where both could have produced the direction (``light_pdf(rows)``, the
    light-sampling density of those rows' directions; None if light sampling never picks this
    emitter; camera rays and delta lobes, prev_pdf = inf, take it whole). Adds it to the wave's
    radiance and denoising features (``out``, the wave's WaveOutput) and returns throughput x
    weighted emission, each row clamped to its ``limit`` (core.integrator.clamp.row_limits),
    also added to each row's light group column ``group`` of ``out.grouped`` (-1: none;
    core.integrator.lightgroups)."""
    weight = np.ones(len(path))
    smooth = np.flatnonzero(~np.isinf(prev_pdf))
    if len(smooth) and light_pdf is not None:
        weight[smooth] = power_heuristic(prev_pdf[smooth], light_pdf(smooth))
    e = throughput * emitted * weight[:, None]
    e = clamp_rows(e, limit)
    out.radiance[path] += e
    if group is not None and out.grouped is not None:
        rows = np.flatnonzero(group >= 0)
        out.grouped[path[rows], group[rows]] += e[rows]
    if out.features is not None:
        out.features.emitted(path, emitted * weight[:, None])
    return e
