"""The mixture of a hit's lobes: which lobe a ray continues through, evaluation of them all
toward a direction, and sampling one (with the pdf of the whole mixture).

These scalar functions (``selection``, ``eval_lobes``, ``sample_lobes``) take one ray's numbers
and are what a fused kernel calls; ``rows`` runs them over a wave's arrays. Directions are
local (z the shading normal) with wo above, as in ``shader``, but where a material's Bump Map
Correction is off: there the specular lobes (``needs_wo_above``) give nothing with wo below the
shading normal, as Cycles' microfacet and toon glossy closures need cos(N, wi) > 0.

The scalar functions of the lobe modules are inlined where they are called
(``inline="always"``): a call between compiled functions increments and decrements the
reference count of every array it passes, atomic operations that cost more than a diffuse
lobe's arithmetic (measured here: evaluation and sampling about 1.5 to 2 times slower
without). Microfacet's take only numbers and stay calls (inlining them too added a third to
the compile time and gained nothing measurable). The price is compile time, paid once per
install (the kernels are cached).
"""
from __future__ import annotations

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from . import blur
from .bump_shadowing import bump_shadowing, own_normal_shadowing
from .diffuse import cosine_sample, diffuse_eval
from .diffuse_normal import into, out_of, tilted
from .glass import glass_eval, glass_sample, lobe_eta
from .hair_lobes import files_as_transmission, hair_lobe_eval, hair_lobe_sample, is_hair
from .layout import (DIFFUSE, H_NORMAL, P_KIND, P_OWN_NORMAL, P_SAMPLED, REFLECT, SHEEN, TOON_DIFFUSE,
                     TOON_GLOSSY, TRANSLUCENT, TRANSPARENT)
from .oren_nayar import oren_nayar_eval
from .passes import diffuse_kind
from .reflection import own_reflect_eval, own_reflect_sample, reflect_eval, reflect_sample
from .sheen import sheen_eval, sheen_sample
from .tables import lobe_albedo, lobe_scale, locate, ms_factor
from .toon import toon_cone_sample, toon_diffuse_eval, toon_glossy_eval, toon_glossy_sample
from .translucent import translucent_eval
from .transparent import transparent_sample

UNLIT_DIFFUSE, UNLIT_REFLECTION, UNLIT_TRANSMISSION = 1, 2, 4
"""``eval_lobes``' parts a light does not reach: the diffuse lobes (translucent too, as Cycles
counts it for lights), the others' reflection and their transmission."""


@kernel(inline="always")
def slot(lp, l, diffuse):
    """Lobe l's place in the lobe choice at a hit, -1 where no ray continues through it: where paths
    may continue through the diffuse reflections (``diffuse``, the flag every function here takes
    with the choice), the lobe's own index; where not, P_SAMPLED (every lobe but the diffuse
    reflections, as without diffuse bounces; a translucent's ray is a transmission bounce, taken)."""
    return l if diffuse else int(lp[l, P_SAMPLED])


@kernel(inline="always")
def _by_albedo(lp, lt, hp, r, mu, mu_o, sel, si, diffuse, diffuse_only):
    """Fill the slots (``slot``) of ``sel[si]`` with their lobes' albedos' largest channel (0 for all
    but the diffuse-type lobes, passes.diffuse_kind, where ``diffuse_only``); (their sum, the slots)."""
    j, t = locate(mu, mu_o)
    total = 0.0
    n = 0
    for l in range(lp.shape[0]):
        k = slot(lp, l, diffuse)
        if k < 0:
            continue
        n += 1
        sel[si, k] = 0.0
        if diffuse_only and not diffuse_kind(int(lp[l, P_KIND])):
            continue
        a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
        sel[si, k] = max(max(a0, a1), a2)
        total += sel[si, k]
    return total, n


