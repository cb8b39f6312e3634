"""Per-ray arithmetic of a material's lobes: evaluation, sampling, pdf, lobe choice, colours.

``bsdf.MaterialShader`` packs its lobes once into flat arrays, which these kernels read:
- ``lp`` (L, P): each lobe's constants at the ``P_*`` offsets (kind, roughness, IOR, Fresnel,
  layering, constant weight, ...);
- ``lt`` (L, T, len(mu)): each lobe's albedo tables at the view cosines ``mu``, at the ``T_*`` offsets;
- ``hp`` (M, L, H): what a texture may change per hit (weight scale, colour, tints, Fresnel
  colour), one row for a constant shader and one per hit for a bound one; ray i reads row
  ``hp[prow[i]]`` (``hp`` and the row ``r`` in the scalar functions).

The scalar functions (``eval_lobes``, ``sample_lobes``, ``selection``, ``colours``) take one ray's
numbers and are what a fused kernel calls; the ``*_rows`` loops run them over a wave's arrays.
Directions are local (z the shading normal) with wo above, as in ``bsdf``.

The scalar functions here are inlined where they are called (``inline="always"``): a call
between compiled functions increments and decrements the reference count of every array it
passes, atomic operations that cost more than a diffuse lobe's arithmetic (measured here:
evaluation and sampling about 1.5 to 2 times slower without). Microfacet's take only numbers
and stay calls (inlining them too added a third to the compile time and gained nothing
measurable). The price is compile time, paid once per install (the kernels are cached).
"""
from __future__ import annotations

import numpy as np

from ..base import vectors as vec
from ..base.constants import TINY
from ..base.jit import kernel
from . import microfacet as mf

# lobe kinds and Fresnel kinds
DIFFUSE, REFLECT, GLASS, TRANSPARENT = 0, 1, 2, 3
F_DIELECTRIC, F_F82, F_TINT = 0, 1, 2

# lp: constants per lobe
P_KIND = 0
P_DELTA = 1  # 1: sampled as a delta distribution (see bsdf.Lobe.delta)
P_ALPHA = 2
P_ALPHA_T = 3  # glass: spread of refracted directions
P_ETA = 4  # glass: n_inside / n_outside
P_REFRACT_ONLY = 5
P_FRESNEL = 6  # F_DIELECTRIC (times the colour H_F0), F_F82 (f0 = H_F0), F_TINT (H_F0)
P_ETA_F = 7  # IOR of a dielectric Fresnel
P_F82 = 8  # (3) F82 tint
P_MS = 11  # 1: multiple-scattering compensation
P_E_AVG = 12  # cosine-weighted white albedo (multiscatter)
P_AFFINE = 13  # 1: albedo from the tables of f0 A + B with a per-hit f0 (T_EA, T_EB)
P_LAYERS = 14  # number of layers above (0 to 2)
P_LAYER_TINT = 15  # (2 x 3) tint of each layer term
P_SAMPLED = 21  # index among the lobes a ray continues through, -1 for diffuse
P_WEIGHT = 22  # (3) constant weight
P_A_AVG = 25  # (3) cosine averages of A and B (affine multiscatter)
P_B_AVG = 28
P = 31

# lt: tables per lobe over mu
T_E = 0  # (3) total albedo, for lobe choice
T_LAYER_E = 3  # (3) albedo as Cycles estimates it for layering and GlossCol
T_MS = 6  # multiple-scattering factor
T_UNDER = 7  # (2) max albedo of the layer above, per layer term
T_WHITE = 9  # exact white single-scatter albedo at alpha (delta lobes' masking)
T_EA = 10  # (3) affine albedo parts
T_EB = 13
T_E1 = 16  # white single-scatter albedo of the tables (affine)
T = 17

# hp: per hit
H_SCALE = 0  # (3) weight multiplier
H_COLOUR = 3  # (3) diffuse / transparent colour
H_TINT_R = 6  # (3) glass reflection tint
H_TINT_T = 9  # (3) glass transmission tint
H_F0 = 12  # (3) Fresnel colour
H = 15


