"""Glass lobe: rough dielectric reflection and refraction, evaluation with its pdf, sampling.

With a thin film (Principled's, ``P_FILM`` above ``thin_film.CUTOFF``) the reflectance R is the
film's RGB one with Cycles' specular tint, the transmission (1 - R) times the transmission tint,
and reflection is chosen with probability mean(R); without one, today's scalar Fresnel."""
from __future__ import annotations

from ..base import vectors as vec
from ..base.constants import TINY
from ..base.jit import kernel
from . import microfacet as mf
from . import thin_film as tf
from .blur import alpha as blurred_alpha
from .layout import H_TINT_R, H_TINT_T, P_ETA, P_FILM, P_FILM_IOR, P_REFRACT_ONLY
from .reflection import masking, reflected


@kernel(inline="always")
def glass_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz, refl, trans, eta):
    """Rough dielectric (Walter et al. 2007), radiance form, following pbrt-v4:
    (f |cos| RGB, density of sampling wi through this lobe)."""
    alpha = blurred_alpha(lp, hp, r, l)
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
    d = mf.ggx_d(mz, alpha)
    g2 = mf.ggx_g2(abs(woz), abs(wiz), alpha)
    dv = mf.visible_normal_pdf(wox, woy, woz, mx, my, mz, alpha)
    if lp[l, P_FILM] > tf.CUTOFF:
        r0, r1, r2, p = film_reflectance(lp, hp, r, l, dot_mo, eta)
        if refl:
            c = d * g2 / (4.0 * abs(woz))
            return r0 * c, r1 * c, r2 * c, dv / (4.0 * abs(dot_mo)) * p
        denom = (dot_mi + dot_mo / etap) ** 2
        c = d * g2 * abs(dot_mi * dot_mo) / max(denom * abs(woz), TINY) / etap ** 2
        return ((1.0 - r0) * hp[r, l, H_TINT_T] * c, (1.0 - r1) * hp[r, l, H_TINT_T + 1] * c,
                (1.0 - r2) * hp[r, l, H_TINT_T + 2] * c, dv * abs(dot_mi) / max(denom, TINY) * (1.0 - p))
    fr = mf.fresnel_dielectric1(dot_mo, eta)
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
def film_reflectance(lp, hp, r, l, c, eta):
    """(RGB reflectance, chance of reflecting = its mean) of a glass lobe with a thin film at
    cos(wo, h) = c: Cycles' film over the relative IOR eta, the film's IOR relative to the side
    wo is on (divided by the glass's from inside), the specular tint in H_TINT_R."""
    film_ior = lp[l, P_FILM_IOR] if eta == lp[l, P_ETA] else lp[l, P_FILM_IOR] * eta
    f0_real = ((eta - 1.0) / (eta + 1.0)) ** 2
    f0, f1, f2 = tf.film_dielectric(tf.SENSITIVITY, c, lp[l, P_FILM], film_ior, eta)
    f0 = tf.tinted(f0, hp[r, l, H_TINT_R], f0_real)
    f1 = tf.tinted(f1, hp[r, l, H_TINT_R + 1], f0_real)
    f2 = tf.tinted(f2, hp[r, l, H_TINT_R + 2], f0_real)
    return f0, f1, f2, min(max((f0 + f1 + f2) / 3.0, 0.0), 1.0)


@kernel(inline="always")
def lobe_eta(lp, l, inside):
    """Relative IOR across lobe l's interface seen from wo's side."""
    return 1.0 / lp[l, P_ETA] if inside else lp[l, P_ETA]



@kernel(inline="always")
def glass_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u_choice, u0, u1, eta):
    """Sample the lobe alone, reflection or refraction by the Fresnel factor at the sampled
    normal: (wi, weight f |cos| / pdf of this lobe RGB, valid)."""
    hx, hy, hz, c, rx, ry, rz = reflected(lp, hp, r, l, wox, woy, woz, u0, u1)
    if lp[l, P_FILM] > tf.CUTOFF:
        r0, r1, r2, p = film_reflectance(lp, hp, r, l, c, eta)
        if u_choice < p:
            g = masking(lp, lt, hp, r, l, j, t, wox, woy, woz, rx, ry, rz) / p
            return rx, ry, rz, r0 * g, r1 * g, r2 * g, rz > 0.0
        tx, ty, tz, ok = mf.refract(wox, woy, woz, hx, hy, hz, eta)
        g = masking(lp, lt, hp, r, l, j, t, wox, woy, woz, tx, ty, tz) / (eta ** 2 * max(1.0 - p, TINY))
        return (tx, ty, tz, (1.0 - r0) * hp[r, l, H_TINT_T] * g, (1.0 - r1) * hp[r, l, H_TINT_T + 1] * g,
                (1.0 - r2) * hp[r, l, H_TINT_T + 2] * g, ok and tz < 0.0)
    fr = mf.fresnel_dielectric1(c, eta)
    p_reflect = 0.0 if lp[l, P_REFRACT_ONLY] != 0.0 else fr
    if u_choice < p_reflect:  # the Fresnel factor cancels against the choice probability
        g = masking(lp, lt, hp, r, l, j, t, wox, woy, woz, rx, ry, rz)
        return rx, ry, rz, hp[r, l, H_TINT_R] * g, hp[r, l, H_TINT_R + 1] * g, hp[r, l, H_TINT_R + 2] * g, rz > 0.0
    tx, ty, tz, ok = mf.refract(wox, woy, woz, hx, hy, hz, eta)
    g = masking(lp, lt, hp, r, l, j, t, wox, woy, woz, tx, ty, tz) / eta ** 2  # radiance scales by 1/eta² crossing
    return tx, ty, tz, hp[r, l, H_TINT_T] * g, hp[r, l, H_TINT_T + 1] * g, hp[r, l, H_TINT_T + 2] * g, ok and tz < 0.0