@kernel(inline="always")
def selection(lp, lt, hp, r, mu, mu_o, sel, si, diffuse):
    """Fill ``sel[si]`` with the probabilities of continuing through each lobe a ray may continue
    through (``slot``): proportional to their albedos' largest channel, uniform when all are black."""
    total, n = _by_albedo(lp, lt, hp, r, mu, mu_o, sel, si, diffuse, False)
    for k in range(n):
        sel[si, k] = sel[si, k] / max(total, TINY) if total > 0.0 else 1.0 / n


@kernel(inline="always")
def diffuse_selection(lp, lt, hp, r, mu, mu_o, sel, si):
    """Fill ``sel[si]`` (a slot per lobe, as ``selection`` with ``diffuse``) with the chance of
    sampling each diffuse-type lobe by its albedo's largest channel, 0 for every other lobe;
    whether any has weight (core.integrator.world_lobes)."""
    total, n = _by_albedo(lp, lt, hp, r, mu, mu_o, sel, si, True, True)
    if not total > 0.0:
        return False
    for l in range(n):
        sel[si, l] = sel[si, l] / total
    return True


@kernel(inline="always")
def needs_wo_above(lp, l, woz):
    """Lobe l (not diffuse) gives nothing toward or from wo (z its cosine to the shading normal): a
    GGX reflection, glass or toon glossy lobe about the shading normal with wo not above it (a hair
    lobe shades about its strand, whatever side wo is on)."""
    kind = int(lp[l, P_KIND])
    return woz <= 0.0 and kind != TRANSPARENT and not (kind == REFLECT and lp[l, P_OWN_NORMAL] != 0.0) \
        and not is_hair(kind)


