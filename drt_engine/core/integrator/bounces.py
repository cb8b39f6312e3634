"""Cycles' bounce limits per kind: whether a path may continue through the diffuse reflections at a
hit, and which paths the glossy and transmission limits end.

With diffuse bounces k, a path continues through a diffuse reflection (Lambert, Oren-Nayar, toon,
sheen) while it has taken fewer than k of them (Cycles' path_state_next, whose kernel limit is the
setting + 1: with k = 0 a diffuse surface gets direct light only, DRT's classic image). A
translucent lobe is a diffuse transmission, which Cycles counts as a transmission bounce: it is
sampled as a glossy lobe is, whatever the diffuse bounces (core.bsdf.shader.Lobe.bounces_diffuse).
The answer is the ``diffuse`` flag of core.bsdf.mixture, False where paths carry no depths
(diffuse bounces 0); ``lobe_choice`` fills the lobe choice it allows.

The glossy and transmission limits work as Cycles' path_state_next: every lobe is sampled as
usual, and a bounce that takes the path's glossy (non-diffuse reflection) or transmission depth
(refraction and diffuse transmission alike) past its limit (Cycles' kernel limit, the setting + 1)
ends it at the next hit: that ray still sees emission and the world, the hit gets no direct light
and no further bounce (Cycles' PATH_RAY_TERMINATE_AFTER_TRANSPARENT, which would still let it pass
transparent surfaces; DRT ends it there too). The depths only reach a limit below the Total
(max_depth), so only then do paths carry them for it (``binding``).
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..bsdf.mixture import selection
from ..shading.lightpath import DIFFUSE_DEPTH, GLOSSY_DEPTH, TRANSMISSION_DEPTH


@kernel(inline="always")
def diffuse_left(bounces, j, limit):
    """Whether paths at hit j (depths ``bounces``, core.shading.lightpath) may still continue through
    the diffuse reflections: the mixture's ``diffuse`` flag."""
    if limit <= 0 or len(bounces) == 0:
        return False
    return bounces[j, DIFFUSE_DEPTH] < limit


@kernel(inline="always")
def lobe_choices(lp, n_sampled):
    """Room for ``lobe_choice``: a row over the lobes paths may continue through without the diffuse
    reflections (``n_sampled``; none where only diffuse reflections are: no lobe to read), one over every lobe."""
    return np.empty((1, n_sampled)), np.empty((1, max(lp.shape[0], 1)))


@kernel(inline="always")
def lobe_choice(lp, lt, hp, r, mu, mu_o, choices, bounces, j, limit):
    """(The lobe choice at hit j, filled by core.bsdf.mixture's ``selection``, the ``diffuse_left`` flag
    it was filled with), in one of ``choices`` (``lobe_choices``)."""
    diffuse = diffuse_left(bounces, j, limit)
    sel = choices[1] if diffuse else choices[0]
    selection(lp, lt, hp, r, mu, mu_o, sel, 0, diffuse)
    return sel, diffuse

LIMIT_TRANSPARENCY = ("paths ended by the Glossy or Transmission bounce limit stop at transparent surfaces, "
                      "where Cycles lets them pass on")
"""The warning for a scene with transparent surfaces and a glossy or transmission limit that binds."""


def binding(settings) -> bool:
    """Whether the glossy or transmission limit can end a path before the Total does: a bounce at
    depth d < max_depth makes a depth of at most max_depth."""
    return min(settings.glossy_bounces, settings.transmission_bounces) < settings.max_depth


def ended(bounces, settings):
    """Per path with depths ``bounces`` (core.shading.lightpath): it passed the glossy or the
    transmission limit on its last bounce, so it ends at this hit."""
    return ((bounces[:, GLOSSY_DEPTH] > settings.glossy_bounces)
            | (bounces[:, TRANSMISSION_DEPTH] > settings.transmission_bounces))
