"""GGX reflection lobe (metal, specular, coat, glossy): Fresnel, evaluation with its pdf, sampling.

The reflected half of sampling (``reflected``: a microfacet normal and wo mirrored about it)
and the masking weight are shared with glass, whose reflection is this lobe's.
An anisotropic lobe (``P_ANISO``, Cycles' alpha_x along the shading frame's tangent, alpha_y
along its bitangent) takes the anisotropic D and Lambda; an isotropic one today's isotropic
arithmetic, so adding anisotropy changed no isotropic result.
"""
from __future__ import annotations

from ..base import vectors as vec
from ..base.constants import TINY
from ..base.jit import kernel
from . import blur
from . import microfacet as mf
from . import thin_film as tf
from .layout import (F_DIELECTRIC, F_F82, F_F82_FILM, F_FILM, GLASS, H_F0, H_NORMAL, P_ANISO, P_ETA_F, P_F82, P_FILM,
                     P_FILM_IOR, P_FRESNEL, P_KIND, T_WHITE)
from .tables import at, place


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
    if kind == F_FILM:  # a film over the specular layer: Cycles' specular tint in H_F0
        eta = lp[l, P_ETA_F]
        f0_real = ((eta - 1.0) / (eta + 1.0)) ** 2
        f0, f1, f2 = tf.film_dielectric(tf.SENSITIVITY, c, lp[l, P_FILM], lp[l, P_FILM_IOR], eta)
        return (tf.tinted(f0, hp[r, l, H_F0], f0_real), tf.tinted(f1, hp[r, l, H_F0 + 1], f0_real),
                tf.tinted(f2, hp[r, l, H_F0 + 2], f0_real))
    if kind == F_F82_FILM:
        return tf.film_conductor(tf.SENSITIVITY, c, lp[l, P_FILM], lp[l, P_FILM_IOR], hp[r, l, H_F0],
                                 hp[r, l, H_F0 + 1], hp[r, l, H_F0 + 2], lp[l, P_F82], lp[l, P_F82 + 1],
                                 lp[l, P_F82 + 2])
    return hp[r, l, H_F0], hp[r, l, H_F0 + 1], hp[r, l, H_F0 + 2]


@kernel(inline="always")
def reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz):
    """GGX reflection: (f |cos| RGB, density of sampling wi through this lobe)."""
    alpha = blur.alpha(lp, hp, r, l)
    hx, hy, hz = vec.unit(wox + wix, woy + wiy, woz + wiz)
    cos_oh = min(max(wox * hx + woy * hy + woz * hz, 0.0), 1.0)
    if lp[l, P_ANISO] != 0.0:
        ax, ay = blur.alphas_xy(lp, hp, r, l)
        d = mf.ggx_d_aniso(hx, hy, hz, ax, ay)
        lambda_o = mf.ggx_lambda_aniso(wox, woy, woz, ax, ay)
        g2 = 1.0 / (1.0 + lambda_o + mf.ggx_lambda_aniso(wix, wiy, wiz, ax, ay))
        g1 = 1.0 / (1.0 + lambda_o)
    else:
        d = mf.ggx_d(hz, alpha)
        g2 = mf.ggx_g2(woz, wiz, alpha)
        g1 = mf.ggx_g1(woz, alpha)
    c = d * g2 / (4.0 * max(woz, TINY))
    f0, f1, f2 = fresnel(lp, hp, r, l, cos_oh)
    return f0 * c, f1 * c, f2 * c, g1 * d / (4.0 * max(woz, TINY))


@kernel(inline="always")
def masking(lp, lt, hp, r, l, j, t, wox, woy, woz, wix, wiy, wiz):
    """Sampling weight G2/G1 of visible-normal sampling toward wi.

    A delta lobe's reflection takes the white albedo of GGX at its own alpha instead
    (the mean of G2/G1 over the lobe it stands for, which differs from G2/G1 at the
    mirror direction near grazing); its refraction is masked at the refracted spread
    alpha_t (none at IOR 1).
    """
    alpha = blur.alpha(lp, hp, r, l)
    if not blur.delta(lp, hp, r, l):
        if lp[l, P_ANISO] != 0.0:
            ax, ay = blur.alphas_xy(lp, hp, r, l)
            lambda_o = mf.ggx_lambda_aniso(wox, woy, woz, ax, ay)
            return (1.0 + lambda_o) / (1.0 + lambda_o + mf.ggx_lambda_aniso(wix, wiy, wiz, ax, ay))
        return mf.ggx_g2(woz, abs(wiz), alpha) / mf.ggx_g1(woz, alpha)
    if wiz > 0.0:
        return at(lt, l, T_WHITE, j, t)
    a_t = blur.alpha_t(lp, hp, r, l) if int(lp[l, P_KIND]) == GLASS else alpha
    return mf.ggx_g2(woz, abs(wiz), a_t) / mf.ggx_g1(woz, a_t)


