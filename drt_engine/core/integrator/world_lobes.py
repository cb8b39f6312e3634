"""A world that does not vary, light-sampled from the hit's diffuse-type lobes.

Its radiance is one constant, so the density that leaves its light sample least noise is the
BSDF's own. Where a hit has diffuse-type lobes (Lambert, Oren-Nayar, toon, sheen, translucent:
without diffuse bounces no ray continues through the reflections among them, whose world light is
then light sampling's alone), the world's sample is drawn from their mixture by albedo rather than
cosine-weighted about the normal: a sheen's light then has the variance of its own LTC sample,
as Cycles' BSDF rays find it (Cycles leaves such a world out of light sampling). Where the hit
has none, or only Lambert and Oren-Nayar lobes (their mixture is the very cosine about the same
normal: drawing it again would cost and change nothing), and at the last depth (where every lobe,
glossy ones too, is lit by this sample alone), the cosine sample lights.strategies drew stays. A
bounce records the same mixture's density toward the ray it sends (``world_density``): an
escaping ray is weighed against it.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..bsdf.bump_shadowing import smooth_local
from ..bsdf.layout import DIFFUSE, OREN_NAYAR, P_KIND
from ..bsdf.mixture import diffuse_selection, eval_lobes, sample_lobes

COSINE = -1.0
"""``world_density`` where the world's sample is lights.world's cosine about the shading normal."""

OWN_SAMPLES = ("translucent", "toon_diffuse", "sheen")
"""The diffuse-type lobe kinds (core.bsdf.shader's) not sampled by the cosine above the normal."""


def draws_from(shader) -> bool:
    """Whether the world's sample may be drawn from ``shader``'s lobes: one of them samples its own
    way (elsewhere the kernels below would leave every hit's cosine sample, at a cost)."""
    return any(lobe.kind in OWN_SAMPLES for lobe in shader.lobes)


@kernel(inline="always")
def _drawn_from_lobes(lp, lt, hp, r, mu, woz, sel):
    """Fill ``sel`` with the hit's diffuse-type lobe choice (bsdf.mixture.diffuse_selection); whether
    the world's sample is drawn from it: some lobe of it is neither Lambert nor Oren-Nayar."""
    if not diffuse_selection(lp, lt, hp, r, mu, woz, sel, 0):
        return False
    for l in range(lp.shape[0]):
        kind = int(lp[l, P_KIND])
        if sel[0, l] > 0.0 and kind != DIFFUSE and kind != OREN_NAYAR:
            return True
    return False


@kernel
def world_from_lobes(lp, lt, hp, prow, mu, frame, smooth, dn, wo_l, inside, u, k, radiance, wi, value, pdf):
    """The uniform world's sample (of ``radiance``, strategy ``k``) of each hit drawn again from the
    hit's diffuse-type lobes, where they are not the cosine it was drawn from: per hit its direction
    ``wi``, ``value`` (radiance / pdf; 0 where the lobe drew no direction) and ``pdf``, as
    lights.strategies fills strategy k's; ``u`` (N, S, 2, 2) the hits' light sample values (the point, [k, 0], draws the
    direction, the choice, [k, 1, 0], the lobe). Shader and hits as core.integrator.direct has them."""
    sel = np.empty((1, max(lp.shape[0], 1)))
    for j in range(len(wo_l)):
        if not _drawn_from_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 2], sel):
            continue
        sx, sy, sz, model = smooth_local(smooth, frame, j)
        s = sample_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], u[j, k, 1, 0], u[j, k, 0, 0],
                         u[j, k, 0, 1], inside[j], sel, 0, True, sx, sy, sz, model, dn[j, 0], dn[j, 1],
                         dn[j, 2])
        x, y, z = s[0], s[1], s[2]
        wi[j, 0] = x * frame[j, 0, 0] + y * frame[j, 1, 0] + z * frame[j, 2, 0]
        wi[j, 1] = x * frame[j, 0, 1] + y * frame[j, 1, 1] + z * frame[j, 2, 1]
        wi[j, 2] = x * frame[j, 0, 2] + y * frame[j, 1, 2] + z * frame[j, 2, 2]
        p = s[6] if s[8] else 0.0
        pdf[j] = p
        for c in range(3):
            value[j, c] = radiance[c] / p if p > 0.0 else 0.0


@kernel(inline="always")
def world_density(lp, lt, hp, r, mu, wox, woy, woz, x, y, z, above, inside, sel, sx, sy, sz, model, dx, dy, dz):
    """The density ``world_from_lobes`` has toward local (x, y, z) at a hit (on the side ``above``,
    core.bsdf.mixture.side_of), or COSINE where it leaves the world's cosine sample."""
    if not _drawn_from_lobes(lp, lt, hp, r, mu, woz, sel):
        return COSINE
    return eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, x, y, z, above, inside, sel, 0, True, 0, sx, sy, sz,
                      model, dx, dy, dz, -1)[6]
