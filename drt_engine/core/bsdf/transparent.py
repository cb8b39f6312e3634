"""Transparent lobe: a straight pass-through tinted by its colour, a delta distribution (so no
evaluation and no pdf toward a given direction)."""
from __future__ import annotations

from ..base.jit import kernel
from .layout import H_COLOUR


@kernel(inline="always")
def transparent_sample(hp, r, l, wox, woy, woz):
    """(wi = -wo, weight RGB, valid)."""
    return -wox, -woy, -woz, hp[r, l, H_COLOUR], hp[r, l, H_COLOUR + 1], hp[r, l, H_COLOUR + 2], True