@kernel(inline="always")
def locate(mu, x):
    """Where x falls in the table cosines ``mf.MU_TABLE``: (j, t) with x = mu[j] + t (mu[j + 1] - mu[j]),
    held at the ends. Found once per ray; every table of every lobe is then read with ``at``.
    The index comes from the table's two spacings, not a search (a binary search over random
    cosines mispredicts half its steps: it cost more than a diffuse lobe's evaluation)."""
    n = len(mu)
    y = min(max(x, mu[0]), mu[n - 1])
    if y >= mf.MU_SPLIT:
        j = mf.MU_GEOMETRIC - 1 + int((y - mf.MU_SPLIT) * ((mf.MU_LINEAR - 1) / (1.0 - mf.MU_SPLIT)))
    else:
        j = int(np.log(y / mf.MU_GRAZING) * ((mf.MU_GEOMETRIC - 1) / np.log(mf.MU_SPLIT / mf.MU_GRAZING)))
    j = min(max(j, 0), n - 2)
    if mu[j + 1] <= y and j < n - 2:  # rounding of the index near a table point
        j += 1
    elif mu[j] > y and j > 0:
        j -= 1
    return j, (y - mu[j]) / (mu[j + 1] - mu[j])


@kernel(inline="always")
def at(lt, l, k, j, t):
    """Table k of lobe l at the cosine ``locate`` found (linear interpolation)."""
    return lt[l, k, j] + (lt[l, k, j + 1] - lt[l, k, j]) * t


@kernel(inline="always")
def lobe_scale(lp, lt, hp, r, j, t, l):
    """RGB weight of lobe l: constant weight, attenuation by the layers above, per-hit scale."""
    a0 = a1 = a2 = 1.0
    for m in range(int(lp[l, P_LAYERS])):
        att = min(max(1.0 - at(lt, l, T_UNDER + m, j, t), 0.0), 1.0)
        k = P_LAYER_TINT + 3 * m
        a0 *= att * lp[l, k]
        a1 *= att * lp[l, k + 1]
        a2 *= att * lp[l, k + 2]
    return (lp[l, P_WEIGHT] * a0 * hp[r, l, H_SCALE], lp[l, P_WEIGHT + 1] * a1 * hp[r, l, H_SCALE + 1],
            lp[l, P_WEIGHT + 2] * a2 * hp[r, l, H_SCALE + 2])


@kernel(inline="always")
def affine_albedo(lp, lt, hp, r, j, t, l):
    """(single-scatter albedo RGB, multiple-scattering factor) of a lobe whose Fresnel is
    f0 A + B for the per-hit colour f0."""
    e0 = hp[r, l, H_F0] * at(lt, l, T_EA, j, t) + at(lt, l, T_EB, j, t)
    e1 = hp[r, l, H_F0 + 1] * at(lt, l, T_EA + 1, j, t) + at(lt, l, T_EB + 1, j, t)
    e2 = hp[r, l, H_F0 + 2] * at(lt, l, T_EA + 2, j, t) + at(lt, l, T_EB + 2, j, t)
    if lp[l, P_MS] == 0.0:
        return e0, e1, e2, 1.0
    f_avg = ((hp[r, l, H_F0] * lp[l, P_A_AVG] + lp[l, P_B_AVG])
             + (hp[r, l, H_F0 + 1] * lp[l, P_A_AVG + 1] + lp[l, P_B_AVG + 1])
             + (hp[r, l, H_F0 + 2] * lp[l, P_A_AVG + 2] + lp[l, P_B_AVG + 2])) / 3.0
    e_avg = lp[l, P_E_AVG]
    f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
    e_w = at(lt, l, T_E1, j, t)
    return e0, e1, e2, 1.0 + f_ms * (1.0 - e_w) / max(e_w, 1e-3)


@kernel(inline="always")
def ms_factor(lp, lt, hp, r, j, t, l):
    """Multiple-scattering compensation of lobe l's single-scatter f (1: none)."""
    if lp[l, P_AFFINE] != 0.0:
        return affine_albedo(lp, lt, hp, r, j, t, l)[3]
    if lp[l, P_MS] != 0.0:
        return at(lt, l, T_MS, j, t)
    return 1.0


