"""Cycles' bump shadowing (closure/bsdf.h bump_shadowing_term): where a bump or normal map tilts
a closure's normal away from the smooth normal, light that the smooth normal sees at a grazing
angle fades out of the diffuse lobes instead of lighting a bumped facet as if it faced the light.
Without it a bumped diffuse floor under a low sun rendered twice as bright as in Cycles.

Two models, as Cycles changed it: Chiang, Li and Burley's "Taming the Shadow Terminator" term
(Cycles 4.2) and Conty Estevez, Lecocq and Stein's microfacet shadowing (Cycles 5), which also
drops every lobe's light from below the smooth surface when it is above the bumped normal. A
material's Bump Map Correction off keeps only the cut-off of each model."""
from __future__ import annotations

import math

from ..base.jit import kernel

CHIANG, GGX = 1, 3
"""The models' codes in the kernels' smooth-normal rows; code + 1 is the model without its smoothing
(Bump Map Correction off), 0 no bump shadowing."""


def model_code(model: str, correction: bool) -> int:
    """The kernels' code of a material's model ("CHIANG" or "GGX", core.scene.Material) and its
    Bump Map Correction."""
    return (CHIANG if model == "CHIANG" else GGX) + (0 if correction else 1)


@kernel(inline="always")
def smooth_local(smooth, frame, j):
    """Hit j's smooth normal (before its bump, facing the ray) in its shading frame and its model
    code; (0, 0, 1) and 0 where no hit has one (``smooth`` empty)."""
    if smooth.shape[0] == 0:
        return 0.0, 0.0, 1.0, 0
    x, y, z = smooth[j, 0], smooth[j, 1], smooth[j, 2]
    return (x * frame[j, 0, 0] + y * frame[j, 0, 1] + z * frame[j, 0, 2],
            x * frame[j, 1, 0] + y * frame[j, 1, 1] + z * frame[j, 1, 2],
            x * frame[j, 2, 0] + y * frame[j, 2, 1] + z * frame[j, 2, 2], int(smooth[j, 3]))


@kernel(inline="always")
def bump_shadowing(sx, sy, sz, model, wix, wiy, wiz):
    """(factor of the diffuse lobes, factor of the others) toward wi (local: z the bumped normal)
    for the smooth normal s and the model code (``model_code``; 0: none)."""
    if model == 0:
        return 1.0, 1.0
    if model <= CHIANG + 1:
        if wiz < 0.0:  # light below the bumped normal (translucent): the smooth normal's back
            sx, sy, sz = -sx, -sy, -sz
        d = wiz * sz
        g = (sx * wix + sy * wiy + sz * wiz) / d if d != 0.0 else 0.0
        if g >= 1.0:
            return 1.0, 1.0
        if g < 0.0:
            return 0.0, 1.0
        if model == CHIANG + 1:
            return 1.0, 1.0
        return g + g * g - g * g * g, 1.0
    cos_si = sx * wix + sy * wiy + sz * wiz
    if cos_si * sz * wiz < 0.0:  # wi and the bumped normal on opposite sides of the smooth surface
        return 0.0, 0.0
    if model == GGX + 1:
        return 1.0, 1.0
    cos_i, cos_d = abs(cos_si), abs(sz)
    if cos_d >= 1.0 or cos_i >= 1.0:
        return 1.0, 1.0
    if cos_i < 1e-6:
        return 0.0, 1.0
    alpha2 = min(max(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0), 1.0)  # GGX roughness from the tilt
    lam = 0.5 * (math.sqrt(1.0 + alpha2 * max(1.0 / (cos_i * cos_i) - 1.0, 0.0)) - 1.0)
    return 1.0 / (1.0 + lam), 1.0


@kernel(inline="always")
def own_normal_shadowing(sx, sy, sz, model, nx, ny, nz, wix, wiy, wiz):
    """The factor of a glossy lobe with its own normal n (a coat's; local) toward wi: Cycles 5 drops
    light on the other side of the smooth surface than n sees it (as ``bump_shadowing`` does for the
    shading normal's lobes), 1 otherwise and under 4.x."""
    if model < GGX:
        return 1.0
    if (sx * wix + sy * wiy + sz * wiz) * (sx * nx + sy * ny + sz * nz) * (nx * wix + ny * wiy + nz * wiz) < 0.0:
        return 0.0
    return 1.0

