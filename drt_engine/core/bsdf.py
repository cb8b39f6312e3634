"""Materials as sums of lobes: Lambert, GGX reflection, dielectric (glass), transparent.

A ``MaterialShader`` turns one ``Material`` (closures with constant inputs) into lobes
with Cycles' Principled layering: coat over (metal | glass | specular over diffuse),
the layer below weighted by one minus the albedo of the layer above. Energy terms
(directional albedo, multiple-scattering compensation) are tabulated per material.

Directions are in the local shading frame with ``wo`` always in the upper hemisphere
(the caller flips the frame to the side the ray arrived from; glass inverts its IOR).
The diffuse lobe is evaluated for light sampling only: as in Cook's distribution ray
tracing (and Cycles with diffuse bounces 0) no rays continue from it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import microfacet as mf
from .scene import Closure, Material

_TINY = 1e-30


@dataclass(eq=False)
class Lobe:
    kind: str  # "diffuse" | "reflect" | "glass" | "transparent"
    weight: np.ndarray  # constant RGB weight
    layer: Callable | None = None  # mu_o -> (N, 3) attenuation by the layers above
    albedo: np.ndarray = field(default_factory=lambda: np.ones(3))  # diffuse colour / transparent tint
    alpha: float = 0.0
    fresnel: Callable | None = None  # cos_h -> (N, 3) for "reflect"
    eta: float = 1.5  # glass: n_inside / n_outside
    tint_r: np.ndarray = field(default_factory=lambda: np.ones(3))
    tint_t: np.ndarray = field(default_factory=lambda: np.ones(3))
    refract_only: bool = False
    table: tuple | None = None  # (mu, E rgb): total albedo of the lobe, for lobe selection
    layer_table: tuple | None = None  # (mu, E rgb): albedo as Cycles estimates it for layering and GlossCol
    ms: tuple | None = None  # (mu, factor): multiple-scattering compensation of f

    @property
    def delta(self) -> bool:
        """Sampled as a delta distribution: smooth, or an interface that barely bends light.

        Refraction spreads directions by about alpha·|eta - 1|: at IOR 1 a rough glass is
        no interface at all (the Walter model's half vector degenerates there), so it
        becomes a straight pass-through whatever its roughness.
        """
        if self.kind == "transparent":
            return True
        if self.kind == "glass" and self.alpha_t < mf.DELTA_ALPHA:
            return True
        return self.kind in ("reflect", "glass") and self.alpha < mf.DELTA_ALPHA

    @property
    def alpha_t(self) -> float:
        """Spread of the refracted directions of a glass lobe (alpha scaled by the bend)."""
        return self.alpha * min(1.0, abs(self.eta - 1.0))

    def scale(self, mu_o: np.ndarray) -> np.ndarray:
        """Per-hit RGB weight: constant weight times the attenuation of layers above."""
        w = np.broadcast_to(self.weight, (len(mu_o), 3))
        if self.layer is not None:
            w = w * self.layer(mu_o)
        return w

    def ms_factor(self, mu_o: np.ndarray) -> np.ndarray | float:
        return np.interp(mu_o, *self.ms)[:, None] if self.ms is not None else 1.0

    def albedo_at(self, mu_o: np.ndarray) -> np.ndarray:
        """Directional albedo of the lobe including its weight and the layers above."""
        if self.kind == "reflect":
            return self.scale(mu_o) * mf.lookup(*self.table, mu_o)
        if self.kind == "glass":
            return self.scale(mu_o) * np.maximum(self.tint_r, self.tint_t)
        return self.scale(mu_o) * self.albedo


def _alpha(roughness: float) -> float:
    return float(np.clip(roughness, 0.0, 1.0)) ** 2


def _dielectric_fresnel(eta: float, tint: np.ndarray) -> Callable:
    return lambda c: mf.fresnel_dielectric(c, eta)[:, None] * tint


def _reflect_lobe(weight, alpha, fresnel, layer=None, multiscatter=True) -> Lobe:
    mu, e = mf.directional_albedo(alpha, fresnel)
    lobe = Lobe("reflect", np.asarray(weight, float), layer=layer, alpha=alpha, fresnel=fresnel)
    _, e1 = mf.white_albedo(float(alpha))
    if multiscatter:
        # Cycles' multiscatter GGX (Kulla-Conty): f_ss times 1 + F_ms (1 - E) / E with
        # F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)), E the white single-scatter albedo.
        e_avg = _cosine_average(mu, e1)
        f_avg = _cosine_average(mu, np.asarray(fresnel(mu)).mean(axis=-1))
        f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
        factor = 1.0 + f_ms * (1.0 - e1) / np.maximum(e1, 1e-3)
        lobe.ms = (mu, factor)
        e = e * factor[:, None]
        lobe.layer_table = (mu, e)
    else:
        # Cycles' albedo estimate for plain GGX is the lobe-averaged Fresnel, without the
        # energy masking loses (measured: diffuse weight 0.9595 under a 0.5-rough, IOR 1.5 layer)
        lobe.layer_table = (mu, e / np.maximum(e1, 1e-6)[:, None])
    lobe.table = (mu, e)
    return lobe


def _cosine_average(mu: np.ndarray, values: np.ndarray) -> float:
    """2 * integral of values(mu) mu dmu over [0, 1] (trapezoids, held constant below mu[0])."""
    x = np.concatenate([[0.0], mu])
    y = 2.0 * x * np.concatenate([values[:1], values])
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def _layer_under(upper: Lobe, weight_scalar: float, tint: np.ndarray | None = None) -> Callable:
    """Attenuation of what lies below ``upper``: 1 - weight * max albedo(mu_o), times a tint."""
    mu, e = upper.layer_table
    emax = e.max(axis=1) * weight_scalar
    tint = np.ones(3) if tint is None else tint
    return lambda m: np.clip(1.0 - np.interp(m, mu, emax), 0.0, 1.0)[:, None] * tint


def _chain(*layers: Callable | None) -> Callable | None:
    layers = [f for f in layers if f is not None]
    if not layers:
        return None

    def combined(mu_o):
        out = layers[0](mu_o)
        for f in layers[1:]:
            out = out * f(mu_o)
        return out

    return combined


def _principled_lobes(c: Closure) -> list[Lobe]:
    lobes = []
    w = c.weight
    base_layer = None
    if c.coat_weight > 0:
        coat = _reflect_lobe(w * c.coat_weight, _alpha(c.coat_roughness),
                             _dielectric_fresnel(max(c.coat_ior, 1.0 + 1e-4), np.ones(3)))
        lobes.append(coat)
        tint = 1.0 + c.coat_weight * (np.clip(c.coat_tint, 0, None) - 1.0)
        base_layer = _layer_under(coat, 1.0, tint)
    alpha = _alpha(c.roughness)
    base = np.clip(c.color, 0.0, 1.0)
    metallic = float(np.clip(c.metallic, 0, 1))
    transmission = float(np.clip(c.transmission, 0, 1))
    if metallic > 0:
        f82 = np.clip(c.specular_tint, 0, 1)
        lobes.append(_reflect_lobe(w * metallic, alpha, lambda x: mf.fresnel_f82(x, base, f82), base_layer,
                                   c.multiscatter))
    dielectric = 1.0 - metallic
    ior = max(float(c.ior), 1e-5)  # IOR below 1 is a valid medium (a bubble), as in Cycles
    if dielectric * transmission > 0:
        lobes.append(Lobe("glass", w * dielectric * transmission, layer=base_layer, alpha=alpha, eta=ior,
                          tint_r=np.clip(c.specular_tint, 0, None), tint_t=np.sqrt(base)))
    opaque = dielectric * (1.0 - transmission)
    if opaque > 0:
        level = max(float(c.specular_ior_level), 0.0)
        f0 = mf.f0_from_ior(ior) * 2.0 * level
        spec_tint = np.clip(c.specular_tint, 0, None)
        diffuse_layer = base_layer
        if f0 > 0:
            spec = _reflect_lobe(w * opaque, alpha, _dielectric_fresnel(mf.ior_from_f0(f0), spec_tint), base_layer,
                                 c.multiscatter)
            lobes.append(spec)
            diffuse_layer = _chain(base_layer, _layer_under(spec, 1.0))
        lobes.append(Lobe("diffuse", w * opaque, layer=diffuse_layer, albedo=base))
    return lobes


def lobes_of(material: Material) -> list[Lobe]:
    lobes = []
    for c in material.closures:
        if not np.any(c.weight > 0):
            continue
        if c.kind == "PRINCIPLED":
            lobes += _principled_lobes(c)
        elif c.kind == "DIFFUSE":
            lobes.append(Lobe("diffuse", c.weight, albedo=np.clip(c.color, 0, 1)))
        elif c.kind == "GLOSSY":
            tint = np.clip(c.color, 0, 1)
            lobes.append(_reflect_lobe(c.weight, _alpha(c.roughness), lambda x, t=tint: np.ones((len(x), 1)) * t,
                                       multiscatter=c.multiscatter))
        elif c.kind in ("GLASS", "REFRACTION"):
            tint = np.clip(c.color, 0, 1)
            lobes.append(Lobe("glass", c.weight, alpha=_alpha(c.roughness), eta=max(float(c.ior), 1e-5),
                              tint_r=tint, tint_t=tint, refract_only=c.kind == "REFRACTION"))
        elif c.kind == "TRANSPARENT":
            lobes.append(Lobe("transparent", c.weight, albedo=np.clip(c.color, 0, 1)))
    return lobes


class MaterialShader:
    """Evaluates and samples one material's lobes for batches of local directions."""

    def __init__(self, material: Material):
        self.material = material
        self.lobes = lobes_of(material)
        self.emission = material.emission
        self.sampled = [lobe for lobe in self.lobes if lobe.kind != "diffuse"]
        self.has_glass = any(lobe.kind == "glass" for lobe in self.lobes)

    @property
    def can_continue(self) -> bool:
        return bool(self.sampled)

    # -- lobe selection ---------------------------------------------------------------
    def selection(self, mu_o: np.ndarray) -> np.ndarray:
        """(N, L) probabilities of continuing through each non-diffuse lobe."""
        p = np.stack([mf.max3(lobe.albedo_at(mu_o)) for lobe in self.sampled], axis=1)
        total = p.sum(axis=1, keepdims=True)
        return np.where(total > 0, p / np.maximum(total, _TINY), 1.0 / len(self.sampled))

    # -- evaluation -----------------------------------------------------------------
    def evaluate(self, wo: np.ndarray, wi: np.ndarray, above: np.ndarray, inside: np.ndarray, sel=None):
        """BSDF times |cos| for light sampling.

        ``above``: wi is on wo's side of the geometric surface; ``inside``: wo arrived
        from the back of the surface (glass sees the inverse IOR). Returns (diffuse part,
        non-diffuse part, density of continuing in direction wi through the non-diffuse
        lobes, for multiple importance sampling). ``sel``: ``selection(wo[:, 2])`` when the
        caller has it already (it depends on wo only, so every light strategy shares it).
        """
        n = len(wo)
        mu_o = wo[:, 2]
        f_diff = np.zeros((n, 3))
        f_nd = np.zeros((n, 3))
        pdf = np.zeros(n)
        refl = above & (wi[:, 2] > 0)
        trans = ~above & (wi[:, 2] < 0)
        if sel is None and self.sampled:
            sel = self.selection(mu_o)
        for lobe in self.lobes:
            if lobe.delta:
                continue
            scale = lobe.scale(mu_o)
            if lobe.kind == "diffuse":
                f_diff += np.where(refl[:, None], scale * lobe.albedo * (wi[:, 2:3] / np.pi), 0.0)
                continue
            j = self.sampled.index(lobe)
            if lobe.kind == "reflect":
                f, p = _reflect_eval(lobe, wo, wi)
                f = np.where(refl[:, None], f, 0.0)
                p = np.where(refl, p, 0.0)
            else:
                f, p = _glass_eval(lobe, wo, wi, refl, trans, _eta(lobe, inside))
            f_nd += scale * f * lobe.ms_factor(mu_o)
            pdf += sel[:, j] * p
        return f_diff, f_nd, pdf

    # -- sampling -------------------------------------------------------------------
    def sample(self, wo: np.ndarray, u_select: np.ndarray, u2: np.ndarray, inside: np.ndarray):
        """Continue through one non-diffuse lobe chosen by its albedo.

        Returns (wi, weight = f |cos| / pdf, pdf (0 for delta), delta flag, valid flag,
        pass-through flag: the transparent lobe was taken).
        For non-delta lobes the weight and pdf are those of the whole non-diffuse
        mixture (one-sample MIS over lobes), which multiple importance sampling with
        light sampling requires.
        """
        n = len(wo)
        mu_o = wo[:, 2]
        sel = self.selection(mu_o)
        cdf = np.cumsum(sel, axis=1)
        choice = np.minimum((u_select[:, None] >= cdf).sum(axis=1), len(self.sampled) - 1)
        lo = np.where(choice > 0, np.take_along_axis(cdf, np.maximum(choice - 1, 0)[:, None], 1)[:, 0], 0.0)
        p_choice = np.take_along_axis(sel, choice[:, None], 1)[:, 0]
        u_re = np.clip((u_select - lo) / np.maximum(p_choice, _TINY), 0.0, 1.0 - 1e-12)
        wi = np.zeros((n, 3))
        weight = np.zeros((n, 3))
        delta = np.zeros(n, bool)
        valid = np.zeros(n, bool)
        passthrough = np.zeros(n, bool)
        for j, lobe in enumerate(self.sampled):
            idx = np.flatnonzero(choice == j)
            if len(idx) == 0:
                continue
            w_j, wt_j, ok_j = _sample_lobe(lobe, wo[idx], u_re[idx], u2[idx], _eta(lobe, inside[idx]))
            wi[idx] = w_j
            weight[idx] = wt_j * lobe.scale(mu_o[idx]) * lobe.ms_factor(mu_o[idx]) \
                / np.maximum(p_choice[idx], _TINY)[:, None]
            delta[idx] = lobe.delta
            passthrough[idx] = lobe.kind == "transparent"
            valid[idx] = ok_j & (p_choice[idx] > 0)
        pdf = np.zeros(n)
        smooth = np.flatnonzero(valid & ~delta)
        if len(smooth):
            above = wi[smooth, 2] > 0
            _, f_nd, pdf_nd = self.evaluate(wo[smooth], wi[smooth], above, inside[smooth], sel[smooth])
            pdf[smooth] = pdf_nd
            ok = pdf_nd > 0
            weight[smooth] = np.where(ok[:, None], f_nd / np.maximum(pdf_nd, _TINY)[:, None], 0.0)
            valid[smooth] &= ok
        weight = np.where(np.isfinite(weight), weight, 0.0)
        return wi, weight, pdf, delta, valid, passthrough

    # -- albedo passes --------------------------------------------------------------
    def colors(self, mu_o: np.ndarray):
        """(diffuse colour, glossy colour) as the DiffCol / GlossCol passes show them."""
        n = len(mu_o)
        diff = np.zeros((n, 3))
        gloss = np.zeros((n, 3))
        for lobe in self.lobes:
            if lobe.kind == "diffuse":
                diff += lobe.albedo_at(mu_o)
            elif lobe.kind == "reflect":
                gloss += lobe.scale(mu_o) * mf.lookup(*lobe.layer_table, mu_o)
            elif lobe.kind == "glass" and not lobe.refract_only:
                # Cycles reports the reflected share of glass as its glossy colour
                gloss += lobe.scale(mu_o) * lobe.tint_r * mf.fresnel_dielectric(mu_o, lobe.eta)[:, None]
        return diff, gloss


def _eta(lobe: Lobe, inside: np.ndarray) -> np.ndarray:
    """Relative IOR across the interface seen from wo's side."""
    return np.where(inside, 1.0 / lobe.eta, lobe.eta)


def _reflect_eval(lobe: Lobe, wo, wi):
    h = mf.normalize(wo + wi)
    cos_oh = np.clip(mf.dot(wo, h), 0.0, 1.0)
    d = mf.ggx_d(h[:, 2], lobe.alpha)
    g2 = mf.ggx_g2(wo[:, 2], wi[:, 2], lobe.alpha)
    f = lobe.fresnel(cos_oh) * (d * g2 / (4.0 * np.maximum(wo[:, 2], _TINY)))[:, None]
    pdf = mf.ggx_g1(wo[:, 2], lobe.alpha) * d / (4.0 * np.maximum(wo[:, 2], _TINY))
    return f, pdf


def _glass_eval(lobe: Lobe, wo, wi, refl, trans, eta):
    """Rough dielectric (Walter et al. 2007), radiance form, following pbrt-v4."""
    n = len(wo)
    etap = np.where(trans, eta, 1.0)
    wm = wi * etap[:, None] + wo
    wm = mf.normalize(np.where((wm[:, 2] < 0)[:, None], -wm, wm))
    cos_o, cos_i = wo[:, 2], wi[:, 2]
    ok = (refl | trans) & (mf.dot(wm, wi) * cos_i > 0) & (mf.dot(wm, wo) * cos_o > 0)
    fr = mf.fresnel_dielectric(mf.dot(wo, wm), eta)
    d = mf.ggx_d(wm[:, 2], lobe.alpha)
    g2 = mf.ggx_g2(np.abs(cos_o), np.abs(cos_i), lobe.alpha)
    dv = mf.visible_normal_pdf(wo, wm, lobe.alpha)
    f = np.zeros((n, 3))
    pdf = np.zeros(n)
    r = ok & refl & (not lobe.refract_only)
    f[r] = lobe.tint_r * (fr * d * g2 / (4.0 * np.abs(cos_o)))[r, None]
    pdf[r] = (dv / (4.0 * np.abs(mf.dot(wo, wm))) * fr)[r]
    t = ok & trans
    denom = (mf.dot(wi, wm) + mf.dot(wo, wm) / etap) ** 2
    t_frac = np.ones(n) if lobe.refract_only else (1.0 - fr)
    ft = d * t_frac * g2 * np.abs(mf.dot(wi, wm) * mf.dot(wo, wm)) / np.maximum(denom * np.abs(cos_o), _TINY)
    f[t] = lobe.tint_t * (ft / etap**2)[t, None]
    pdf[t] = (dv * np.abs(mf.dot(wi, wm)) / np.maximum(denom, _TINY) * t_frac)[t]
    return f, pdf


def _masking(lobe: Lobe, wo, wi):
    """Sampling weight G2/G1 of visible-normal sampling toward wi.

    A delta lobe's reflection takes the white albedo of GGX at its own alpha instead
    (the mean of G2/G1 over the lobe it stands for, which differs from G2/G1 at the
    mirror direction near grazing); its refraction is masked at the refracted spread
    ``alpha_t`` (none at IOR 1).
    """
    if not lobe.delta:
        return mf.ggx_g2(wo[:, 2], np.abs(wi[:, 2]), lobe.alpha) / mf.ggx_g1(wo[:, 2], lobe.alpha)
    a_t = lobe.alpha_t if lobe.kind == "glass" else lobe.alpha
    g_t = mf.ggx_g2(wo[:, 2], np.abs(wi[:, 2]), a_t) / mf.ggx_g1(wo[:, 2], a_t)
    return np.where(wi[:, 2] > 0, mf.lookup(*mf.white_albedo(float(lobe.alpha)), wo[:, 2]), g_t)


def _sample_lobe(lobe: Lobe, wo, u_choice, u2, eta):
    """Sample one lobe: (wi, weight f|cos|/pdf of this lobe alone, valid)."""
    n = len(wo)
    if lobe.kind == "transparent":
        return -wo, np.broadcast_to(lobe.albedo, (n, 3)).copy(), np.ones(n, bool)
    if lobe.delta:
        h = np.tile([0.0, 0.0, 1.0], (n, 1))
    else:
        h = mf.sample_visible_normal(wo, lobe.alpha, u2)
    if lobe.kind == "reflect":
        wi = mf.reflect(wo, h)
        ok = wi[:, 2] > 0
        fr = lobe.fresnel(np.clip(mf.dot(wo, h), 0, 1))
        return wi, fr * _masking(lobe, wo, wi)[:, None], ok
    fr = mf.fresnel_dielectric(mf.dot(wo, h), eta)
    p_reflect = np.zeros(n) if lobe.refract_only else fr
    go_reflect = u_choice < p_reflect
    wr = mf.reflect(wo, h)
    wt, ok_t = mf.refract(wo, h, eta)
    wi = np.where(go_reflect[:, None], wr, wt)
    ok = np.where(go_reflect, wr[:, 2] > 0, ok_t & (wt[:, 2] < 0))
    g = _masking(lobe, wo, wi)
    # The Fresnel factor cancels against the choice probability; radiance scales by 1/eta².
    weight = np.where(go_reflect[:, None], lobe.tint_r * g[:, None], lobe.tint_t * (g / eta**2)[:, None])
    return wi, weight, ok