@kernel(inline="always")
def reflect_albedo(lp, lt, hp, r, j, t, l, layering):
    """Albedo of a reflect lobe without its weight: total, or as Cycles estimates it for
    layering and GlossCol (``layering``)."""
    if lp[l, P_AFFINE] == 0.0:
        k = T_LAYER_E if layering else T_E
        return at(lt, l, k, j, t), at(lt, l, k + 1, j, t), at(lt, l, k + 2, j, t)
    e0, e1, e2, factor = affine_albedo(lp, lt, hp, r, j, t, l)
    if lp[l, P_MS] == 0.0 and layering:
        d = max(at(lt, l, T_E1, j, t), 1e-6)
        return e0 / d, e1 / d, e2 / d
    return e0 * factor, e1 * factor, e2 * factor


@kernel(inline="always")
def lobe_albedo(lp, lt, hp, r, j, t, l):
    """Directional albedo of lobe l including its weight and the layers above."""
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    kind = int(lp[l, P_KIND])
    if kind == REFLECT:
        e0, e1, e2 = reflect_albedo(lp, lt, hp, r, j, t, l, False)
        return s0 * e0, s1 * e1, s2 * e2
    if kind == GLASS:
        return (s0 * max(hp[r, l, H_TINT_R], hp[r, l, H_TINT_T]),
                s1 * max(hp[r, l, H_TINT_R + 1], hp[r, l, H_TINT_T + 1]),
                s2 * max(hp[r, l, H_TINT_R + 2], hp[r, l, H_TINT_T + 2]))
    return s0 * hp[r, l, H_COLOUR], s1 * hp[r, l, H_COLOUR + 1], s2 * hp[r, l, H_COLOUR + 2]


@kernel(inline="always")
def selection(lp, lt, hp, r, mu, mu_o, sel, si):
    """Fill ``sel[si]`` with the probabilities of continuing through each non-diffuse lobe:
    proportional to their albedos' largest channel, uniform when all are black."""
    j, t = locate(mu, mu_o)
    total = 0.0
    n = 0
    for l in range(lp.shape[0]):
        k = int(lp[l, P_SAMPLED])
        if k < 0:
            continue
        a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
        sel[si, k] = max(max(a0, a1), a2)
        total += sel[si, k]
        n += 1
    for k in range(n):
        sel[si, k] = sel[si, k] / max(total, TINY) if total > 0.0 else 1.0 / n


@kernel(inline="always")
def fresnel(lp, hp, r, l, c):
    """RGB Fresnel factor of a reflect lobe at cos(wo, h) = c."""
    kind = int(lp[l, P_FRESNEL])
    if kind == F_DIELECTRIC:
        f = mf.fresnel_dielectric1(c, lp[l, P_ETA_F])
        return f * hp[r, l, H_F0], f * hp[r, l, H_F0 + 1], f * hp[r, l, H_F0 + 2]
    if kind == F_F82:
        return (mf.fresnel_f82(c, hp[r, l, H_F0], lp[l, P_F82]),
                mf.fresnel_f82(c, hp[r, l, H_F0 + 1], lp[l, P_F82 + 1]),
                mf.fresnel_f82(c, hp[r, l, H_F0 + 2], lp[l, P_F82 + 2]))
    return hp[r, l, H_F0], hp[r, l, H_F0 + 1], hp[r, l, H_F0 + 2]


@kernel(inline="always")
def reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz):
    """GGX reflection: (f |cos| RGB, density of sampling wi through this lobe)."""
    alpha = lp[l, P_ALPHA]
    hx, hy, hz = vec.unit(wox + wix, woy + wiy, woz + wiz)
    cos_oh = min(max(wox * hx + woy * hy + woz * hz, 0.0), 1.0)
    d = mf.ggx_d(hz, alpha)
    c = d * mf.ggx_g2(woz, wiz, alpha) / (4.0 * max(woz, TINY))
    f0, f1, f2 = fresnel(lp, hp, r, l, cos_oh)
    return f0 * c, f1 * c, f2 * c, mf.ggx_g1(woz, alpha) * d / (4.0 * max(woz, TINY))


