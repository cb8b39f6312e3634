"""Lambert lobe. Only evaluated, for light sampling: as in Cook's distribution ray tracing (and
Cycles with diffuse bounces 0) no ray continues from it, so it has no sampling and no pdf."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from .layout import H_COLOUR
from .tables import lobe_scale


@kernel(inline="always")
def diffuse_eval(lp, lt, hp, r, j, t, l, wiz):
    """f |cos| RGB toward wi in the upper hemisphere, weight included."""
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    c = wiz / np.pi
    return s0 * hp[r, l, H_COLOUR] * c, s1 * hp[r, l, H_COLOUR + 1] * c, s2 * hp[r, l, H_COLOUR + 2] * c
