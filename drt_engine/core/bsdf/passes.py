"""What a hit's lobes show in the passes: DiffCol / GlossCol / TransCol, Cycles' Denoising Albedo, and the
transparency Mist and the index passes weigh a hit by."""
from __future__ import annotations

from ..base.jit import kernel
from . import microfacet as mf
from .hair_lobes import files_as_transmission, hair_albedo, is_hair
from .layout import (DIFFUSE, GLASS, H_TINT_R, H_TINT_T, OREN_NAYAR, P_ALPHA, P_ETA, P_KIND,
                     P_REFRACT_ONLY, REFLECT, SHEEN, TOON_DIFFUSE, TOON_GLOSSY, TRANSLUCENT, TRANSPARENT)
from .tables import lobe_albedo, lobe_scale, locate, reflect_albedo


@kernel(inline="always")
def diffuse_kind(kind):
    """Lambert, Oren-Nayar, diffuse toon, sheen or translucent: Cycles' diffuse closures
    (CLOSURE_IS_BSDF_DIFFUSE), which its DiffCol pass and the diffuse side of its denoising albedo take."""
    return kind == DIFFUSE or kind == OREN_NAYAR or kind == TOON_DIFFUSE or kind == SHEEN or kind == TRANSLUCENT


@kernel(inline="always")
def colours(lp, lt, hp, r, mu, mu_o):
    """(diffuse colour RGB, glossy colour RGB) as the DiffCol / GlossCol passes show them."""
    j, t = locate(mu, mu_o)
    d0 = d1 = d2 = g0 = g1 = g2 = 0.0
    for l in range(lp.shape[0]):
        kind = int(lp[l, P_KIND])
        if diffuse_kind(kind):
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
        elif kind == TOON_GLOSSY or (is_hair(kind) and not files_as_transmission(lp, l)):
            # Cycles' albedo of a closure without tables: its weight (times Principled Hair's estimate)
            if is_hair(kind):
                a0, a1, a2 = hair_albedo(lp, lt, hp, r, j, t, l)
            else:
                a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
            g0 += a0
            g1 += a1
            g2 += a2
        elif kind == GLASS and lp[l, P_REFRACT_ONLY] == 0.0:
            # Cycles reports the reflected share of glass as its glossy colour
            s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
            f = mf.fresnel_dielectric1(mu_o, lp[l, P_ETA])
            g0 += s0 * hp[r, l, H_TINT_R] * f
            g1 += s1 * hp[r, l, H_TINT_R + 1] * f
            g2 += s2 * hp[r, l, H_TINT_R + 2] * f
    return d0, d1, d2, g0, g1, g2


@kernel(inline="always")
def transmission_colour(lp, lt, hp, r, mu, mu_o):
    """The transmission colour RGB as the TransCol pass shows it: Cycles' surface_shader_transmission,
    each glass lobe's transmitted share (its transmission tint times 1 - Fresnel at wo; the whole tint
    of a Refraction BSDF's), which its transmission closures' albedo estimate gives for a smooth surface,
    and the Hair BSDF's transmission lobe's weight."""
    j, t = locate(mu, mu_o)
    c0 = c1 = c2 = 0.0
    for l in range(lp.shape[0]):
        if files_as_transmission(lp, l):
            a0, a1, a2 = hair_albedo(lp, lt, hp, r, j, t, l)
            c0 += a0
            c1 += a1
            c2 += a2
        if int(lp[l, P_KIND]) != GLASS:
            continue
        s0, s1, s2 = lobe_scale(lp, lt, hp, r, j, t, l)
        f = 0.0 if lp[l, P_REFRACT_ONLY] != 0.0 else mf.fresnel_dielectric1(mu_o, lp[l, P_ETA])
        c0 += s0 * hp[r, l, H_TINT_T] * (1.0 - f)
        c1 += s1 * hp[r, l, H_TINT_T + 1] * (1.0 - f)
        c2 += s2 * hp[r, l, H_TINT_T + 2] * (1.0 - f)
    return c0, c1, c2


DENOISE_ROUGH = 0.075
"""GGX alpha above which Cycles counts a closure as diffuse-like for the denoising features
(``bsdf_get_specular_roughness_squared > sqr(0.075)`` in kernel/film/denoising_passes.h)."""


@kernel(inline="always")
def denoising_albedos(lp, lt, hp, r, mu, mu_o, inside):
    """(diffuse-like albedo RGB, specular-like albedo RGB, whether the hit is diffuse-like enough
    to take the denoising features), by Cycles' rule: each lobe's albedo goes to one side by its
    roughness (the glossy toon's and hair's count as 1, as Cycles' bsdf_get_specular_roughness_squared
    has it for a closure that is not microfacet), and the hit waits for the next bounce if 75% or more
    of the lobes' weight (the mean of their albedos) is specular-like."""
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
        elif is_hair(kind):
            a0, a1, a2 = hair_albedo(lp, lt, hp, r, j, t, l)
        else:
            a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
        weight = (a0 + a1 + a2) / 3.0
        total += weight
        rough = kind == TOON_GLOSSY or is_hair(kind) or (kind != TRANSPARENT and lp[l, P_ALPHA] > DENOISE_ROUGH)
        if diffuse_kind(kind) or rough:
            d0 += a0
            d1 += a1
            d2 += a2
            diffuse += weight
        else:
            s0 += a0
            s1 += a1
            s2 += a2
    return d0, d1, d2, s0, s1, s2, total == 0.0 or 4.0 * diffuse > total


@kernel(inline="always")
def transparency(lp, lt, hp, r, mu, mu_o):
    """The transparent lobes' summed weight RGB (Cycles' ``surface_shader_transparency``)."""
    j, t = locate(mu, mu_o)
    c0 = c1 = c2 = 0.0
    for l in range(lp.shape[0]):
        if int(lp[l, P_KIND]) == TRANSPARENT:
            a0, a1, a2 = lobe_albedo(lp, lt, hp, r, j, t, l)
            c0 += a0
            c1 += a1
            c2 += a2
    return c0, c1, c2