@kernel(inline="always")
def glass_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz, refl, trans, eta):
    """Rough dielectric (Walter et al. 2007), radiance form, following pbrt-v4:
    (f |cos| RGB, density of sampling wi through this lobe)."""
    alpha = lp[l, P_ALPHA]
    etap = eta if trans else 1.0
    mx, my, mz = wix * etap + wox, wiy * etap + woy, wiz * etap + woz
    if mz < 0.0:
        mx, my, mz = -mx, -my, -mz
    mx, my, mz = vec.unit(mx, my, mz)
    dot_mi = mx * wix + my * wiy + mz * wiz
    dot_mo = mx * wox + my * woy + mz * woz
    if not ((refl or trans) and dot_mi * wiz > 0.0 and dot_mo * woz > 0.0):
        return 0.0, 0.0, 0.0, 0.0
    refract_only = lp[l, P_REFRACT_ONLY] != 0.0
    if refl and refract_only:
        return 0.0, 0.0, 0.0, 0.0
    fr = mf.fresnel_dielectric1(dot_mo, eta)
    d = mf.ggx_d(mz, alpha)
    g2 = mf.ggx_g2(abs(woz), abs(wiz), alpha)
    dv = mf.visible_normal_pdf(wox, woy, woz, mx, my, mz, alpha)
    if refl:
        c = fr * d * g2 / (4.0 * abs(woz))
        pdf = dv / (4.0 * abs(dot_mo)) * fr
        return hp[r, l, H_TINT_R] * c, hp[r, l, H_TINT_R + 1] * c, hp[r, l, H_TINT_R + 2] * c, pdf
    denom = (dot_mi + dot_mo / etap) ** 2
    t_frac = 1.0 if refract_only else 1.0 - fr
    c = d * t_frac * g2 * abs(dot_mi * dot_mo) / max(denom * abs(woz), TINY) / etap ** 2
    pdf = dv * abs(dot_mi) / max(denom, TINY) * t_frac
    return hp[r, l, H_TINT_T] * c, hp[r, l, H_TINT_T + 1] * c, hp[r, l, H_TINT_T + 2] * c, pdf


@kernel(inline="always")
def lobe_eta(lp, l, inside):
    """Relative IOR across lobe l's interface seen from wo's side."""
    return 1.0 / lp[l, P_ETA] if inside else lp[l, P_ETA]


@kernel(inline="always")
def eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, si):
    """BSDF times |cos| of every non-delta lobe toward wi, for light sampling.

    ``above``: wi is on wo's side of the geometric surface; ``inside``: wo arrived from the
    back of the surface. ``sel[si]``: the lobe choice (``selection``) at wo. Returns
    (diffuse part RGB, non-diffuse part RGB, density of continuing toward wi through the
    non-diffuse lobes).
    """
    j, t = locate(mu, woz)
    fd0 = fd1 = fd2 = fn0 = fn1 = fn2 = pdf = 0.0
    refl = above and wiz > 0.0
    trans = (not above) and wiz < 0.0
    for l in range(lp.shape[0]):
        if lp[l, P_DELTA] != 0.0:
            continue
        kind = int(lp[l, P_KIND])
        if kind == DIFFUSE:
            if refl:
                s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
                c = wiz / np.pi
                fd0 += s0 * hp[r, l, H_COLOUR] * c
                fd1 += s1 * hp[r, l, H_COLOUR + 1] * c
                fd2 += s2 * hp[r, l, H_COLOUR + 2] * c
            continue
        if kind == REFLECT:
            if not refl:
                continue
            f0, f1, f2, p = reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz)
        else:
            f0, f1, f2, p = glass_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz, refl, trans, lobe_eta(lp, l, inside))
            if p == 0.0 and f0 == 0.0 and f1 == 0.0 and f2 == 0.0:
                continue
        s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
        ms = ms_factor(lp, lt, hp, r, j, t, l)
        fn0 += s0 * f0 * ms
        fn1 += s1 * f1 * ms
        fn2 += s2 * f2 * ms
        pdf += sel[si, int(lp[l, P_SAMPLED])] * p
    return fd0, fd1, fd2, fn0, fn1, fn2, pdf


