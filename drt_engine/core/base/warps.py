"""Warps of the unit square onto other domains, shared by the lens, the lights and the lobes."""
from __future__ import annotations

import numpy as np

from .jit import kernel


@kernel(inline="always")
def concentric_disk(u0, u1):
    """Shirley's concentric map of the unit square onto the unit disk (lens, disk lights, cones)."""
    a = 2.0 * u0 - 1.0
    b = 2.0 * u1 - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0
    if abs(a) > abs(b):
        r, phi = a, (np.pi / 4) * (b / a)
    else:
        r, phi = b, np.pi / 2 - (np.pi / 4) * (a / b)
    return r * np.cos(phi), r * np.sin(phi)
