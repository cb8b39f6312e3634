"""Hair lobes in the mixture: each model's constants (``P_HAIR``) and per-hit frame (``H_HAIR``)
read from the packed arrays and handed to its module (core.bsdf.hair, hair_chiang, hair_huang).
Evaluation and sampling are calls, not inlined into the mixture as the other lobes are: the hair
models are large (Huang's quadratures), and inlined they would lengthen the compile of every
kernel that holds the mixture, hair or not; a call costs only the hits that have hair.

A hair closure shades about a strand's tangent, not the surface's normal: on a mesh Cycles takes
the triangle's dPdu (Principled Hair) or dPdv (Hair BSDF), each turned with the face toward the
ray. The binding carries that tangent per hit (world); ``hair_frames`` turns it into the local
frame and derives what each model fixes per hit from it and wo (Cycles' setup).

After a blurry bounce Filter Glossy raises Principled Hair's roughnesses to the hit's ``H_BLUR``
(core.bsdf.blur) as Cycles' bsdf_hair_chiang_blur and bsdf_hair_huang_blur do; the Hair BSDF has
no blur in Cycles."""
from __future__ import annotations

import math

from ..base.jit import kernel
from .hair import hair_eval, hair_sample
from .hair_chiang import chiang_albedo, chiang_blur, chiang_eval, chiang_frame, chiang_sample
from .hair_huang import huang_albedo, huang_eval, huang_frame, huang_sample
from .layout import (H_BLUR, H_COLOUR, H_HAIR, H_HAIR_ALBEDO, H_SIGMA, HAIR_CHIANG, HAIR_HUANG, HAIR_REFLECTION,
                     HAIR_TRANSMISSION, P_HAIR, P_HAIR_CUT, P_KIND)
from .tables import lobe_albedo, lobe_scale


@kernel(inline="always")
def is_hair(kind):
    """One of the hair lobes: they have no side of the surface of their own."""
    return kind == HAIR_REFLECTION or kind == HAIR_TRANSMISSION or kind == HAIR_CHIANG or kind == HAIR_HUANG


@kernel(inline="always")
def files_as_transmission(lp, l):
    """Where Cycles files hair lobe l's light and colour: Hair Transmission under Transmission, every
    other hair lobe (Hair Reflection, Principled Hair) under Glossy, whatever side the light comes
    from (its closure type, CLOSURE_IS_BSDF_TRANSMISSION or _GLOSSY)."""
    return int(lp[l, P_KIND]) == HAIR_TRANSMISSION


@kernel(inline="always")
def has_hair(lp):
    """The mixture has a hair lobe."""
    for l in range(lp.shape[0]):
        if is_hair(int(lp[l, P_KIND])):
            return True
    return False


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
        v, s, m0 = chiang_blur(lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], hp[r, l, H_BLUR])
        return chiang_eval(v, s, m0, lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
                           hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2], hp[r, l, H_HAIR + 6],
                           hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
                           hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5],
                           wox, woy, woz, wix, wiy, wiz)
    if kind == HAIR_HUANG:
        return huang_eval(max(lp[l, P_HAIR], hp[r, l, H_BLUR]), lp[l, P_HAIR + 1], lp[l, P_HAIR + 2],
                          lp[l, P_HAIR + 3], lp[l, P_HAIR + 4], lp[l, P_HAIR + 5], lp[l, P_HAIR + 6],
                          hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2],
                          hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
                          hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5],
                          wox, woy, woz, wix, wiy, wiz)
    p = hair_eval(lp, hp, r, l, kind == HAIR_TRANSMISSION, wox, woy, woz, wix, wiy, wiz)
    return hp[r, l, H_COLOUR] * p, hp[r, l, H_COLOUR + 1] * p, hp[r, l, H_COLOUR + 2] * p, p


