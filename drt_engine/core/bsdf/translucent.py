"""Translucent lobe: Lambert on the side opposite the shading normal (Cycles' bsdf_translucent in
kernel/closure/bsdf_diffuse.h). A diffuse transmission, which Cycles counts as a transmission
bounce: rays continue through it whatever the diffuse bounces (core.integrator.bounces)."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from .layout import H_COLOUR
from .tables import lobe_scale


@kernel(inline="always")
def translucent_eval(lp, lt, hp, r, j, t, l, wiz):
    """f |cos| RGB toward wi in the lower hemisphere (wiz < 0), weight included."""
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    c = -wiz / np.pi
    return s0 * hp[r, l, H_COLOUR] * c, s1 * hp[r, l, H_COLOUR + 1] * c, s2 * hp[r, l, H_COLOUR + 2] * c