@kernel(inline="always")
def reflected(lp, hp, r, l, wox, woy, woz, u0, u1):
    """(microfacet normal h, cos(wo, h), wo mirrored about h): h is the shading normal for a delta
    lobe, else sampled among the normals visible from wo."""
    if blur.delta(lp, hp, r, l):
        hx, hy, hz = 0.0, 0.0, 1.0
    elif lp[l, P_ANISO] != 0.0:
        ax, ay = blur.alphas_xy(lp, hp, r, l)
        hx, hy, hz = mf.sample_visible_normal(wox, woy, woz, ax, ay, u0, u1)
    else:
        a = blur.alpha(lp, hp, r, l)
        hx, hy, hz = mf.sample_visible_normal(wox, woy, woz, a, a, u0, u1)
    c = wox * hx + woy * hy + woz * hz
    rx, ry, rz = 2.0 * c * hx - wox, 2.0 * c * hy - woy, 2.0 * c * hz - woz
    return hx, hy, hz, c, rx, ry, rz


@kernel(inline="always")
def reflect_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u0, u1):
    """Sample the lobe alone: (wi, weight f |cos| / pdf of this lobe RGB, valid)."""
    _, _, _, c, rx, ry, rz = reflected(lp, hp, r, l, wox, woy, woz, u0, u1)
    f0, f1, f2 = fresnel(lp, hp, r, l, min(max(c, 0.0), 1.0))
    g = masking(lp, lt, hp, r, l, j, t, wox, woy, woz, rx, ry, rz)
    return rx, ry, rz, f0 * g, f1 * g, f2 * g, rz > 0.0


@kernel(inline="always")
def own_frame(hp, r, l):
    """(t, b, n) of the frame about a lobe's own normal (``H_NORMAL``, local to the shading frame):
    an isotropic lobe needs only its normal, any tangent does."""
    nx, ny, nz = hp[r, l, H_NORMAL], hp[r, l, H_NORMAL + 1], hp[r, l, H_NORMAL + 2]
    tx, ty, tz, bx, by, bz = vec.basis(nx, ny, nz)
    return tx, ty, tz, bx, by, bz, nx, ny, nz


@kernel(inline="always")
def own_reflect_eval(lp, hp, r, l, wox, woy, woz, wix, wiy, wiz):
    """``reflect_eval`` about the lobe's own normal (a Coat Normal): nothing where wo or wi is below it."""
    tx, ty, tz, bx, by, bz, nx, ny, nz = own_frame(hp, r, l)
    oz, iz = wox * nx + woy * ny + woz * nz, wix * nx + wiy * ny + wiz * nz
    if oz <= 0.0 or iz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    return reflect_eval(lp, hp, r, l, wox * tx + woy * ty + woz * tz, wox * bx + woy * by + woz * bz, oz,
                        wix * tx + wiy * ty + wiz * tz, wix * bx + wiy * by + wiz * bz, iz)


@kernel(inline="always")
def own_reflect_sample(lp, lt, hp, r, j, t, l, wox, woy, woz, u0, u1):
    """``reflect_sample`` about the lobe's own normal, its tables read at wo's cosine to it."""
    tx, ty, tz, bx, by, bz, nx, ny, nz = own_frame(hp, r, l)
    oz = wox * nx + woy * ny + woz * nz
    if oz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, False
    j, t = place(lp, hp, r, l, j, t)
    x, y, z, w0, w1, w2, ok = reflect_sample(lp, lt, hp, r, j, t, l, wox * tx + woy * ty + woz * tz,
                                             wox * bx + woy * by + woz * bz, oz, u0, u1)
    wix, wiy, wiz = x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz
    return wix, wiy, wiz, w0, w1, w2, ok