@kernel(inline="always")
def eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, si, diffuse, unlit,
               sx, sy, sz, model, dx, dy, dz, skip):
    """BSDF times |cos| of every non-delta lobe toward wi, for light sampling.

    ``above``: wi is on wo's side of the surface (light sampling: of Cycles' sd->N, which the diffuse
    lobes have, core.bsdf.diffuse_normal; where that is not the frame's, the diffuse lobes' side is
    their cosine's and ``above`` the others'); ``inside``: wo arrived from the
    back of the surface. ``sel[si]``: the lobe choice (``selection``) at wo, for the ``diffuse``
    lobes a path may continue through (``slot``). ``unlit`` (``UNLIT_*`` bits): parts a light
    does not reach (the world's ray visibility): their BSDF is left out, their density kept, so
    that the rays the lobes send weigh against this light sample as they would. A part is a side
    of the surface, but for the hair lobes, which Cycles files by closure whatever side wi is on:
    Principled Hair and Hair Reflection reflect, Hair Transmission transmits. ``skip``: a lobe
    left out, BSDF and density (the sampled hair lobe whose own value ``sample_lobes`` keeps), -1:
    none. (sx, sy, sz, model): the smooth normal before a bump and its model of shadowing
    (``bump_shadowing``); (dx, dy, dz) the diffuse lobes' normal (core.bsdf.diffuse_normal). Returns (the part
    no ray continues through RGB: the diffuse reflections (Lambert, Oren-Nayar, toon, sheen) left out
    of the choice, the part rays continue through RGB, density of continuing toward wi through
    the lobes of the choice).
    """
    j, t = locate(mu, woz)
    fd0 = fd1 = fd2 = fn0 = fn1 = fn2 = pdf = 0.0
    refl = above and wiz > 0.0
    trans = (not above) and wiz < 0.0
    shade_diffuse, shade = bump_shadowing(sx, sy, sz, model, wix, wiy, wiz)
    cd = dx * wix + dy * wiy + dz * wiz  # wi's cosine to the diffuse lobes' normal
    own = tilted(dx, dy)
    if own and model != 0:  # the diffuse lobes' shadowing about their own normal
        ax, ay, az = into(dx, dy, dz, sx, sy, sz)
        bx, by, bz = into(dx, dy, dz, wix, wiy, wiz)
        shade_diffuse, _ = bump_shadowing(ax, ay, az, model, bx, by, bz)
    lit_part = 0.0 if unlit & (UNLIT_REFLECTION if above else UNLIT_TRANSMISSION) else 1.0
    lit = lit_part * shade
    lit_diffuse = 0.0 if unlit & UNLIT_DIFFUSE else shade_diffuse
    for l in range(lp.shape[0]):
        if blur.delta(lp, hp, r, l):
            continue
        kind = int(lp[l, P_KIND])
        if diffuse_kind(kind):
            p = abs(cd) / np.pi  # cosine-weighted (cosine_sample), but for the toon lobe's cone and sheen's
            if kind == TRANSLUCENT:
                if not (cd < 0.0 if own else not above and cd < 0.0):
                    continue
                d0, d1, d2 = translucent_eval(lp, lt, hp, r, j, t, l, cd)
            elif not (cd > 0.0 if own else above and cd > 0.0):
                continue
            elif kind == DIFFUSE:
                d0, d1, d2 = diffuse_eval(lp, lt, hp, r, j, t, l, cd)
            elif kind == TOON_DIFFUSE:
                d0, d1, d2, p = toon_diffuse_eval(lp, lt, hp, r, j, t, l, cd)
            else:  # sheen and Oren-Nayar see wo and wi about their normal
                ox, oy, oz, ix, iy, iz = wox, woy, woz, wix, wiy, wiz
                if own:
                    ox, oy, oz = into(dx, dy, dz, wox, woy, woz)
                    ix, iy, iz = into(dx, dy, dz, wix, wiy, wiz)
                if kind == SHEEN:
                    d0, d1, d2, p = sheen_eval(lp, lt, hp, r, j, t, l, ox, oy, oz, ix, iy, iz)
                else:
                    d0, d1, d2 = oren_nayar_eval(lp, lt, hp, r, j, t, l, ox, oy, oz, ix, iy, iz)
            d0, d1, d2 = d0 * lit_diffuse, d1 * lit_diffuse, d2 * lit_diffuse
            k = slot(lp, l, diffuse)
            if k >= 0:  # a lobe paths continue through: weighed against sampling it, as the others
                fn0 += d0
                fn1 += d1
                fn2 += d2
                pdf += sel[si, k] * p
                continue
            fd0 += d0
            fd1 += d1
            fd2 += d2
            continue
        if is_hair(kind):
            if l == skip:
                continue
            f0, f1, f2, p = hair_lobe_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
            s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
            seen = 0.0 if unlit & (UNLIT_TRANSMISSION if files_as_transmission(lp, l) else UNLIT_REFLECTION) else shade
            fn0 += s0 * f0 * seen
            fn1 += s1 * f1 * seen
            fn2 += s2 * f2 * seen
            pdf += sel[si, slot(lp, l, diffuse)] * p
            continue
        if needs_wo_above(lp, l, woz):
            continue
        seen = lit
        if kind == REFLECT and lp[l, P_OWN_NORMAL] != 0.0:  # its hemisphere is its own normal's, as Cycles'
            if not above:
                continue
            f0, f1, f2, p = own_reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
            seen = lit_part * own_normal_shadowing(sx, sy, sz, model, hp[r, l, H_NORMAL], hp[r, l, H_NORMAL + 1],
                                                   hp[r, l, H_NORMAL + 2], wix, wiy, wiz)
        elif kind == REFLECT:
            if not refl:
                continue
            f0, f1, f2, p = reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
        elif kind == TOON_GLOSSY:
            if not refl:
                continue
            f0, f1, f2, p = toon_glossy_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
        else:
            f0, f1, f2, p = glass_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz, refl, trans, lobe_eta(lp, l, inside))
            if p == 0.0 and f0 == 0.0 and f1 == 0.0 and f2 == 0.0:
                continue
        s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
        ms = ms_factor(lp, lt, hp, r, j, t, l)
        fn0 += s0 * f0 * ms * seen
        fn1 += s1 * f1 * ms * seen
        fn2 += s2 * f2 * ms * seen
        pdf += sel[si, slot(lp, l, diffuse)] * p
    return fd0, fd1, fd2, fn0, fn1, fn2, pdf