@kernel(inline="always")
def masking(lp, lt, l, j, t, woz, wiz):
    """Sampling weight G2/G1 of visible-normal sampling toward wi.

    A delta lobe's reflection takes the white albedo of GGX at its own alpha instead
    (the mean of G2/G1 over the lobe it stands for, which differs from G2/G1 at the
    mirror direction near grazing); its refraction is masked at the refracted spread
    alpha_t (none at IOR 1).
    """
    alpha = lp[l, P_ALPHA]
    if lp[l, P_DELTA] == 0.0:
        return mf.ggx_g2(woz, abs(wiz), alpha) / mf.ggx_g1(woz, alpha)
    if wiz > 0.0:
        return at(lt, l, T_WHITE, j, t)
    a_t = lp[l, P_ALPHA_T] if int(lp[l, P_KIND]) == GLASS else alpha
    return mf.ggx_g2(woz, abs(wiz), a_t) / mf.ggx_g1(woz, a_t)


@kernel(inline="always")
def sample_lobe(lp, lt, hp, r, j, t, l, wox, woy, woz, u_choice, u0, u1, eta):
    """Sample lobe l alone: (wi, weight f |cos| / pdf of this lobe RGB, valid)."""
    kind = int(lp[l, P_KIND])
    if kind == TRANSPARENT:
        return -wox, -woy, -woz, hp[r, l, H_COLOUR], hp[r, l, H_COLOUR + 1], hp[r, l, H_COLOUR + 2], True
    if lp[l, P_DELTA] != 0.0:
        hx, hy, hz = 0.0, 0.0, 1.0
    else:
        hx, hy, hz = mf.sample_visible_normal(wox, woy, woz, lp[l, P_ALPHA], u0, u1)
    c = wox * hx + woy * hy + woz * hz
    rx, ry, rz = 2.0 * c * hx - wox, 2.0 * c * hy - woy, 2.0 * c * hz - woz
    if kind == REFLECT:
        f0, f1, f2 = fresnel(lp, hp, r, l, min(max(c, 0.0), 1.0))
        g = masking(lp, lt, l, j, t, woz, rz)
        return rx, ry, rz, f0 * g, f1 * g, f2 * g, rz > 0.0
    fr = mf.fresnel_dielectric1(c, eta)
    p_reflect = 0.0 if lp[l, P_REFRACT_ONLY] != 0.0 else fr
    if u_choice < p_reflect:  # the Fresnel factor cancels against the choice probability
        g = masking(lp, lt, l, j, t, woz, rz)
        return rx, ry, rz, hp[r, l, H_TINT_R] * g, hp[r, l, H_TINT_R + 1] * g, hp[r, l, H_TINT_R + 2] * g, rz > 0.0
    tx, ty, tz, ok = mf.refract(wox, woy, woz, hx, hy, hz, eta)
    g = masking(lp, lt, l, j, t, woz, tz) / eta ** 2  # radiance scales by 1/eta² crossing
    return tx, ty, tz, hp[r, l, H_TINT_T] * g, hp[r, l, H_TINT_T + 1] * g, hp[r, l, H_TINT_T + 2] * g, ok and tz < 0.0


