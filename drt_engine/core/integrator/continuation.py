"""Paths continued through one lobe, for a shader's hits in one kernel call: the lobe (non-diffuse,
or diffuse where diffuse bounces let the path, integrator.bounces) chosen by its albedo and
sampled (core.bsdf.mixture), the new throughput, the direction in the
world, the check that it leaves through the side of the geometric surface the lobe says, the
next ray's origin pushed off the surface, and (when a shader program reads Light Path) the path's
ray kind and depths after the bounce."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..bsdf.bump_shadowing import smooth_local
from ..bsdf.hair_lobes import files_as_transmission
from ..bsdf.mixture import UNLIT_REFLECTION, UNLIT_TRANSMISSION, sample_lobes, side_of
from ..geometry.accel import spawn_point
from ..shading.lightpath import DEPTH, DIFFUSE, DIFFUSE_DEPTH, GLOSSY, GLOSSY_DEPTH, KIND, REFLECT, SINGULAR
from ..shading.lightpath import TRANSMISSION_DEPTH, TRANSMIT, TRANSPARENT_DEPTH
from .bounces import lobe_choice, lobe_choices
from .lightpasses import eval_parts, other_parts, share
from .world_lobes import COSINE, world_density


@kernel
def continue_paths(lp, lt, hp, prow, mu, n_sampled, frame, smooth, dn, wo_l, inside, u_select, u2, throughput, pos, ng,
                   scale, bounces, diffuse_limit, u_roulette, min_bounces, go, origin, wi, weight, prev_pdf,
                   passthrough, transmit, next_bounces, diffuse, first, shares, chance, world_pdf):
    """Per hit j: ``go[j]`` whether its path goes on; where it does, the next ray's ``origin`` and
    world direction ``wi``, the path's new throughput ``weight``, the density that sampled the
    direction (``prev_pdf``, inf for a delta lobe), whether the transparent lobe was taken, whether
    the ray crosses the surface and, when ``bounces`` has rows (core.shading.lightpath's kind and
    depths of the paths), ``next_bounces``: as Cycles' path_state_next, a transparent lobe keeps
    the kind and counts a transparent bounce; any other sets reflection or transmission, glossy,
    and singular for a delta lobe, and counts a bounce and a glossy (reflected) or transmission
    one; a diffuse lobe (allowed by ``diffuse_limit``, the diffuse bounces, on paths that carry
    their depths) sets reflection or transmission and diffuse, and counts a bounce and a diffuse
    (reflected) or transmission one; ``diffuse[j]``: a diffuse lobe was taken. With
    ``min_bounces`` (bounces, transparent bounces; -1: no roulette) a path past them goes on with
    Cycles' probability p = min(sqrt(max throughput), 1) (``roulette``), decided by ``u_roulette[j]``
    and applied where Cycles applies it, at the next hit (integrator_intersect_terminate): the ray
    still goes and what it finds (lights, world, emission) counts at the undivided ``weight``;
    ``chance[j]`` is p for a path that survives (its hit divides the throughput by it before direct
    light and the next bounce), 0 for one that ends at that hit; 1 without roulette.
    Where ``world_pdf`` has rows (a world that does not vary), ``world_pdf[j]`` the density its
    light sample has toward the new direction (core.integrator.world_lobes).
    Where ``first[j]`` (empty: no light passes) and the path bounces (not through a transparent
    lobe), ``shares[j]`` its light passes' weights (core.integrator.lightpasses, ``pass_shares``): the
    diffuse lobes' and the other lobes' reflection's shares of the BSDF toward the new direction
    (Cycles' bsdf_eval_pass_*_weight), a delta lobe's whole by its side.
    Shader and hits as core.integrator.direct has them."""
    choices = lobe_choices(lp, n_sampled)
    sel_world = np.empty((1, max(lp.shape[0], 1)))
    for j in range(len(wo_l)):
        sel, diffuse_on = lobe_choice(lp, lt, hp, prow[j], mu, wo_l[j, 2], choices, bounces, j, diffuse_limit)
        sx, sy, sz, model = smooth_local(smooth, frame, j)
        s = sample_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], u_select[j], u2[j, 0], u2[j, 1],
                         inside[j], sel, 0, diffuse_on, sx, sy, sz, model, dn[j, 0], dn[j, 1], dn[j, 2])
        t0, t1, t2 = throughput[j, 0] * s[3], throughput[j, 1] * s[4], throughput[j, 2] * s[5]
        peak = np.maximum(np.maximum(t0, t1), t2)
        go[j] = False
        if not (s[8] and peak > 0):
            continue
        x, y, z = s[0], s[1], s[2]
        wx = x * frame[j, 0, 0] + y * frame[j, 1, 0] + z * frame[j, 2, 0]
        wy = x * frame[j, 0, 1] + y * frame[j, 1, 1] + z * frame[j, 2, 1]
        wz = x * frame[j, 0, 2] + y * frame[j, 1, 2] + z * frame[j, 2, 2]
        # a sampled direction on the wrong side of the geometric surface would leak light
        crosses = s[11]
        if (wx * ng[j, 0] + wy * ng[j, 1] + wz * ng[j, 2] < 0) != crosses:
            continue
        chance[j] = 1.0
        if min_bounces[0] >= 0 and len(bounces):
            p = roulette(bounces, j, s[9], peak, min_bounces)
            chance[j] = p if u_roulette[j] < p else 0.0
        go[j] = True
        origin[j, 0], origin[j, 1], origin[j, 2] = spawn_point(pos[j, 0], pos[j, 1], pos[j, 2], ng[j, 0], ng[j, 1],
                                                               ng[j, 2], wx, wy, wz, scale[j])
        wi[j, 0], wi[j, 1], wi[j, 2] = wx, wy, wz
        weight[j, 0], weight[j, 1], weight[j, 2] = t0, t1, t2
        prev_pdf[j] = np.inf if s[7] else s[6]
        passthrough[j], transmit[j], diffuse[j] = s[9], crosses, s[10]
        if len(world_pdf):
            world_pdf[j] = COSINE if s[7] else world_density(
                lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], x, y, z,
                side_of(z, crosses, s[10], dn[j, 0], dn[j, 1]), inside[j], sel_world, sx, sy, sz, model, dn[j, 0],
                dn[j, 1], dn[j, 2])
        if len(first) and first[j] and not s[9]:
            pass_shares(lp, lt, hp, prow[j], mu, wo_l, j, x, y, z, crosses, s[7], side_of(z, crosses, s[10], dn[j, 0],
                        dn[j, 1]), inside[j], sel, diffuse_on, sx, sy, sz, model, dn[j, 0], dn[j, 1], dn[j, 2],
                        s[12], s[13], s[14], s[15], shares)
        if len(bounces):
            next_bounces[j] = bounces[j]
            if s[9]:
                next_bounces[j, TRANSPARENT_DEPTH] += 1
            elif s[10]:
                next_bounces[j, KIND] = (TRANSMIT if crosses else REFLECT) | DIFFUSE
                next_bounces[j, DEPTH] += 1
                next_bounces[j, TRANSMISSION_DEPTH if crosses else DIFFUSE_DEPTH] += 1
            else:  # a hair lobe's by its sample's label (s[16]), not by the side it leaves by
                next_bounces[j, KIND] = (TRANSMIT if s[16] else REFLECT) | GLOSSY | (SINGULAR if s[7] else 0)
                next_bounces[j, DEPTH] += 1
                next_bounces[j, TRANSMISSION_DEPTH if s[16] else GLOSSY_DEPTH] += 1


@kernel(inline="always")
def pass_shares(lp, lt, hp, r, mu, wo_l, j, x, y, z, crosses, delta, above, inside, sel, diffuse, sx, sy, sz, model, dx, dy,
                dz, own, o0, o1, o2, shares):
    """``shares[j]``: the diffuse, glossy and transmission weights of a path continued toward local
    (x, y, z) (on the side ``above`` as the sampling weighed it, core.bsdf.mixture.side_of; the
    diffuse lobes' normal (dx, dy, dz)).
    Rows 0-2, for what the path brings from further on (Indirect): the shares of the whole mixture's
    BSDF there, the diffuse lobes no ray continues through (no diffuse bounce left) included, as
    Cycles' bsdf_eval of a sampled direction sums every closure (closure MIS). Rows 3-5, for the
    emission this ray finds (Direct): the shares of the lobes it continues through, the BSDF its MIS
    weighs against light sampling (the other diffuse lobes' direct light is light sampling's alone,
    core.integrator.direct): Cycles' Direct passes hold each kind's own direct light. Each share is
    its own parts' evaluation, exactly 0 for a kind the BSDF has none of there (not what the others
    leave of 1: that rounding would fill a pass nothing lights). A sampled hair lobe ``own`` (-1:
    none) counts with its sample's own value (o0, o1, o2), as the path's weight does
    (core.bsdf.mixture.sample_lobes), filed by its closure."""
    for i in range(6):
        for c in range(3):
            shares[j, i, c] = 0.0
    if delta:  # a mirror or glass's sharp reflection is glossy, its refraction transmission
        for c in range(3):
            shares[j, 2 if crosses else 1, c] = shares[j, 5 if crosses else 4, c] = 1.0
        return
    # np.int64(0), not the literal 0: a literal argument would compile eval_parts a second time
    f = eval_parts(lp, lt, hp, r, mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], x, y, z, above, inside, sel, diffuse,
                   np.int64(0), sx, sy, sz, model, dx, dy, dz, own)
    fd = eval_parts(lp, lt, hp, r, mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], x, y, z, above, inside, sel, diffuse,
                    UNLIT_REFLECTION | UNLIT_TRANSMISSION, sx, sy, sz, model, dx, dy, dz, own)
    # the other lobes' glossy and transmission parts, the sampled hair lobe's by its closure
    fo = other_parts(lp, lt, hp, r, mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], x, y, z, above, inside, sel, diffuse,
                     np.int64(0), sx, sy, sz, model, dx, dy, dz, own)
    g0, g1, g2, t0, t1, t2 = fo
    if own >= 0:
        if files_as_transmission(lp, own):
            t0, t1, t2 = t0 + o0, t1 + o1, t2 + o2
        else:
            g0, g1, g2 = g0 + o0, g1 + o1, g2 + o2
    _channel_shares(shares, j, 0, fd[0] + fd[3], fd[3], g0, t0, f[0] + f[3] + o0, f[3] + o0)
    _channel_shares(shares, j, 1, fd[1] + fd[4], fd[4], g1, t1, f[1] + f[4] + o1, f[4] + o1)
    _channel_shares(shares, j, 2, fd[2] + fd[5], fd[5], g2, t2, f[2] + f[5] + o2, f[5] + o2)


@kernel(inline="always")
def _channel_shares(shares, j, c, diffuse, diffuse_continued, glossy, transmission, whole, continued):
    """One channel of ``pass_shares``: each kind's part of the ``whole`` BSDF (Indirect rows) and of
    the ``continued`` lobes' (Direct rows; the diffuse part of those is ``diffuse_continued``)."""
    shares[j, 0, c] = share(diffuse, whole)
    shares[j, 1, c] = share(glossy, whole)
    shares[j, 2, c] = share(transmission, whole)
    shares[j, 3, c] = share(diffuse_continued, continued)
    shares[j, 4, c] = share(glossy, continued)
    shares[j, 5, c] = share(transmission, continued)


@kernel(inline="always")
def roulette(bounces, j, transparent, peak, min_bounces):
    """The probability that path j goes on after this bounce (Cycles'
    path_state_continuation_probability): 1 while its bounces (transparent ones through a
    transparent lobe) are at most the minimum + 1 (Cycles' kernel limit: the setting + 1),
    min(sqrt(largest channel of the throughput), 1) after."""
    if transparent:
        if bounces[j, TRANSPARENT_DEPTH] + 1 <= min_bounces[1] + 1:
            return 1.0
    elif bounces[j, DEPTH] + 1 <= min_bounces[0] + 1:
        return 1.0
    return min(np.sqrt(peak), 1.0)