@kernel
def hair_lobe_sample(lp, hp, r, l, wox, woy, woz, u_choice, u0, u1):
    """(wi, f |cos| RGB without the weight, pdf, valid, reflect) of hair lobe l as its sample gives them:
    Cycles' rand (u0, u1, u_choice) for Principled Hair, (u0, u1) for the Hair BSDF. Huang's f is
    its sampled path's weight (pdf 1), not its evaluation toward wi; core.bsdf.mixture.sample_lobes
    keeps the sample's own f and pdf, as Cycles does. Last, whether Cycles labels the sample a
    reflection (the Hair BSDF's Reflection, Principled Hair's R lobe) rather than a transmission."""
    kind = int(lp[l, P_KIND])
    if kind == HAIR_CHIANG:
        v, s, m0 = chiang_blur(lp[l, P_HAIR], lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], hp[r, l, H_BLUR])
        wix, wiy, wiz, f0, f1, f2, pdf, reflect = chiang_sample(
            v, s, m0, lp[l, P_HAIR + 3], lp[l, P_HAIR + 4],
            hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2], hp[r, l, H_HAIR + 6],
            hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
            hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5], wox, woy, woz, u0, u1, u_choice)
    elif kind == HAIR_HUANG:
        wix, wiy, wiz, f0, f1, f2, pdf, reflect = huang_sample(
            max(lp[l, P_HAIR], hp[r, l, H_BLUR]), lp[l, P_HAIR + 1], lp[l, P_HAIR + 2], lp[l, P_HAIR + 3],
            lp[l, P_HAIR + 4], lp[l, P_HAIR + 5], lp[l, P_HAIR + 6],
            hp[r, l, H_SIGMA], hp[r, l, H_SIGMA + 1], hp[r, l, H_SIGMA + 2],
            hp[r, l, H_HAIR], hp[r, l, H_HAIR + 1], hp[r, l, H_HAIR + 2],
            hp[r, l, H_HAIR + 3], hp[r, l, H_HAIR + 4], hp[r, l, H_HAIR + 5], wox, woy, woz, u0, u1, u_choice)
    else:
        wix, wiy, wiz, pdf = hair_sample(lp, hp, r, l, kind == HAIR_TRANSMISSION, wox, woy, woz, u0, u1)
        f0, f1, f2 = hp[r, l, H_COLOUR] * pdf, hp[r, l, H_COLOUR + 1] * pdf, hp[r, l, H_COLOUR + 2] * pdf
        reflect = kind == HAIR_REFLECTION
    if not pdf > 0.0:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, False, reflect
    return wix, wiy, wiz, f0, f1, f2, pdf, True, reflect


@kernel
def hair_frames(lp, hp, tangent, ng, n, wo):
    """Fill each hit's hair frame (``H_HAIR``) from its strand tangent (N, L, 3: per lobe, local, as
    Cycles takes it before normalising), its geometric normal facing the ray ``ng``, shading normal
    ``n`` and ``wo`` (N, 3, local): the unit tangent, then for Principled Hair Cycles' frame axis Y
    (Chiang) or X (Huang) and h, the offset across the strand the ray is seen at, then the shading
    normal (Cycles' sd->N, which ``_cut`` compares the closure's normal with); for Principled Hair
    also Cycles' albedo estimate at the hit (``H_HAIR_ALBEDO``, for ``hair_albedo``). (On a mesh
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
            sg0, sg1, sg2 = hp[i, l, H_SIGMA], hp[i, l, H_SIGMA + 1], hp[i, l, H_SIGMA + 2]
            if kind == HAIR_CHIANG:
                yx, yy, yz, h = chiang_frame(x, y, z, ng[i, 0], ng[i, 1], ng[i, 2], wo[i, 0], wo[i, 1], wo[i, 2])
                hp[i, l, H_HAIR + 3], hp[i, l, H_HAIR + 4], hp[i, l, H_HAIR + 5], hp[i, l, H_HAIR + 6] = yx, yy, yz, h
                a0, a1, a2 = chiang_albedo(lp[l, P_HAIR], lp[l, P_HAIR + 4], sg0, sg1, sg2, h, x, y, z,
                                           wo[i, 0], wo[i, 1], wo[i, 2])
                hp[i, l, H_HAIR_ALBEDO], hp[i, l, H_HAIR_ALBEDO + 1], hp[i, l, H_HAIR_ALBEDO + 2] = a0, a1, a2
            elif kind == HAIR_HUANG:
                frame = huang_frame(x, y, z, n[i, 0], n[i, 1], n[i, 2], wo[i, 0], wo[i, 1], wo[i, 2])
                for k in range(7):
                    hp[i, l, H_HAIR + k] = frame[k]
                a0, a1, a2 = huang_albedo(lp[l, P_HAIR + 2], sg0, sg1, sg2, frame[0], frame[1], frame[2], frame[3],
                                          frame[4], frame[5], frame[6], wo[i, 0], wo[i, 1], wo[i, 2])
                hp[i, l, H_HAIR_ALBEDO], hp[i, l, H_HAIR_ALBEDO + 1], hp[i, l, H_HAIR_ALBEDO + 2] = a0, a1, a2
            hp[i, l, H_HAIR + 7], hp[i, l, H_HAIR + 8], hp[i, l, H_HAIR + 9] = n[i, 0], n[i, 1], n[i, 2]


@kernel(inline="always")
def hair_albedo(lp, lt, hp, r, j, t, l):
    """Cycles' bsdf_albedo of hair lobe l with its weight, RGB, as its passes show it (GlossCol or
    TransCol, the denoising albedo): the Hair BSDF's is its weight, Principled Hair's its weight
    times its model's estimate at the hit (``hair_frames``). The estimate is of the unblurred
    lobe: the passes read first hits, and a hit after a blurry bounce is no longer
    specular enough to wait for the denoising albedo (core.bsdf.passes)."""
    kind = int(lp[l, P_KIND])
    if kind == HAIR_CHIANG or kind == HAIR_HUANG:
        s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
        return s0 * hp[r, l, H_HAIR_ALBEDO], s1 * hp[r, l, H_HAIR_ALBEDO + 1], s2 * hp[r, l, H_HAIR_ALBEDO + 2]
    return lobe_albedo(lp, lt, hp, r, j, t, l)