@kernel(inline="always")
def sample_lobes(lp, lt, hp, r, mu, wox, woy, woz, u_select, u0, u1, inside, sel, si):
    """Continue through one non-diffuse lobe chosen by ``sel[si]`` (``selection`` at wo).

    Returns (wi, weight = f |cos| / pdf RGB, pdf (0 for delta), delta, valid, pass-through:
    the transparent lobe was taken). For non-delta lobes the weight and pdf are those of
    the whole non-diffuse mixture (one-sample MIS over lobes), as multiple importance
    sampling with light sampling requires.
    """
    n = sel.shape[1]
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
    l = 0
    while int(lp[l, P_SAMPLED]) != choice:
        l += 1
    wix, wiy, wiz, w0, w1, w2, ok = sample_lobe(lp, lt, hp, r, j, t, l, wox, woy, woz, u_re, u0, u1,
                                                lobe_eta(lp, l, inside))
    s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
    ms = ms_factor(lp, lt, hp, r, j, t, l)
    p = max(p_choice, TINY)
    w0, w1, w2 = w0 * s0 * ms / p, w1 * s1 * ms / p, w2 * s2 * ms / p
    delta = lp[l, P_DELTA] != 0.0
    valid = ok and p_choice > 0.0
    pdf = 0.0
    if valid and not delta:
        _, _, _, f0, f1, f2, pdf = eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, wiz > 0.0, inside,
                                              sel, si)
        if pdf > 0.0:
            w0, w1, w2 = f0 / max(pdf, TINY), f1 / max(pdf, TINY), f2 / max(pdf, TINY)
        else:
            w0 = w1 = w2 = 0.0
            valid = False
    w0 = w0 if np.isfinite(w0) else 0.0
    w1 = w1 if np.isfinite(w1) else 0.0
    w2 = w2 if np.isfinite(w2) else 0.0
    return wix, wiy, wiz, w0, w1, w2, pdf, delta, valid, int(lp[l, P_KIND]) == TRANSPARENT


@kernel(inline="always")
def colours(lp, lt, hp, r, mu, mu_o):
    """(diffuse colour RGB, glossy colour RGB) as the DiffCol / GlossCol passes show them."""
    j, t = locate(mu, mu_o)
    d0 = d1 = d2 = g0 = g1 = g2 = 0.0
    for l in range(lp.shape[0]):
        kind = int(lp[l, P_KIND])
        if kind == DIFFUSE:
            a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
            d0 += a0
            d1 += a1
            d2 += a2
        elif kind == REFLECT:
            s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
            e0, e1, e2 = reflect_albedo(lp, lt, hp, r, j, t, l, True)
            g0 += s0 * e0
            g1 += s1 * e1
            g2 += s2 * e2
        elif kind == GLASS and lp[l, P_REFRACT_ONLY] == 0.0:
            # Cycles reports the reflected share of glass as its glossy colour
            s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
            f = mf.fresnel_dielectric1(mu_o, lp[l, P_ETA])
            g0 += s0 * hp[r, l, H_TINT_R] * f
            g1 += s1 * hp[r, l, H_TINT_R + 1] * f
            g2 += s2 * hp[r, l, H_TINT_R + 2] * f
    return d0, d1, d2, g0, g1, g2


DENOISE_ROUGH = 0.075
"""GGX alpha above which Cycles counts a closure as diffuse-like for the denoising features
(``bsdf_get_specular_roughness_squared > sqr(0.075)`` in kernel/film/denoising_passes.h)."""


@kernel(inline="always")
def denoising_albedos(lp, lt, hp, r, mu, mu_o, inside):
    """(diffuse-like albedo RGB, specular-like albedo RGB, whether the hit is diffuse-like enough
    to take the denoising features), by Cycles' rule: each lobe's albedo goes to one side by its
    roughness, and the hit waits for the next bounce if 75% or more of the lobes' weight (the
    mean of their albedos) is specular-like."""
    j, t = locate(mu, mu_o)
    d0 = d1 = d2 = s0 = s1 = s2 = 0.0
    total = diffuse = 0.0
    for l in range(lp.shape[0]):
        kind = int(lp[l, P_KIND])
        if kind == GLASS:
            w0, w1, w2 = lobe_scale(lp, lt, hp, r, j, t, l)
            f = 0.0
            if lp[l, P_REFRACT_ONLY] == 0.0:
                f = mf.fresnel_dielectric1(-mu_o if inside else mu_o, lp[l, P_ETA])
            a0 = w0 * (hp[r, l, H_TINT_R] * f + hp[r, l, H_TINT_T] * (1.0 - f))
            a1 = w1 * (hp[r, l, H_TINT_R + 1] * f + hp[r, l, H_TINT_T + 1] * (1.0 - f))
            a2 = w2 * (hp[r, l, H_TINT_R + 2] * f + hp[r, l, H_TINT_T + 2] * (1.0 - f))
        elif kind == REFLECT:
            w0, w1, w2 = lobe_scale(lp, lt, hp, r, j, t, l)
            e0, e1, e2 = reflect_albedo(lp, lt, hp, r, j, t, l, True)
            a0, a1, a2 = w0 * e0, w1 * e1, w2 * e2
        else:
            a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
        weight = (a0 + a1 + a2) / 3.0
        total += weight
        if kind == DIFFUSE or (kind != TRANSPARENT and lp[l, P_ALPHA] > DENOISE_ROUGH):
            d0 += a0
            d1 += a1
            d2 += a2
            diffuse += weight
        else:
            s0 += a0
            s1 += a1
            s2 += a2
    return d0, d1, d2, s0, s1, s2, total == 0.0 or 4.0 * diffuse > total


