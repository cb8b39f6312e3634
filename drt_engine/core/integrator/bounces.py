"""Which diffuse lobes a path may continue through at a hit: Cycles' diffuse bounce limit.

With diffuse bounces k, a path continues through a diffuse reflection (Lambert, Oren-Nayar)
while it has taken fewer than k of them (Cycles' path_state_next, whose kernel limit is the
setting + 1: with k = 0 a diffuse surface gets direct light only, DRT's classic image). A
translucent lobe is a diffuse transmission, which Cycles counts as a transmission bounce: it is
sampled whenever diffuse bounces are on, within the path's depth. The answer is the
``diffuse`` bits of core.bsdf.mixture, 0 where paths carry no depths (diffuse bounces 0).
"""
from __future__ import annotations

from ..base.jit import kernel
from ..bsdf.layout import SAMPLE_DIFFUSE, SAMPLE_TRANSLUCENT
from ..shading.lightpath import DIFFUSE_DEPTH


@kernel(inline="always")
def diffuse_bits(bounces, j, limit):
    """The mixture's ``diffuse`` bits at hit j of paths with depths ``bounces`` (core.shading.lightpath)."""
    if limit <= 0 or len(bounces) == 0:
        return 0
    if bounces[j, DIFFUSE_DEPTH] < limit:
        return SAMPLE_DIFFUSE | SAMPLE_TRANSLUCENT
    return SAMPLE_TRANSLUCENT
