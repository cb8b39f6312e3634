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

import copy
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
    ms: tuple | None = None  # (mu, factor, E_avg): multiple-scattering compensation of f
    f82: np.ndarray | None = None  # metal: F82 tint
    source: int = 0  # index of the closure the lobe comes from
    role: str = ""  # "diffuse" | "metal" | "spec" | "coat" | "glass" | "glossy" | "transparent"
    # per-hit values of a bound lobe (see MaterialShader.bind), indexed by ``rows``
    hit_scale: np.ndarray | None = None  # (N, 3) weight multiplier
    hit_albedo: np.ndarray | None = None  # (N, 3) diffuse / transparent colour
    hit_tint_t: np.ndarray | None = None  # (N, 3) glass transmission tint
    hit_tint_r: np.ndarray | None = None  # (N, 3) glass reflection tint
    hit_f0: np.ndarray | None = None  # (N, 3) colour p of a Fresnel affine in it: p A(c) + B(c)
    affine: tuple | None = None  # (A, B, E_A, E_B, e1, a_avg, b_avg): tables of that Fresnel

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

    def scale(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """Per-hit RGB weight: constant weight times the attenuation of layers above."""
        w = np.broadcast_to(self.weight, (len(mu_o), 3))
        if self.layer is not None:
            w = w * self.layer(mu_o)
        if self.hit_scale is not None:
            w = w * self.hit_scale[rows]
        return w

    def colour(self, rows=None):
        return self.albedo if self.hit_albedo is None else self.hit_albedo[rows]

    def tints(self, rows=None):
        r = self.tint_r if self.hit_tint_r is None else self.hit_tint_r[rows]
        t = self.tint_t if self.hit_tint_t is None else self.hit_tint_t[rows]
        return r, t

    def fresnel_at(self, cos_h: np.ndarray, rows=None) -> np.ndarray:
        if self.hit_f0 is None:
            return self.fresnel(cos_h)
        a, b = self.affine[0], self.affine[1]
        return np.clip(self.hit_f0[rows] * a(cos_h) + b(cos_h), 0.0, 1.0)

    def _affine_tables(self, mu_o, rows):
        """(single-scatter albedo, multiple-scattering factor) of a bound affine-Fresnel lobe."""
        _, _, ea, eb, e1, a_avg, b_avg = self.affine
        mu = self.table[0]
        p = self.hit_f0[rows]
        e_ss = p * mf.lookup(mu, ea, mu_o) + mf.lookup(mu, eb, mu_o)
        if self.ms is None:
            return e_ss, 1.0
        f_avg = (p * a_avg + b_avg).mean(axis=1)
        e_avg = self.ms[2]
        f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
        e_w = np.interp(mu_o, mu, e1)
        return e_ss, (1.0 + f_ms * (1.0 - e_w) / np.maximum(e_w, 1e-3))[:, None]

    def ms_factor(self, mu_o: np.ndarray, rows=None) -> np.ndarray | float:
        if self.hit_f0 is not None:
            return self._affine_tables(mu_o, rows)[1]
        return np.interp(mu_o, self.ms[0], self.ms[1])[:, None] if self.ms is not None else 1.0

    def reflect_albedo(self, mu_o, rows=None, layering=False):
        """Albedo of a reflect lobe without its weight: total, or as Cycles estimates it for
        layering and GlossCol (``layering``)."""
        if self.hit_f0 is None:
            return mf.lookup(*(self.layer_table if layering else self.table), mu_o)
        e_ss, factor = self._affine_tables(mu_o, rows)
        if self.ms is None and layering:
            return e_ss / np.maximum(np.interp(mu_o, self.table[0], self.affine[4]), 1e-6)[:, None]
        return e_ss * factor

    def albedo_at(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """Directional albedo of the lobe including its weight and the layers above."""
        if self.kind == "reflect":
            return self.scale(mu_o, rows) * self.reflect_albedo(mu_o, rows)
        if self.kind == "glass":
            return self.scale(mu_o, rows) * np.maximum(*self.tints(rows))
        return self.scale(mu_o, rows) * self.colour(rows)


def _alpha(roughness: float) -> float:
    return float(np.clip(roughness, 0.0, 1.0)) ** 2


def _dielectric_fresnel(eta: float, tint: np.ndarray) -> Callable:
    return lambda c: mf.fresnel_dielectric(c, eta)[:, None] * tint


ROUGHNESS_GRID = 32
"""Shaders built per texel value tabulate their albedos at roughness (k / ROUGHNESS_GRID)^2
(dense where albedos change fast; cached across shaders) and interpolate in between; below
the second level (roughness 0.004) they are exact. Measured: lobe weights (layering and
multiple-scattering factors) within 0.1% of the exact tables' for view cosines above 0.2,
0.5% above 0.1 and 1.7% at 0.02 (test_bsdf)."""
_GRID_TABLES: dict = {}


class Tables:
    """Directional albedo tables of reflect lobes: exact, or interpolated in roughness from a
    cached grid (``grid``), which makes a shader per texture value cheap to build."""

    def __init__(self, grid: bool = False):
        self.grid = grid

    def albedo(self, alpha: float, fresnel, key) -> tuple[np.ndarray, np.ndarray]:
        s = max(float(alpha), 0.0) ** 0.25 * ROUGHNESS_GRID  # sqrt(roughness) in grid units
        if not self.grid or s < 2.0:
            return mf.directional_albedo(alpha, fresnel)
        k = min(int(np.floor(s)), ROUGHNESS_GRID - 1)
        t = s - k
        lo = self._grid(key, k, fresnel)
        hi = self._grid(key, k + 1, fresnel)
        return lo[0], (1.0 - t) * lo[1] + t * hi[1]

    def white(self, alpha: float):
        return self.albedo(alpha, lambda c: np.ones_like(c), ("white",))

    def f82(self, alpha: float, f82: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mu, E_A, E_B): albedos of the two parts of the F82 Fresnel f0 A(c) + B(c), each
        linear in 1 - f82, from four tables that do not depend on the tint."""
        a0, a1, b0, b1 = _F82_TERMS
        mu, ea0 = self.albedo(alpha, a0, ("f82 a0",))
        ea1 = self.albedo(alpha, a1, ("f82 a1",))[1]
        eb0 = self.albedo(alpha, b0, ("f82 b0",))[1]
        eb1 = self.albedo(alpha, b1, ("f82 b1",))[1]
        s = 1.0 - np.asarray(f82, float)
        return mu, ea0[:, None] - ea1[:, None] * s, eb0[:, None] - eb1[:, None] * s

    @staticmethod
    def _grid(key, k, fresnel):
        found = _GRID_TABLES.get((key, k))
        if found is None:
            found = _GRID_TABLES[(key, k)] = mf.directional_albedo((k / ROUGHNESS_GRID) ** 4, fresnel)
        return found


EXACT = Tables()


def _reflect_lobe(weight, alpha, fresnel, layer=None, multiscatter=True, tables=EXACT, key=None, tint=None,
                  table=None) -> Lobe:
    """A GGX reflection lobe with Fresnel ``fresnel`` times a constant ``tint`` (its albedo
    table is the untinted one times the tint, so lobes differing in tint share tables);
    ``table`` (mu, E) when the caller has it."""
    mu, e = table if table is not None else tables.albedo(alpha, fresnel, key)
    if tint is not None:
        untinted = fresnel
        e = e * tint
        fresnel = lambda c: untinted(c) * tint  # noqa: E731
    lobe = Lobe("reflect", np.asarray(weight, float), layer=layer, alpha=alpha, fresnel=fresnel)
    _, e1 = tables.white(float(alpha))
    if multiscatter:
        # Cycles' multiscatter GGX (Kulla-Conty): f_ss times 1 + F_ms (1 - E) / E with
        # F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)), E the white single-scatter albedo.
        e_avg = _cosine_average(mu, e1)
        f_avg = _cosine_average(mu, np.asarray(fresnel(mu)).mean(axis=-1))
        f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
        factor = 1.0 + f_ms * (1.0 - e1) / np.maximum(e1, 1e-3)
        lobe.ms = (mu, factor, e_avg)
        e = e * factor[:, None]
        lobe.layer_table = (mu, e)
    else:
        # Cycles' albedo estimate for plain GGX is the lobe-averaged Fresnel, without the
        # energy masking loses (measured: diffuse weight 0.9595 under a 0.5-rough, IOR 1.5 layer)
        lobe.layer_table = (mu, e / np.maximum(e1, 1e-6)[:, None])
    lobe.table = (mu, e)
    return lobe


def _affine(lobe: Lobe, a: Callable, b: Callable, tables: Tables, key, parts=None) -> tuple:
    """Tables of a reflect lobe whose Fresnel is p A(c) + B(c) for a per-hit colour p
    (``parts`` (mu, E_A, E_B) when the caller has them)."""
    if parts is not None:
        mu, ea, eb = parts
    else:
        mu, ea = tables.albedo(lobe.alpha, a, key + ("A",))
        _, eb = tables.albedo(lobe.alpha, b, key + ("B",))
    _, e1 = tables.white(float(lobe.alpha))
    fa = np.broadcast_to(a(mu), (len(mu), 3))
    fb = np.broadcast_to(b(mu), (len(mu), 3))
    a_avg = np.array([_cosine_average(mu, fa[:, k]) for k in range(3)])
    b_avg = np.array([_cosine_average(mu, fb[:, k]) for k in range(3)])
    return a, b, np.broadcast_to(ea, (len(mu), 3)), np.broadcast_to(eb, (len(mu), 3)), e1, a_avg, b_avg


def _f82_term(kind):
    def term(c):
        c = np.clip(c, 0.0, 1.0)
        bump = c * (1.0 - c) ** 6 / mf.F82_M
        return {"a0": 1.0 - (1.0 - c) ** 5, "a1": (1.0 - mf.F82_K) * bump, "b0": (1.0 - c) ** 5,
                "b1": mf.F82_K * bump}[kind]
    return term


_F82_TERMS = tuple(_f82_term(k) for k in ("a0", "a1", "b0", "b1"))
"""mf.fresnel_f82 before clipping is f0 (a0 - (1 - f82) a1) + b0 - (1 - f82) b1."""


def _f82_parts(f82: np.ndarray) -> tuple[Callable, Callable]:
    """mf.fresnel_f82 (before clipping) as f0 A(c) + B(c)."""
    k = mf.F82_K
    scale = (1.0 - f82) / mf.F82_M

    def a(c):
        c = np.clip(c, 0.0, 1.0)[:, None]
        return 1.0 - (1.0 - c) ** 5 - (1.0 - k) * scale * c * (1.0 - c) ** 6

    def b(c):
        c = np.clip(c, 0.0, 1.0)[:, None]
        return (1.0 - c) ** 5 - k * scale * c * (1.0 - c) ** 6

    return a, b


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


def _key(*parts):
    return tuple(tuple(np.round(np.atleast_1d(p), 9).tolist()) if not isinstance(p, str) else p for p in parts)


def _principled_lobes(c: Closure, tables: Tables) -> list[Lobe]:
    lobes = []
    w = c.weight
    base_layer = None
    if c.coat_weight > 0:
        coat_ior = max(c.coat_ior, 1.0 + 1e-4)
        coat = _reflect_lobe(w * c.coat_weight, _alpha(c.coat_roughness), _dielectric_fresnel(coat_ior, np.ones(3)),
                             tables=tables, key=_key("dielectric", coat_ior, np.ones(3)))
        coat.role = "coat"
        lobes.append(coat)
        tint = 1.0 + c.coat_weight * (np.clip(c.coat_tint, 0, None) - 1.0)
        base_layer = _layer_under(coat, 1.0, tint)
    alpha = _alpha(c.roughness)
    base = np.clip(c.color, 0.0, 1.0)
    metallic = float(np.clip(c.metallic, 0, 1))
    transmission = float(np.clip(c.transmission, 0, 1))
    if metallic > 0:
        f82 = np.clip(c.specular_tint, 0, 1)
        table = None
        if tables.grid:  # tint-independent tables; exact but for the clipping of mf.fresnel_f82
            mu, ea, eb = tables.f82(alpha, f82)
            table = (mu, base * ea + eb)
        metal = _reflect_lobe(w * metallic, alpha, lambda x: mf.fresnel_f82(x, base, f82), base_layer,
                              c.multiscatter, tables, _key("f82", base, f82), table=table)
        metal.role, metal.f82 = "metal", f82
        lobes.append(metal)
    dielectric = 1.0 - metallic
    ior = max(float(c.ior), 1e-5)  # IOR below 1 is a valid medium (a bubble), as in Cycles
    if dielectric * transmission > 0:
        lobes.append(Lobe("glass", w * dielectric * transmission, layer=base_layer, alpha=alpha, eta=ior,
                          tint_r=np.clip(c.specular_tint, 0, None), tint_t=np.sqrt(base), role="glass"))
    opaque = dielectric * (1.0 - transmission)
    if opaque > 0:
        level = max(float(c.specular_ior_level), 0.0)
        f0 = mf.f0_from_ior(ior) * 2.0 * level
        spec_tint = np.clip(c.specular_tint, 0, None)
        diffuse_layer = base_layer
        if f0 > 0:
            eta = mf.ior_from_f0(f0)
            spec = _reflect_lobe(w * opaque, alpha, _dielectric_fresnel(eta, np.ones(3)), base_layer,
                                 c.multiscatter, tables, _key("dielectric", eta, np.ones(3)), spec_tint)
            spec.role = "spec"
            lobes.append(spec)
            diffuse_layer = _chain(base_layer, _layer_under(spec, 1.0))
        lobes.append(Lobe("diffuse", w * opaque, layer=diffuse_layer, albedo=base, role="diffuse"))
    return lobes


def lobes_of(material: Material, tables: Tables = EXACT) -> list[Lobe]:
    lobes = []
    for i, c in enumerate(material.closures):
        if not np.any(c.weight > 0):
            continue
        if c.kind == "PRINCIPLED":
            new = _principled_lobes(c, tables)
        elif c.kind == "DIFFUSE":
            new = [Lobe("diffuse", c.weight, albedo=np.clip(c.color, 0, 1), role="diffuse")]
        elif c.kind == "GLOSSY":
            tint = np.clip(c.color, 0, 1)
            new = [_reflect_lobe(c.weight, _alpha(c.roughness), lambda x: np.ones((len(x), 3)),
                                 multiscatter=c.multiscatter, tables=tables, key=("unit rgb",), tint=tint)]
            new[0].role = "glossy"
        elif c.kind in ("GLASS", "REFRACTION"):
            tint = np.clip(c.color, 0, 1)
            new = [Lobe("glass", c.weight, alpha=_alpha(c.roughness), eta=max(float(c.ior), 1e-5),
                        tint_r=tint, tint_t=tint, refract_only=c.kind == "REFRACTION", role="bsdf_glass")]
        elif c.kind == "TRANSPARENT":
            new = [Lobe("transparent", c.weight, albedo=np.clip(c.color, 0, 1), role="transparent")]
        else:
            new = []
        for lobe in new:
            lobe.source = i
        lobes += new
    return lobes


class MaterialShader:
    """Evaluates and samples one material's lobes for batches of local directions.

    A shader built with ``varying`` closures (closure index -> names of inputs that vary
    per hit) is bound to the hits of one call with ``bind``; methods then take ``rows``,
    the hits' positions in that binding (None: all of them, in order).
    """

    def __init__(self, material: Material, varying: dict | None = None, tables: Tables = EXACT):
        self.material = material
        self.lobes = lobes_of(material, tables)
        self.emission = material.emission
        self.sampled = [lobe for lobe in self.lobes if lobe.kind != "diffuse"]
        self.has_glass = any(lobe.kind == "glass" for lobe in self.lobes)
        for lobe in self.lobes:
            names = (varying or {}).get(lobe.source, ())
            if "color" in names and lobe.role == "metal":
                parts = tables.f82(lobe.alpha, lobe.f82) if tables.grid else None
                lobe.affine = _affine(lobe, *_f82_parts(lobe.f82), tables, _key("f82", lobe.f82), parts)
            elif "color" in names and lobe.role == "glossy":
                lobe.affine = _affine(lobe, lambda c: np.ones((len(c), 3)), lambda c: np.zeros((len(c), 3)), tables,
                                      ("glossy",))

    @property
    def can_continue(self) -> bool:
        return bool(self.sampled)

    def bind(self, values: dict) -> "MaterialShader":
        """A copy whose lobes take per-hit values: ``values[closure index]`` maps "weight" and
        "color" to (N, 3) arrays (the shader was built with those set to one)."""
        bound = copy.copy(self)
        bound.lobes = [copy.copy(lobe) for lobe in self.lobes]
        bound.sampled = [lobe for lobe in bound.lobes if lobe.kind != "diffuse"]
        for lobe in bound.lobes:
            v = values.get(lobe.source, {})
            if "weight" in v:
                lobe.hit_scale = v["weight"]
            color = v.get("color")
            if color is None:
                continue
            base = np.clip(color, 0.0, 1.0)
            if lobe.role in ("diffuse", "transparent"):
                lobe.hit_albedo = base
            elif lobe.role == "glass":
                lobe.hit_tint_t = np.sqrt(base)
            elif lobe.role == "bsdf_glass":
                lobe.hit_tint_t = lobe.hit_tint_r = base
            elif lobe.affine is not None:
                lobe.hit_f0 = base
        return bound

    # -- lobe selection ---------------------------------------------------------------
    def selection(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """(N, L) probabilities of continuing through each non-diffuse lobe."""
        rows = np.arange(len(mu_o)) if rows is None else rows
        p = np.stack([mf.max3(lobe.albedo_at(mu_o, rows)) for lobe in self.sampled], axis=1)
        total = p.sum(axis=1, keepdims=True)
        return np.where(total > 0, p / np.maximum(total, _TINY), 1.0 / len(self.sampled))

    # -- evaluation -----------------------------------------------------------------
    def evaluate(self, wo: np.ndarray, wi: np.ndarray, above: np.ndarray, inside: np.ndarray, sel=None,
                 rows=None):
        """BSDF times |cos| for light sampling.

        ``above``: wi is on wo's side of the geometric surface; ``inside``: wo arrived
        from the back of the surface (glass sees the inverse IOR). Returns (diffuse part,
        non-diffuse part, density of continuing in direction wi through the non-diffuse
        lobes, for multiple importance sampling). ``sel``: ``selection(wo[:, 2])`` when the
        caller has it already (it depends on wo only, so every light strategy shares it).
        """
        n = len(wo)
        rows = np.arange(n) if rows is None else rows
        mu_o = wo[:, 2]
        f_diff = np.zeros((n, 3))
        f_nd = np.zeros((n, 3))
        pdf = np.zeros(n)
        refl = above & (wi[:, 2] > 0)
        trans = ~above & (wi[:, 2] < 0)
        if sel is None and self.sampled:
            sel = self.selection(mu_o, rows)
        for lobe in self.lobes:
            if lobe.delta:
                continue
            scale = lobe.scale(mu_o, rows)
            if lobe.kind == "diffuse":
                f_diff += np.where(refl[:, None], scale * lobe.colour(rows) * (wi[:, 2:3] / np.pi), 0.0)
                continue
            j = self.sampled.index(lobe)
            if lobe.kind == "reflect":
                f, p = _reflect_eval(lobe, wo, wi, rows)
                f = np.where(refl[:, None], f, 0.0)
                p = np.where(refl, p, 0.0)
            else:
                f, p = _glass_eval(lobe, wo, wi, refl, trans, _eta(lobe, inside), rows)
            f_nd += scale * f * lobe.ms_factor(mu_o, rows)
            pdf += sel[:, j] * p
        return f_diff, f_nd, pdf

    # -- sampling -------------------------------------------------------------------
    def sample(self, wo: np.ndarray, u_select: np.ndarray, u2: np.ndarray, inside: np.ndarray, rows=None):
        """Continue through one non-diffuse lobe chosen by its albedo.

        Returns (wi, weight = f |cos| / pdf, pdf (0 for delta), delta flag, valid flag,
        pass-through flag: the transparent lobe was taken).
        For non-delta lobes the weight and pdf are those of the whole non-diffuse
        mixture (one-sample MIS over lobes), which multiple importance sampling with
        light sampling requires.
        """
        n = len(wo)
        rows = np.arange(n) if rows is None else rows
        mu_o = wo[:, 2]
        sel = self.selection(mu_o, rows)
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
            r = rows[idx]
            w_j, wt_j, ok_j = _sample_lobe(lobe, wo[idx], u_re[idx], u2[idx], _eta(lobe, inside[idx]), r)
            wi[idx] = w_j
            weight[idx] = wt_j * lobe.scale(mu_o[idx], r) * lobe.ms_factor(mu_o[idx], r) \
                / np.maximum(p_choice[idx], _TINY)[:, None]
            delta[idx] = lobe.delta
            passthrough[idx] = lobe.kind == "transparent"
            valid[idx] = ok_j & (p_choice[idx] > 0)
        pdf = np.zeros(n)
        smooth = np.flatnonzero(valid & ~delta)
        if len(smooth):
            above = wi[smooth, 2] > 0
            _, f_nd, pdf_nd = self.evaluate(wo[smooth], wi[smooth], above, inside[smooth], sel[smooth], rows[smooth])
            pdf[smooth] = pdf_nd
            ok = pdf_nd > 0
            weight[smooth] = np.where(ok[:, None], f_nd / np.maximum(pdf_nd, _TINY)[:, None], 0.0)
            valid[smooth] &= ok
        weight = np.where(np.isfinite(weight), weight, 0.0)
        return wi, weight, pdf, delta, valid, passthrough

    # -- albedo passes --------------------------------------------------------------
    def colors(self, mu_o: np.ndarray, rows=None):
        """(diffuse colour, glossy colour) as the DiffCol / GlossCol passes show them."""
        n = len(mu_o)
        rows = np.arange(n) if rows is None else rows
        diff = np.zeros((n, 3))
        gloss = np.zeros((n, 3))
        for lobe in self.lobes:
            if lobe.kind == "diffuse":
                diff += lobe.albedo_at(mu_o, rows)
            elif lobe.kind == "reflect":
                gloss += lobe.scale(mu_o, rows) * lobe.reflect_albedo(mu_o, rows, layering=True)
            elif lobe.kind == "glass" and not lobe.refract_only:
                # Cycles reports the reflected share of glass as its glossy colour
                tint_r, _ = lobe.tints(rows)
                gloss += lobe.scale(mu_o, rows) * tint_r * mf.fresnel_dielectric(mu_o, lobe.eta)[:, None]
        return diff, gloss


def _eta(lobe: Lobe, inside: np.ndarray) -> np.ndarray:
    """Relative IOR across the interface seen from wo's side."""
    return np.where(inside, 1.0 / lobe.eta, lobe.eta)


def _reflect_eval(lobe: Lobe, wo, wi, rows=None):
    h = mf.normalize(wo + wi)
    cos_oh = np.clip(mf.dot(wo, h), 0.0, 1.0)
    d = mf.ggx_d(h[:, 2], lobe.alpha)
    g2 = mf.ggx_g2(wo[:, 2], wi[:, 2], lobe.alpha)
    f = lobe.fresnel_at(cos_oh, rows) * (d * g2 / (4.0 * np.maximum(wo[:, 2], _TINY)))[:, None]
    pdf = mf.ggx_g1(wo[:, 2], lobe.alpha) * d / (4.0 * np.maximum(wo[:, 2], _TINY))
    return f, pdf


def _glass_eval(lobe: Lobe, wo, wi, refl, trans, eta, rows=None):
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
    tint_r, tint_t = (np.broadcast_to(x, (n, 3)) for x in lobe.tints(rows))
    r = ok & refl & (not lobe.refract_only)
    f[r] = tint_r[r] * (fr * d * g2 / (4.0 * np.abs(cos_o)))[r, None]
    pdf[r] = (dv / (4.0 * np.abs(mf.dot(wo, wm))) * fr)[r]
    t = ok & trans
    denom = (mf.dot(wi, wm) + mf.dot(wo, wm) / etap) ** 2
    t_frac = np.ones(n) if lobe.refract_only else (1.0 - fr)
    ft = d * t_frac * g2 * np.abs(mf.dot(wi, wm) * mf.dot(wo, wm)) / np.maximum(denom * np.abs(cos_o), _TINY)
    f[t] = tint_t[t] * (ft / etap**2)[t, None]
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


def _sample_lobe(lobe: Lobe, wo, u_choice, u2, eta, rows=None):
    """Sample one lobe: (wi, weight f|cos|/pdf of this lobe alone, valid)."""
    n = len(wo)
    if lobe.kind == "transparent":
        return -wo, np.broadcast_to(lobe.colour(rows), (n, 3)).copy(), np.ones(n, bool)
    if lobe.delta:
        h = np.tile([0.0, 0.0, 1.0], (n, 1))
    else:
        h = mf.sample_visible_normal(wo, lobe.alpha, u2)
    if lobe.kind == "reflect":
        wi = mf.reflect(wo, h)
        ok = wi[:, 2] > 0
        fr = lobe.fresnel_at(np.clip(mf.dot(wo, h), 0, 1), rows)
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
    tint_r, tint_t = lobe.tints(rows)
    weight = np.where(go_reflect[:, None], tint_r * g[:, None], tint_t * (g / eta**2)[:, None])
    return wi, weight, ok
