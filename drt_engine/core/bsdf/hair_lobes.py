"""Hair lobes in the mixture: each model's constants (``P_HAIR``) and per-hit frame (``H_HAIR``)
read from the packed arrays and handed to its module (core.bsdf.hair, hair_chiang, hair_huang).
Evaluation and sampling are calls, not inlined into the mixture as the other lobes are: the hair
models are large (Huang's quadratures), and inlined they would lengthen the compile of every
kernel that holds the mixture, hair or not; a call costs only the hits that have hair.

A hair closure shades about a strand's tangent, not the surface's normal: on a mesh Cycles takes
the triangle's dPdu (Principled Hair) or dPdv (Hair BSDF), each turned with the face toward the
ray. The binding carries that tangent per hit (world); ``hair_frames`` turns it into the local
frame and derives what each model fixes per hit from it and wo (Cycles' setup)."""
from __future__ import annotations

import math

from ..base.jit import kernel
from .hair import hair_eval, hair_sample
from .hair_chiang import chiang_eval, chiang_frame, chiang_sample
from .hair_huang import huang_eval, huang_frame, huang_sample
from .layout import (H_COLOUR, H_HAIR, H_SIGMA, HAIR_CHIANG, HAIR_HUANG, HAIR_REFLECTION, HAIR_TRANSMISSION,
                     P_HAIR, P_HAIR_CUT, P_KIND)


@kernel(inline="always")
def is_hair(kind):
    """One of the hair lobes: they have no side of the surface of their own."""
    return kind == HAIR_REFLECTION or kind == HAIR_TRANSMISSION or kind == HAIR_CHIANG or kind == HAIR_HUANG


@kernel(inline="always")
def own_hair_normal(lp, l):
    """Principled Hair (either model): a closure whose normal is its own frame's axis, not the surface's."""
    kind = int(lp[l, P_KIND])
    return kind == HAIR_CHIANG or kind == HAIR_HUANG


@kernel(inline="always")
def _cut(lp, hp, r, l, wix, wiy, wiz):
    """Cycles 5's bump_shadowing_term on a Principled Hair closure, whose normal (Chiang's Y, Huang's X)
    is not the shading normal Ns: nothing toward wi where Ns . wi, Ns . N and N . wi multiply to
    below 0 (light from across the surface relative to where N points). Cycles 4 has no such cut."""
    if lp[l, P_HAIR_CUT] == 0.0:
        return False
    nx, ny, nz = hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5]
    sx, sy, sz = hp[r, l, H_HAIR + 7], hp[r, l, H_HAIR + 8], hp[r, l, H_HAIR + 9]
    return (sx * wix + sy * wiy + sz * wiz) * (sx * nx + sy * ny + sz * nz) * (nx * wix + ny * wiy + nz * wiz) < 0.0


@kernel
def hair_lobe_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz):
    """f |cos| RGB of hair lobe l toward wi without its weight, and its density (both 0 where Cycles
    5 cuts a Principled Hair's light, ``_cut``)."""
    kind = int(lp[l, P_KIND])
    if own_hair_normal(lp, l) and _cut(lp, hp, r, l, wix, wiy, wiz):
        return 0.0, 0.0, 0.0, 0.0
    if kind == HAIR_CHIANG:
        return chiang_eval(lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
                           hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2], hp[r, l, H_HAIR + 6],
                           hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
                           hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5],
                           wox, woy, woz, wix, wiy, wiz)
    if kind == HAIR_HUANG:
        return huang_eval(lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
                          lp[l, P_HAIR + 5], lp[l, P_HAIR + 6],
                          hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2],
                          hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
                          hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5],
                          wox, woy, woz, wix, wiy, wiz)
    p = hair_eval(lp, hp, r, l, kind == HAIR_TRANSMISSION, wox, woy, woz, wix, wiy, wiz)
    return hp[r, l, H_COLOUR] * p, hp[r, l, H_COLOUR + 1] * p, hp[r, l, H_COLOUR + 2] * p, p


