"""Lambert lobe: evaluated for light sampling, and sampled (cosine-weighted) only where a path may
continue through diffuse lobes (diffuse bounces > 0): as in Cook's distribution ray tracing (and
Cycles with diffuse bounces 0) no ray continues from it by default."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..base.warps import concentric_disk
from .layout import H_COLOUR
from .tables import lobe_scale


@kernel(inline="always")
def diffuse_eval(lp, lt, hp, r, j, t, l, wiz):
    """f |cos| RGB toward wi in the upper hemisphere, weight included."""
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    c = wiz / np.pi
    return s0 * hp[r, l, H_COLOUR] * c, s1 * hp[r, l, H_COLOUR + 1] * c, s2 * hp[r, l, H_COLOUR + 2] * c


@kernel(inline="always")
def cosine_sample(u0, u1, side):
    """A cosine-weighted direction about +z (side 1) or -z (side -1), and its density |cos| / pi;
    the sampling of every diffuse lobe (Lambert, Oren-Nayar, translucent), whose weight the
    mixture then takes from the evaluation of all lobes."""
    x, y = concentric_disk(u0, u1)
    z = np.sqrt(max(1.0 - x * x - y * y, 0.0))
    return x, y, side * z, z / np.pi