# -- batch loops over a wave's arrays --------------------------------------------------
@kernel
def selection_rows(lp, lt, hp, prow, mu, mu_o, out):
    for i in range(len(mu_o)):
        selection(lp, lt, hp, prow[i], mu, mu_o[i], out, i)


@kernel
def evaluate_rows(lp, lt, hp, prow, mu, wo, wi, above, inside, sel, f_diff, f_nd, pdf):
    for i in range(len(wo)):
        v = eval_lobes(lp, lt, hp, prow[i], mu, wo[i, 0], wo[i, 1], wo[i, 2], wi[i, 0], wi[i, 1], wi[i, 2],
                       above[i], inside[i], sel, i)
        f_diff[i, 0], f_diff[i, 1], f_diff[i, 2] = v[0], v[1], v[2]
        f_nd[i, 0], f_nd[i, 1], f_nd[i, 2] = v[3], v[4], v[5]
        pdf[i] = v[6]


@kernel
def sample_rows(lp, lt, hp, prow, mu, wo, u_select, u2, inside, wi, weight, pdf, delta, valid, passthrough,
                n_sampled):
    sel = np.empty((1, n_sampled))
    for i in range(len(wo)):
        selection(lp, lt, hp, prow[i], mu, wo[i, 2], sel, 0)
        v = sample_lobes(lp, lt, hp, prow[i], mu, wo[i, 0], wo[i, 1], wo[i, 2], u_select[i], u2[i, 0], u2[i, 1],
                         inside[i], sel, 0)
        wi[i, 0], wi[i, 1], wi[i, 2] = v[0], v[1], v[2]
        weight[i, 0], weight[i, 1], weight[i, 2] = v[3], v[4], v[5]
        pdf[i], delta[i], valid[i], passthrough[i] = v[6], v[7], v[8], v[9]


@kernel
def colours_rows(lp, lt, hp, prow, mu, mu_o, diff, gloss):
    for i in range(len(mu_o)):
        v = colours(lp, lt, hp, prow[i], mu, mu_o[i])
        diff[i, 0], diff[i, 1], diff[i, 2] = v[0], v[1], v[2]
        gloss[i, 0], gloss[i, 1], gloss[i, 2] = v[3], v[4], v[5]


@kernel
def denoising_rows(lp, lt, hp, prow, mu, mu_o, inside, diff, spec, take):
    for i in range(len(mu_o)):
        v = denoising_albedos(lp, lt, hp, prow[i], mu, mu_o[i], inside[i])
        diff[i, 0], diff[i, 1], diff[i, 2] = v[0], v[1], v[2]
        spec[i, 0], spec[i, 1], spec[i, 2] = v[3], v[4], v[5]
        take[i] = v[6]


@kernel
def weights_rows(lp, lt, hp, prow, mu, mu_o, out):
    """(N, L, 3) weight of each lobe: scale times its multiple-scattering factor."""
    for i in range(len(mu_o)):
        j, t = locate(mu, mu_o[i])
        for l in range(lp.shape[0]):
            s0, s1, s2 = lobe_scale(lp, lt, hp, prow[i], j, t, l)
            ms = ms_factor(lp, lt, hp, prow[i], j, t, l)
            out[i, l, 0], out[i, l, 1], out[i, l, 2] = s0 * ms, s1 * ms, s2 * ms