@kernel
def hair_lobe_sample(lp, hp, r, l, wox, woy, woz, u_choice, u0, u1):
    """(wi, f |cos| RGB without the weight, pdf, valid) of hair lobe l as its sample gives them:
    Cycles' rand (u0, u1, u_choice) for Principled Hair, (u0, u1) for the Hair BSDF. Huang's f is
    its sampled path's weight (pdf 1), not its evaluation toward wi; core.bsdf.mixture.sample_lobes
    keeps the sample's own f and pdf, as Cycles does."""
    kind = int(lp[l, P_KIND])
    if kind == HAIR_CHIANG:
        wix, wiy, wiz, f0, f1, f2, pdf, _ = chiang_sample(
            lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
            hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2], hp[r, l, H_HAIR + 6],
            hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
            hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5], wox, woy, woz, u0, u1, u_choice)
    elif kind == HAIR_HUANG:
        wix, wiy, wiz, f0, f1, f2, pdf, _ = huang_sample(
            lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
            lp[l, P_HAIR + 5], lp[l, P_HAIR + 6], hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2],
            hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
            hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5], wox, woy, woz, u0, u1, u_choice)
    else:
        wix, wiy, wiz, pdf = hair_sample(lp, hp, r, l, kind == HAIR_TRANSMISSION, wox, woy, woz, u0, u1)
        f0, f1, f2 = hp[r, l, H_COLOUR] * pdf, hp[r, l, H_COLOUR + 1] * pdf, hp[r, l, H_COLOUR + 2] * pdf
    if not pdf > 0.0:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, False
    return wix, wiy, wiz, f0, f1, f2, pdf, True


@kernel
def hair_frames(lp, hp, tangent, ng, n, wo):
    """Fill each hit's hair frame (``H_HAIR``) from its strand tangent (N, L, 3: per lobe, local, as
    Cycles takes it before normalising), its geometric normal facing the ray ``ng``, shading normal
    ``n`` and ``wo`` (N, 3, local): the unit tangent, then for Principled Hair Cycles' frame axis Y
    (Chiang) or X (Huang) and h, the offset across the strand the ray is seen at, then the shading
    normal (Cycles' sd->N, which ``_cut`` compares the closure's normal with). (On a mesh
    Huang's projected radius is 1 and |h| reaches it only where wo grazes the surface: Cycles'
    transparent stand-in for a hit outside the radius is not made there.)"""
    for i in range(hp.shape[0]):
        for l in range(lp.shape[0]):
            kind = int(lp[l, P_KIND])
            if not is_hair(kind):
                continue
            x, y, z = tangent[i, l, 0], tangent[i, l, 1], tangent[i, l, 2]
            length = math.sqrt(x * x + y * y + z * z)
            if length > 0.0 and math.isfinite(length):
                x, y, z = x / length, y / length, z / length
            else:
                x = y = z = 0.0
            hp[i, l, H_HAIR], hp[i, l, H_HAIR + 1], hp[i, l, H_HAIR + 2] = x, y, z
            if kind == HAIR_CHIANG:
                yx, yy, yz, h = chiang_frame(x, y, z, ng[i, 0], ng[i, 1], ng[i, 2], wo[i, 0], wo[i, 1], wo[i, 2])
                hp[i, l, H_HAIR + 3], hp[i, l, H_HAIR + 4], hp[i, l, H_HAIR + 5], hp[i, l, H_HAIR + 6] = yx, yy, yz, h
            elif kind == HAIR_HUANG:
                frame = huang_frame(x, y, z, n[i, 0], n[i, 1], n[i, 2], wo[i, 0], wo[i, 1], wo[i, 2])
                for k in range(7):
                    hp[i, l, H_HAIR + k] = frame[k]
            hp[i, l, H_HAIR + 7], hp[i, l, H_HAIR + 8], hp[i, l, H_HAIR + 9] = n[i, 0], n[i, 1], n[i, 2]