@kernel(inline="always")
def side_of(wiz, crosses, diffuse, dx, dy):
    """The side of the surface ``eval_lobes`` weighs a sampled direction on: the one it leaves by,
    but for a ``diffuse`` lobe's sample about the diffuse lobes' own normal (dx, dy, ...: at a rim),
    whose side for the other lobes is the frame's."""
    if tilted(dx, dy) and diffuse:
        return wiz > 0.0
    return not crosses


@kernel(inline="always")
def sample_lobe(lp, lt, hp, r, j, t, l, wox, woy, woz, u_choice, u0, u1, eta):
    """Sample lobe l alone: (wi, weight f |cos| / pdf of this lobe RGB, valid)."""
    kind = int(lp[l, P_KIND])
    if kind == TRANSPARENT:
        return transparent_sample(hp, r, l, wox, woy, woz)
    if kind == REFLECT and lp[l, P_OWN_NORMAL] != 0.0:
        return own_reflect_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u0, u1)
    if kind == REFLECT:
        return reflect_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u0, u1)
    if kind == TOON_GLOSSY:
        return toon_glossy_sample(lp, hp, r, l, wox, woy, woz, u0, u1)
    return glass_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u_choice, u0, u1, eta)


@kernel(inline="always")
def sample_lobes(lp, lt, hp, r, mu, wox, woy, woz, u_select, u0, u1, inside, sel, si, diffuse,
                 sx, sy, sz, model, dx, dy, dz):
    """Continue through one lobe chosen by ``sel[si]`` (``selection`` at wo with the same
    ``diffuse`` flag): a non-diffuse one, or a diffuse one where the flag lets paths continue through
    (about the diffuse lobes' normal (dx, dy, dz)); (sx, sy, sz, model) the smooth normal as
    ``eval_lobes`` takes it.

    Returns (wi, weight = f |cos| / pdf RGB, pdf (0 for delta), delta, valid, pass-through:
    the transparent lobe was taken, diffuse: a diffuse lobe was, crosses: wi leaves through the
    surface (below the shading normal, but for a reflection about a lobe's own normal), the hair lobe
    sampled (-1: none) and its own f |cos| RGB in the mixture's, which the light passes file by its
    closure, transmits: Cycles' label of the sample, a transmission (``crosses``, but a hair lobe's
    by its sample's lobe)). For non-delta lobes the weight and pdf are those of the whole mixture of the choice
    (one-sample MIS over lobes), as multiple importance sampling with light sampling requires.
    """
    n = sel.shape[1]
    if n == 0:  # nothing to continue through (diffuse reflections only): no sample, and no read past sel
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, False, False, False, -1, 0.0, 0.0, 0.0, False
    count = 0
    acc = 0.0
    for k in range(n):
        acc += sel[si, k]
        if u_select >= acc:
            count += 1
    choice = min(count, n - 1)
    lo = 0.0
    for k in range(choice):
        lo += sel[si, k]
    p_choice = sel[si, choice]
    u_re = min(max((u_select - lo) / max(p_choice, TINY), 0.0), 1.0 - 1e-12)
    j, t = locate(mu, woz)
    l = choice
    if not diffuse:
        l = 0
        while int(lp[l, P_SAMPLED]) != choice:
            l += 1
    kind = int(lp[l, P_KIND])
    reflect = False  # a hair sample's label (hair_lobes.hair_lobe_sample)
    if kind == TOON_DIFFUSE:  # its weight is the mixture's, below, as the other diffuse lobes'
        wix, wiy, wiz = toon_cone_sample(lp, l, dx, dy, dz, u0, u1)
        w0 = w1 = w2 = 1.0
        ok = True
    elif kind == SHEEN:
        ox, oy, oz = into(dx, dy, dz, wox, woy, woz) if tilted(dx, dy) else (wox, woy, woz)
        wix, wiy, wiz = sheen_sample(lp, l, ox, oy, oz, u0, u1)
        ok = wiz > 0.0
        if tilted(dx, dy):
            wix, wiy, wiz = out_of(dx, dy, dz, wix, wiy, wiz)
        w0 = w1 = w2 = 1.0
    elif diffuse_kind(kind):
        wix, wiy, wiz, _ = cosine_sample(u0, u1, -1.0 if kind == TRANSLUCENT else 1.0)
        if tilted(dx, dy):
            wix, wiy, wiz = out_of(dx, dy, dz, wix, wiy, wiz)
        w0 = w1 = w2 = 1.0
        ok = True
    elif is_hair(kind):  # its sample's own value and density, which the mixture keeps (below)
        wix, wiy, wiz, h0, h1, h2, h_pdf, ok, reflect = hair_lobe_sample(lp, hp, r, l, wox, woy, woz, u_re, u0,
                                                                          u1)
        w0, w1, w2 = h0 / max(h_pdf, TINY), h1 / max(h_pdf, TINY), h2 / max(h_pdf, TINY)
    else:
        wix, wiy, wiz, w0, w1, w2, ok = sample_lobe(lp, lt, hp, r, j, t, l, wox, woy, woz, u_re, u0, u1,
                                                    lobe_eta(lp, l, inside))
        ok = ok and not needs_wo_above(lp, l, woz)
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    ms = ms_factor(lp, lt, hp, r, j, t, l)
    p = max(p_choice, TINY)
    w0, w1, w2 = w0 * s0 * ms / p, w1 * s1 * ms / p, w2 * s2 * ms / p
    delta = blur.delta(lp, hp, r, l)
    valid = ok and p_choice > 0.0
    pdf = 0.0
    # a reflection about a lobe's own normal may leave below the shading normal, on wo's side still,
    # and a diffuse one about the diffuse lobes' normal
    if diffuse_kind(kind):
        crosses = kind == TRANSLUCENT if tilted(dx, dy) else wiz < 0.0
    else:
        crosses = wiz < 0.0 and not (kind == REFLECT and lp[l, P_OWN_NORMAL] != 0.0)
    above = side_of(wiz, crosses, diffuse_kind(kind), dx, dy)
    transmits = (not reflect) if is_hair(kind) else crosses
    own, o0, o1, o2 = -1, 0.0, 0.0, 0.0
    if valid and not delta:
        if is_hair(kind):
            own = l
        _, _, _, f0, f1, f2, pdf = eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside,
                                              sel, si, diffuse, 0, sx, sy, sz, model, dx, dy, dz, own)
        if own >= 0:
            # Cycles keeps a sampled hair closure's own value and density in place of its evaluation:
            # the Hair BSDF's ignore the side of the surface wi leaves by, Huang's is its path's
            # weight (its evaluation is a quadrature), and Cycles 5 cuts no sample by Principled
            # Hair's own normal as it cuts their evaluation (hair_lobes.hair_lobe_eval)
            _, shade = bump_shadowing(sx, sy, sz, model, wix, wiy, wiz)
            o0, o1, o2 = s0 * shade * h0, s1 * shade * h1, s2 * shade * h2
            f0, f1, f2 = f0 + o0, f1 + o1, f2 + o2
            pdf += p_choice * h_pdf
        if pdf > 0.0:
            w0, w1, w2 = f0 / max(pdf, TINY), f1 / max(pdf, TINY), f2 / max(pdf, TINY)
        else:
            w0 = w1 = w2 = 0.0
            valid = False
    w0 = w0 if np.isfinite(w0) else 0.0
    w1 = w1 if np.isfinite(w1) else 0.0
    w2 = w2 if np.isfinite(w2) else 0.0
    return wix, wiy, wiz, w0, w1, w2, pdf, delta, valid, kind == TRANSPARENT, diffuse_kind(kind), crosses, own, \
        o0, o1, o2, transmits
