"""The Embree mask of each ray a path traces, from its kind (core.geometry.visibility): camera
rays (through transparent surfaces too), diffuse and glossy reflections, transmissions of any
lobe, as Cycles' path_state_ray_visibility (for objects, diffuse and glossy are reflections only)."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..geometry.visibility import CAMERA, DIFFUSE, GLOSSY, TRANSMIT
from ..shading import lightpath as lp


@kernel
def ray_masks(straight, kinds, dirs, normal):
    """Per ray its mask bit: ``straight`` camera rays, else by ``kinds`` (the kind bits paths carry,
    core.shading.lightpath), or without them (no ray took a diffuse lobe) by the side of the
    surface's geometric ``normal`` (facing where the ray came from) it leaves to: glossy or transmission."""
    out = np.empty(len(dirs), np.int32)
    for j in range(len(dirs)):
        if straight[j]:
            out[j] = CAMERA
        elif len(kinds):
            k = kinds[j]
            out[j] = TRANSMIT if k & lp.TRANSMIT else DIFFUSE if k & lp.DIFFUSE else GLOSSY
        elif dirs[j, 0] * normal[j, 0] + dirs[j, 1] * normal[j, 1] + dirs[j, 2] * normal[j, 2] >= 0:
            out[j] = GLOSSY
        else:
            out[j] = TRANSMIT
    return out
