"""Materials as sums of lobes: Lambert, Oren-Nayar, translucent, GGX reflection, dielectric (glass),
transparent, toon (diffuse and glossy), sheen, hair (the Hair BSDF's two, Principled Hair).

A ``MaterialShader`` turns one ``Material`` (closures with constant inputs) into lobes
with Cycles' Principled layering: coat over (metal | glass | specular over diffuse),
the layer below weighted by one minus the albedo of the layer above. Energy terms
(directional albedo, multiple-scattering compensation) are tabulated per material.

Directions are in the local shading frame with ``wo`` always in the upper hemisphere
(the caller flips the frame to the side the ray arrived from; glass inverts its IOR).
The diffuse lobes (Lambert, Oren-Nayar, translucent, diffuse toon) are evaluated for light sampling only: as
in Cook's distribution ray tracing (and Cycles with diffuse bounces 0) no rays continue from them.

Building lobes and their tables is NumPy, once per shader; the per-ray work (evaluation,
sampling, pdf, lobe choice, pass colours) is compiled (one module per lobe kind, ``mixture``
over them, ``passes``, run per wave by ``rows``), over the flat arrays ``MaterialShader``
packs the lobes into (``layout``).
"""
from __future__ import annotations

import copy
import threading
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..scene import Closure, Material
from . import layout
from . import microfacet as mf
from . import thin_film as tf
from .records import BsdfSample, BsdfValue
from .hair_absorption import melanin_sigma, random_factor, sigma_from_reflectance
from .hair_chiang import chiang_constants
from .hair_huang import huang_constants, huang_present
from .hair_lobes import hair_frames
from .sheen import sheen_albedo, sheen_rows
from .rows import (colours_rows, denoising_rows, evaluate_rows, sample_rows, selection_rows, transmission_rows,
                   transparency_rows, weights_rows)


BLURRED = ("reflect", "glass", "hair_chiang", "hair_huang")
"""The lobe kinds Cycles' Filter Glossy blurs (bsdf_blur): microfacet ones and Principled Hair's."""


@dataclass(eq=False)
class Lobe:
    """One lobe as built from the closures; ``MaterialShader`` packs its lobes into the flat
    arrays of ``layout``."""
    kind: str  # "diffuse" | "oren_nayar" | "translucent" | "reflect" | "glass" | "transparent" | "toon_diffuse"
    # | "toon_glossy" | "sheen" | "hair_reflection" | "hair_transmission" | "hair_chiang" | "hair_huang"
    weight: np.ndarray  # constant RGB weight
    layers: list = field(default_factory=list)  # [(max albedo of the layer above over mu, tint)]
    albedo: np.ndarray = field(default_factory=lambda: np.ones(3))  # diffuse colour / transparent tint
    alpha: float = 0.0
    sigma: float = 0.0  # Oren-Nayar roughness
    toon: tuple = (0.0, 0.0)  # toon: (size, smooth) as angles in radians
    sheen: np.ndarray | None = None  # sheen: (3, layout.SHEEN_N) a, b, albedo over the view cosines
    fresnel: Callable | None = None  # cos_h -> (N, 3) for "reflect", for its tables
    fresnel_kind: int = layout.F_TINT  # the same Fresnel for the kernels (reflection.fresnel)
    fresnel_eta: float = 1.0
    f0: np.ndarray = field(default_factory=lambda: np.ones(3))  # Fresnel colour: tint or metal f0
    eta: float = 1.5  # glass: n_inside / n_outside
    tint_r: np.ndarray = field(default_factory=lambda: np.ones(3))
    tint_t: np.ndarray = field(default_factory=lambda: np.ones(3))
    refract_only: bool = False
    table: tuple | None = None  # (mu, E rgb): total albedo of the lobe, for lobe selection
    layer_table: tuple | None = None  # (mu, E rgb): albedo as Cycles estimates it for layering and GlossCol
    ms: tuple | None = None  # (mu, factor, E_avg): multiple-scattering compensation of f
    f82: np.ndarray | None = None  # metal: F82 tint
    source: int = 0  # index of the closure the lobe comes from
    role: str = ""  # "diffuse" | "metal" | "spec" | "coat" | "glass" | "glossy" | "transparent" | "translucent"
    # | "toon" | "hair" | "principled_hair"
    affine: tuple | None = None  # (E_A, E_B, e1, a_avg, b_avg): tables of a Fresnel p A(c) + B(c), per-hit p
    alpha_xy: tuple | None = None  # anisotropic reflect lobe: (alpha_x, alpha_y), alpha their geometric mean
    film: tuple = (0.0, 1.0)  # thin film (thickness nm, IOR): reflect lobes of F_FILM / F_F82_FILM, glass
    hair: tuple = ()  # hair: its model's constants (layout.P_HAIR)
    hair_cut: bool = False  # Principled Hair: Cycles 5 cuts its light by its own normal (layout.P_HAIR_CUT)
    hair_sigma: np.ndarray = field(default_factory=lambda: np.zeros(3))  # Principled Hair: absorption
    hair_radial: float = 0.0  # Principled Hair: the radial roughness a per-hit reflectance colour's sigma takes
    own_normal: bool = False  # the coat of a Principled whose Coat Normal varies: its own normal per hit
    under_own: bool = False  # under such a coat: its first layer term read at the coat normal's cosine

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
    def anisotropic(self) -> bool:
        """An anisotropic GGX lobe (a delta lobe is sampled as a mirror whatever its alphas)."""
        return self.alpha_xy is not None and not self.delta

    @property
    def diffuse(self) -> bool:
        """One of the diffuse lobes (Cycles' CLOSURE_IS_BSDF_DIFFUSE)."""
        return self.kind in DIFFUSE_KINDS

    @property
    def bounces_diffuse(self) -> bool:
        """A diffuse reflection, which rays continue through only with diffuse bounces on: a
        translucent lobe's ray is a transmission bounce (Cycles' path_state_next), taken always."""
        return self.diffuse and self.kind != "translucent"

    @property
    def transmits_diffuse(self) -> bool:
        """A diffuse transmission (translucent), whose rays continue whatever the diffuse bounces."""
        return self.diffuse and not self.bounces_diffuse

    @property
    def alpha_t(self) -> float:
        """Spread of the refracted directions of a glass lobe (alpha scaled by the bend)."""
        return self.alpha * min(1.0, abs(self.eta - 1.0))


DIFFUSE_KINDS = ("diffuse", "oren_nayar", "translucent", "toon_diffuse", "sheen")


def _alpha(roughness: float) -> float:
    return float(np.clip(roughness, 0.0, 1.0)) ** 2


def anisotropic_alphas(kind: str, roughness: float, anisotropy: float) -> tuple | None:
    """(alpha_x, alpha_y) as Cycles' svm_node_closure_bsdf sets them, None when isotropic.

    Principled (and the Metallic BSDF): Anisotropic clamped to [0, 1], aspect sqrt(1 - 0.9 a),
    alpha_x = r² / aspect, alpha_y = r² aspect. Glossy: Anisotropy clamped to [-0.99, 0.99], isotropic
    within 1e-4 of 0, alpha_x = r² (1 - a), alpha_y = r² / (1 - a) (for a < 0: r² / (1 + a), r² (1 + a)).
    Either way sqrt(alpha_x alpha_y) = r², the alpha Cycles' albedo tables are read at, so the
    lobe's tables are the isotropic ones of its roughness."""
    alpha = _alpha(roughness)
    if not np.isfinite(anisotropy):
        return None
    if kind == "PRINCIPLED":
        a = float(np.clip(anisotropy, 0.0, 1.0))
        if not a > 0.0:
            return None
        aspect = np.sqrt(1.0 - 0.9 * a)
        return alpha / aspect, alpha * aspect
    a = float(np.clip(anisotropy, -0.99, 0.99))
    if abs(a) <= 1e-4:
        return None
    if a < 0.0:
        return alpha / (1.0 + a), alpha * (1.0 + a)
    return alpha * (1.0 - a), alpha / (1.0 - a)


FILM_GRID = np.linspace(0.0, 1.0, 4097)
"""Cosines a thin film's Fresnel is computed at for its albedo tables (interpolated between; the
kernels compute it exactly per ray): the tables then cost what a plain lobe's do."""


def _on_grid(fresnel: Callable) -> Callable:
    """``fresnel`` (cosines -> (N, 3)) read from its values at FILM_GRID."""
    f = fresnel(FILM_GRID)
    return lambda c: np.stack([np.interp(c, FILM_GRID, f[:, k]) for k in range(3)], axis=-1)


def _dielectric_fresnel(eta: float, tint: np.ndarray) -> Callable:
    return lambda c: mf.fresnel_dielectric(c, eta)[:, None] * tint


ROUGHNESS_GRID = 32
"""Shaders built per texel value tabulate their albedos at roughness (k / ROUGHNESS_GRID)^2
(dense where albedos change fast; cached across shaders) and interpolate in between; below
the second level (roughness 0.004) they are exact. Measured: lobe weights (layering and
multiple-scattering factors) within 0.1% of the exact tables' for view cosines above 0.2,
0.5% above 0.1 and 1.7% at 0.02 (test_bsdf)."""
_GRID_TABLES: dict = {}
_EXACT_TABLES: dict = {}
_EXACT_TABLES_MAX = 512
_EXACT_LOCK = threading.Lock()
"""Exact tables by (Fresnel key, alpha), kept across shaders and renders (a material preview
or a re-render builds the same lobes again; computing a table cost about 50 ms, measured in
bench/preview_times.py); read-only, oldest dropped first past the cap (each is a few kB)."""


class Tables:
    """Directional albedo tables of reflect lobes: exact, or interpolated in roughness from a
    cached grid (``grid``), which makes a shader per texture value cheap to build."""

    def __init__(self, grid: bool = False):
        self.grid = grid

    def albedo(self, alpha: float, fresnel, key) -> tuple[np.ndarray, np.ndarray]:
        s = max(float(alpha), 0.0) ** 0.25 * ROUGHNESS_GRID  # sqrt(roughness) in grid units
        if not self.grid or s < 2.0:
            return _exact_table(key, float(alpha), fresnel)
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


def _exact_table(key, alpha: float, fresnel):
    """``mf.directional_albedo(alpha, fresnel)``, kept by (key, alpha): a key names its Fresnel."""
    if key is None:
        return mf.directional_albedo(alpha, fresnel)
    found = _EXACT_TABLES.get((key, alpha))
    if found is None:
        mu, e = mf.directional_albedo(alpha, fresnel)
        e.setflags(write=False)
        found = (mu, e)
        with _EXACT_LOCK:  # a viewport's worker may prepare a scene meanwhile
            if len(_EXACT_TABLES) >= _EXACT_TABLES_MAX:
                _EXACT_TABLES.pop(next(iter(_EXACT_TABLES)))
            _EXACT_TABLES[(key, alpha)] = found
    return found


EXACT = Tables()


def _reflect_lobe(weight, alpha, fresnel, layers=(), multiscatter=True, tables=EXACT, key=None, tint=None,
                  table=None, fresnel_kind=layout.F_TINT, fresnel_eta=1.0, f0=None, bare=None) -> Lobe:
    """A GGX reflection lobe with Fresnel ``fresnel`` (for the kernels: ``fresnel_kind``,
    ``fresnel_eta`` and the colour ``f0``) times a constant ``tint`` (its albedo table is the
    untinted one times the tint, so lobes differing in tint share tables); ``table`` (mu, E)
    when the caller has it. ``bare``: a thin film's lobe, the Fresnel without the film, which
    Cycles' multiple-scattering term keeps; its layering albedo is then, as Cycles estimates it,
    the film's Fresnel at the view cosine times that term's darkening."""
    mu, e = table if table is not None else tables.albedo(alpha, fresnel, key)
    f0 = np.ones(3) if f0 is None else np.asarray(f0, float)
    if tint is not None:
        untinted = fresnel
        e = e * tint
        f0 = f0 * tint
        fresnel = lambda c: untinted(c) * tint  # noqa: E731
    lobe = Lobe("reflect", np.asarray(weight, float), layers=list(layers), alpha=alpha, fresnel=fresnel,
                fresnel_kind=fresnel_kind, fresnel_eta=fresnel_eta, f0=f0)
    _, e1 = tables.white(float(alpha))
    if multiscatter:
        # Cycles' multiscatter GGX (Kulla-Conty): f_ss times 1 + F_ms (1 - E) / E with
        # F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)), E the white single-scatter albedo.
        e_avg = _cosine_average(mu, e1)
        f_avg = _cosine_average(mu, np.asarray((fresnel if bare is None else bare)(mu)).mean(axis=-1))
        f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
        factor = 1.0 + f_ms * (1.0 - e1) / np.maximum(e1, 1e-3)
        lobe.ms = (mu, factor, e_avg)
        e = e * factor[:, None]
        lobe.layer_table = (mu, e)
        if bare is not None:
            lobe.layer_table = (mu, np.asarray(fresnel(mu)) * (e1 + f_ms * (1.0 - e1))[:, None])
    else:
        # Cycles' albedo estimate for plain GGX is the lobe-averaged Fresnel, without the
        # energy masking loses (measured: diffuse weight 0.9595 under a 0.5-rough, IOR 1.5 layer)
        lobe.layer_table = (mu, e / np.maximum(e1, 1e-6)[:, None] if bare is None else np.asarray(fresnel(mu)))
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
    return np.broadcast_to(ea, (len(mu), 3)), np.broadcast_to(eb, (len(mu), 3)), e1, a_avg, b_avg


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
    """mf.fresnel_f82 (before clipping) as f0 A(c) + B(c), over arrays of cosines."""
    k = mf.F82_K
    scale = (1.0 - f82) / mf.F82_M

    def a(c):
        c = np.clip(c, 0.0, 1.0)[:, None]
        return 1.0 - (1.0 - c) ** 5 - (1.0 - k) * scale * c * (1.0 - c) ** 6

    def b(c):
        c = np.clip(c, 0.0, 1.0)[:, None]
        return (1.0 - c) ** 5 - k * scale * c * (1.0 - c) ** 6

    return a, b


def _f82_fresnel(f0: np.ndarray, f82: np.ndarray) -> Callable:
    """mf.fresnel_f82 over arrays of cosines (for the tables)."""
    a, b = _f82_parts(f82)
    return lambda c: np.clip(f0 * a(c) + b(c), 0.0, 1.0)


def _cosine_average(mu: np.ndarray, values: np.ndarray) -> float:
    """2 * integral of values(mu) mu dmu over [0, 1] (trapezoids, held constant below mu[0])."""
    x = np.concatenate([[0.0], mu])
    y = 2.0 * x * np.concatenate([values[:1], values])
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def _layer_under(upper: Lobe, tint: np.ndarray | None = None) -> tuple:
    """Attenuation of what lies below ``upper``, 1 - max albedo(mu_o), times a tint: as
    (max albedo over mu, tint), a term of a lobe's ``layers``."""
    return upper.layer_table[1].max(axis=1), np.ones(3) if tint is None else np.asarray(tint, float)


def _key(*parts):
    return tuple(tuple(np.round(np.atleast_1d(p), 9).tolist()) if not isinstance(p, str) else p for p in parts)


SHEEN_CUTOFF = 1e-5
"""Cycles' CLOSURE_WEIGHT_CUTOFF: a Principled sheen weight at or below it adds no sheen."""


def _principled_sheen(c: Closure) -> tuple[Lobe | None, tuple | None]:
    """Principled's sheen, the first layer as in Cycles' closure.h (weight Sheen Weight x Sheen Tint)
    and its layer term over the rest: Cycles' closure_layering_weight, one minus the sheen's albedo
    over the closure's weight, its largest channel (Sheen Weight x max(tint) x albedo(mu))."""
    weight = max(float(c.sheen_weight), 0.0)
    if not weight > SHEEN_CUTOFF:
        return None, None
    tint = np.clip(c.sheen_tint, 0, None)
    sheen = sheen_lobe(c.weight * weight * tint, np.ones(3), c.sheen_roughness)
    sheen.role = "principled_sheen"  # the base colour is not its colour
    return sheen, (weight * float(tint.max()) * sheen.table[1][:, 0], np.ones(3))


def _over(upper: tuple, lower: tuple) -> tuple:
    """One layer term for two layers one over the other: (1 - a)(1 - b), each clamped as Cycles
    clamps each layering weight, as 1 - emax; tints multiply."""
    keep = np.clip(1.0 - upper[0], 0.0, 1.0) * np.clip(1.0 - lower[0], 0.0, 1.0)
    return 1.0 - keep, upper[1] * lower[1]


def _principled_lobes(c: Closure, tables: Tables) -> list[Lobe]:
    lobes = []
    w = c.weight
    sheen, sheen_layer = _principled_sheen(c)
    base_layers = []
    if sheen is not None:
        lobes.append(sheen)
        base_layers = [sheen_layer]
    if c.coat_weight > 0:
        coat_ior = max(c.coat_ior, 1.0 + 1e-4)
        coat = _reflect_lobe(w * c.coat_weight, _alpha(c.coat_roughness), _dielectric_fresnel(coat_ior, np.ones(3)),
                             list(base_layers), tables=tables, key=_key("dielectric", coat_ior, np.ones(3)),
                             fresnel_kind=layout.F_DIELECTRIC, fresnel_eta=coat_ior)
        coat.role = "coat"
        lobes.append(coat)
        tint = 1.0 + c.coat_weight * (np.clip(c.coat_tint, 0, None) - 1.0)
        coat_layer = _layer_under(coat, tint)
        base_layers = [coat_layer if sheen is None else _over(sheen_layer, coat_layer)]
    alpha = _alpha(c.roughness)
    base = np.clip(c.color, 0.0, 1.0)
    metallic = float(np.clip(c.metallic, 0, 1))
    transmission = float(np.clip(c.transmission, 0, 1))
    film = float(c.thin_film_thickness) if c.thin_film_thickness > tf.CUTOFF else 0.0
    film_ior = max(float(c.thin_film_ior), 1e-5)
    if metallic > 0:
        f82 = np.clip(c.specular_tint, 0, 1)
        if film and c.thin_film_metal:
            metal = _reflect_lobe(w * metallic, alpha, _on_grid(lambda x: tf.conductor(x, film, film_ior, base, f82)),
                                  base_layers, c.multiscatter, EXACT, _key("f82 film", base, f82, film, film_ior),
                                  fresnel_kind=layout.F_F82_FILM, f0=base, bare=_f82_fresnel(base, f82))
            metal.film = (film, film_ior)
        else:
            table = None
            if tables.grid:  # tint-independent tables; exact but for the clipping of mf.fresnel_f82
                mu, ea, eb = tables.f82(alpha, f82)
                table = (mu, base * ea + eb)
            metal = _reflect_lobe(w * metallic, alpha, _f82_fresnel(base, f82), base_layers, c.multiscatter, tables,
                                  _key("f82", base, f82), table=table, fresnel_kind=layout.F_F82, f0=base)
        metal.role, metal.f82 = "metal", f82
        metal.alpha_xy = anisotropic_alphas("PRINCIPLED", c.roughness, c.anisotropy)
        lobes.append(metal)
    dielectric = 1.0 - metallic
    ior = max(float(c.ior), 1e-5)  # IOR below 1 is a valid medium (a bubble), as in Cycles
    if dielectric * transmission > 0:
        lobes.append(Lobe("glass", w * dielectric * transmission, layers=list(base_layers), alpha=alpha, eta=ior,
                          tint_r=np.clip(c.specular_tint, 0, None), tint_t=np.sqrt(base), role="glass",
                          film=(film, film_ior)))
    opaque = dielectric * (1.0 - transmission)
    if opaque > 0:
        level = max(float(c.specular_ior_level), 0.0)
        f0 = mf.f0_from_ior(ior) * 2.0 * level
        spec_tint = np.clip(c.specular_tint, 0, None)
        diffuse_layers = list(base_layers)
        if film:  # Cycles' specular layer over a film: its tint scales the film's reflectance near F0
            eta = ior if level == 0.5 else float(mf.ior_from_f0(f0)) if f0 > 0 else 1.0
            eta = 1.0 / eta if ior < 1.0 and level != 0.5 else eta
            tint = np.clip(spec_tint, 0.0, 1.0 / max(mf.f0_from_ior(eta), 1e-6))
            fresnel = _on_grid(lambda x: tf.dielectric(x, film, film_ior, eta, tint))
            spec = _reflect_lobe(w * opaque, alpha, fresnel, base_layers, c.multiscatter, EXACT,
                                 _key("dielectric film", eta, tint, film, film_ior),
                                 fresnel_kind=layout.F_FILM, fresnel_eta=eta, f0=tint,
                                 bare=lambda x: np.clip(mf.fresnel_dielectric(x, eta)[:, None] * tint, 0.0, 1.0))
            spec.role, spec.film = "spec", (film, film_ior)
            spec.alpha_xy = anisotropic_alphas("PRINCIPLED", c.roughness, c.anisotropy)
            lobes.append(spec)
            diffuse_layers.append(_layer_under(spec))
        elif f0 > 0:
            eta = mf.ior_from_f0(f0)
            spec = _reflect_lobe(w * opaque, alpha, _dielectric_fresnel(eta, np.ones(3)), base_layers,
                                 c.multiscatter, tables, _key("dielectric", eta, np.ones(3)), spec_tint,
                                 fresnel_kind=layout.F_DIELECTRIC, fresnel_eta=eta)
            spec.role = "spec"
            spec.alpha_xy = anisotropic_alphas("PRINCIPLED", c.roughness, c.anisotropy)
            lobes.append(spec)
            diffuse_layers.append(_layer_under(spec))
        lobes.append(_diffuse_lobe(w * opaque, base, c.diffuse_roughness, diffuse_layers))
    return lobes


OREN_NAYAR_FROM = 1e-5
"""Roughness from which Cycles' diffuse is Oren-Nayar rather than Lambert
(``diffuse_roughness_is_almost_zero`` in kernel/closure/bsdf_oren_nayar.h)."""


def _diffuse_lobe(weight, albedo, roughness, layers=()) -> Lobe:
    """Lambert, or Oren-Nayar of sigma ``roughness`` from OREN_NAYAR_FROM up."""
    rough = float(roughness) >= OREN_NAYAR_FROM
    return Lobe("oren_nayar" if rough else "diffuse", np.asarray(weight, float), layers=list(layers), albedo=albedo,
                sigma=float(roughness) if rough else 0.0, role="diffuse")


def toon_angles(size: float, smooth: float) -> tuple[float, float]:
    """(size, smooth) as angles, as Cycles' bsdf_toon_setup_common sets them: Size clamped to
    [1e-5, 1] and Smooth to [0, 1], each times pi / 2 (a non-finite value counts as 0)."""
    size = float(size) if np.isfinite(size) else 0.0
    smooth = float(smooth) if np.isfinite(smooth) else 0.0
    return float(np.clip(size, 1e-5, 1.0)) * np.pi / 2, float(np.clip(smooth, 0.0, 1.0)) * np.pi / 2


def sheen_lobe(weight, colour, roughness) -> Lobe:
    """Cycles' microfiber sheen (core.bsdf.sheen) of this roughness (clamped to [1e-3, 1] as
    bsdf_sheen_setup), its albedo tabulated over the view cosines for lobe choice and the passes."""
    rows = sheen_rows(roughness if np.isfinite(roughness) else 0.0)
    mu = mf.MU_TABLE
    e = sheen_albedo(rows, mu)[:, None] * np.ones(3)
    return Lobe("sheen", np.asarray(weight, float), albedo=colour, sheen=rows, table=(mu, e), layer_table=(mu, e),
                role="sheen")


def principled_hair_lobe(c: Closure, cut: bool) -> Lobe | None:
    """The Principled Hair BSDF as Cycles' svm_node_closure_bsdf sets its closure up on a mesh: Random
    (the socket's; a mesh has no per-strand random) spreads Roughness and the melanin, the
    absorption from the parametrization (colour as reflectance, melanin with its tint, or direct),
    then the model's own setup (core.bsdf.hair_chiang, hair_huang; Huang's radial roughness is its
    roughness, and it makes no closure with its three gains at 0). The node's colour is no weight.
    ``cut``: the material's Cycles (5.x) cuts the closure's light by its own normal (hair_lobes)."""
    random = float(c.hair_random)
    spread = float(random_factor(random, float(c.random_roughness)))
    roughness = float(c.roughness) * spread
    huang = c.hair_model == "HUANG"
    radial = roughness if huang else float(c.radial_roughness) * spread
    if c.hair_parametrization == "ABSORPTION":
        sigma = np.array(c.absorption, float)
    elif c.hair_parametrization == "MELANIN":
        tint_spread = random_factor(random, float(np.clip(c.random_color, 0.0, 1.0)))
        sigma = melanin_sigma(c.melanin, c.melanin_redness, c.hair_tint, radial, tint_spread)
    else:
        sigma = sigma_from_reflectance(c.color, radial)
    if huang:
        if not huang_present(*c.hair_gains):
            return None
        kind, constants = "hair_huang", huang_constants(roughness, c.hair_offset, c.ior, c.aspect_ratio, *c.hair_gains)
    else:
        kind, constants = "hair_chiang", chiang_constants(roughness, radial, c.hair_coat, c.hair_offset, c.ior)
    return Lobe(kind, c.weight, hair=tuple(float(x) for x in constants), hair_cut=cut,
                hair_sigma=np.asarray(sigma, float), hair_radial=radial, role="principled_hair")


def lobes_of(material: Material, tables: Tables = EXACT) -> list[Lobe]:
    lobes = []
    for i, c in enumerate(material.closures):
        if not np.any(c.weight > 0):
            continue
        if c.kind == "PRINCIPLED":
            new = _principled_lobes(c, tables)
        elif c.kind == "DIFFUSE":
            new = [_diffuse_lobe(c.weight, np.clip(c.color, 0, 1), c.diffuse_roughness)]
        elif c.kind == "TRANSLUCENT":
            new = [Lobe("translucent", c.weight, albedo=np.clip(c.color, 0, 1), role="translucent")]
        elif c.kind == "GLOSSY":
            tint = np.clip(c.color, 0, 1)
            new = [_reflect_lobe(c.weight, _alpha(c.roughness), lambda x: np.ones((len(x), 3)),
                                 multiscatter=c.multiscatter, tables=tables, key=("unit rgb",), tint=tint)]
            new[0].role = "glossy"
            new[0].alpha_xy = anisotropic_alphas("GLOSSY", c.roughness, c.anisotropy)
        elif c.kind in ("GLASS", "REFRACTION"):
            tint = np.clip(c.color, 0, 1)
            new = [Lobe("glass", c.weight, alpha=_alpha(c.roughness), eta=max(float(c.ior), 1e-5),
                        tint_r=tint, tint_t=tint, refract_only=c.kind == "REFRACTION", role="bsdf_glass")]
        elif c.kind in ("DIFFUSE_TOON", "GLOSSY_TOON"):
            new = [Lobe("toon_diffuse" if c.kind == "DIFFUSE_TOON" else "toon_glossy", c.weight,
                        albedo=np.clip(c.color, 0, 1), toon=toon_angles(c.toon_size, c.toon_smooth), role="toon")]
        elif c.kind == "SHEEN":
            new = [sheen_lobe(c.weight, np.clip(c.color, 0, 1), c.roughness)]
        elif c.kind == "TRANSPARENT":
            new = [Lobe("transparent", c.weight, albedo=np.clip(c.color, 0, 1), role="transparent")]
        elif c.kind in ("HAIR_REFLECTION", "HAIR_TRANSMISSION"):
            new = [Lobe(c.kind.lower(), c.weight, albedo=np.array(c.color, float), role="hair",
                        hair=(c.roughness, c.hair_roughness_v, -c.hair_offset))]
        elif c.kind == "PRINCIPLED_HAIR":
            new = [lobe for lobe in [principled_hair_lobe(c, material.bump_shadowing == "GGX")] if lobe is not None]
        else:
            new = []
        for lobe in new:
            lobe.source = i
        lobes += new
    return lobes


def see_through(material: Material) -> bool:
    """Whether shadow rays may pass the material (Cycles' SD_HAS_TRANSPARENT_SHADOW): its
    Transparent Shadows are on and it has a Transparent closure of some weight, constant or
    computed by its program (a Principled Alpha, a mix, a texture)."""
    weighted = [bool(c.inputs) or bool(np.any(c.weight > 0)) for c in material.closures if c.kind == "TRANSPARENT"]
    return material.transparent_shadow and any(weighted)


_KINDS = {"diffuse": layout.DIFFUSE, "reflect": layout.REFLECT, "glass": layout.GLASS,
          "transparent": layout.TRANSPARENT, "translucent": layout.TRANSLUCENT, "oren_nayar": layout.OREN_NAYAR,
          "toon_diffuse": layout.TOON_DIFFUSE, "toon_glossy": layout.TOON_GLOSSY, "sheen": layout.SHEEN,
          "hair_reflection": layout.HAIR_REFLECTION, "hair_transmission": layout.HAIR_TRANSMISSION,
          "hair_chiang": layout.HAIR_CHIANG, "hair_huang": layout.HAIR_HUANG}


def _pack(lobes: list[Lobe], sampled: list[Lobe]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lobes as ``layout``'s flat arrays: constants (L, P), tables (L, T, len(MU_TABLE))
    and the per-hit part for a constant shader (1, L, H)."""
    n_mu = len(mf.MU_TABLE)
    lp = np.zeros((len(lobes), layout.P))
    lt = np.zeros((len(lobes), layout.T, n_mu))
    hp = np.zeros((1, len(lobes), layout.H))
    for l, lobe in enumerate(lobes):
        row = lp[l]
        row[layout.P_KIND] = _KINDS[lobe.kind]
        row[layout.P_DELTA] = lobe.delta
        row[layout.P_ALPHA], row[layout.P_ALPHA_T], row[layout.P_ETA] = lobe.alpha, lobe.alpha_t, lobe.eta
        row[layout.P_REFRACT_ONLY] = lobe.refract_only
        row[layout.P_SIGMA] = lobe.sigma
        row[layout.P_TOON_SIZE], row[layout.P_TOON_SMOOTH] = lobe.toon
        row[layout.P_FILM], row[layout.P_FILM_IOR] = lobe.film
        row[layout.P_OWN_NORMAL], row[layout.P_UNDER_OWN] = lobe.own_normal, lobe.under_own
        row[layout.P_HAIR:layout.P_HAIR + len(lobe.hair)] = lobe.hair
        row[layout.P_HAIR_CUT] = lobe.hair_cut
        if lobe.sheen is not None:
            row[layout.P_SHEEN_TABLE:layout.P_SHEEN_TABLE + 3 * layout.SHEEN_N] = lobe.sheen.reshape(-1)
        if lobe.anisotropic:
            row[layout.P_ANISO] = 1.0
            row[layout.P_ALPHA_X], row[layout.P_ALPHA_Y] = lobe.alpha_xy
        row[layout.P_FRESNEL], row[layout.P_ETA_F] = lobe.fresnel_kind, lobe.fresnel_eta
        row[layout.P_F82:layout.P_F82 + 3] = 1.0 if lobe.f82 is None else lobe.f82
        row[layout.P_LAYERS] = len(lobe.layers)
        for t, (emax, tint) in enumerate(lobe.layers):
            lt[l, layout.T_UNDER + t] = emax
            row[layout.P_LAYER_TINT + 3 * t:layout.P_LAYER_TINT + 3 * t + 3] = tint
        row[layout.P_SAMPLED] = sampled.index(lobe) if lobe in sampled else -1
        row[layout.P_WEIGHT:layout.P_WEIGHT + 3] = lobe.weight
        if lobe.table is not None:
            assert np.array_equal(lobe.table[0], mf.MU_TABLE)  # every table is over MU_TABLE
            lt[l, layout.T_E:layout.T_E + 3] = np.broadcast_to(lobe.table[1], (n_mu, 3)).T
            lt[l, layout.T_LAYER_E:layout.T_LAYER_E + 3] = np.broadcast_to(lobe.layer_table[1], (n_mu, 3)).T
        if lobe.ms is not None:
            row[layout.P_MS], row[layout.P_E_AVG] = 1.0, lobe.ms[2]
            lt[l, layout.T_MS] = lobe.ms[1]
        if lobe.delta and lobe.kind in ("reflect", "glass"):
            lt[l, layout.T_WHITE] = mf.white_albedo(float(lobe.alpha))[1]
        if lobe.affine is not None:
            ea, eb, e1, a_avg, b_avg = lobe.affine
            row[layout.P_AFFINE] = 1.0
            lt[l, layout.T_EA:layout.T_EA + 3], lt[l, layout.T_EB:layout.T_EB + 3], lt[l, layout.T_E1] = ea.T, eb.T, e1
            row[layout.P_A_AVG:layout.P_A_AVG + 3], row[layout.P_B_AVG:layout.P_B_AVG + 3] = a_avg, b_avg
        h = hp[0, l]
        h[layout.H_SCALE:layout.H_SCALE + 3] = 1.0
        h[layout.H_COLOUR:layout.H_COLOUR + 3] = lobe.albedo
        h[layout.H_TINT_R:layout.H_TINT_R + 3] = lobe.tint_r
        h[layout.H_TINT_T:layout.H_TINT_T + 3] = lobe.tint_t
        h[layout.H_F0:layout.H_F0 + 3] = lobe.f0
        h[layout.H_NORMAL + 2] = 1.0
        h[layout.H_SIGMA:layout.H_SIGMA + 3] = lobe.hair_sigma
    return lp, lt, hp


def _floats(a):
    """``a`` as the kernels take it (one compiled version per layout: keep to C-contiguous)."""
    return np.ascontiguousarray(a, np.float64)


def _bools(a):
    return np.ascontiguousarray(a, np.bool_)


class MaterialShader:
    """Evaluates and samples one material's lobes for batches of local directions.

    The lobes are packed once into flat arrays (see ``layout``) and every method is one
    compiled loop over the batch. A shader built with ``varying`` closures (closure index ->
    names of inputs that vary per hit) is bound to the hits of one call with ``bind``, which
    gives it a per-hit row of those inputs; methods then take ``rows``, the hits' positions in
    that binding (None: all of them, in order).
    """

    def __init__(self, material: Material, varying: dict | None = None, tables: Tables = EXACT):
        self.material = material
        self.lobes = lobes_of(material, tables)
        self.emission = material.emission
        self.sampled = [lobe for lobe in self.lobes if not lobe.bounces_diffuse]
        self.has_glass = any(lobe.kind == "glass" for lobe in self.lobes)
        self.hair = any(lobe.role in ("hair", "principled_hair") for lobe in self.lobes)
        """It has hair lobes: a bound shader takes their frames with ``turn_hair``."""
        for lobe in self.lobes:
            names = (varying or {}).get(lobe.source, ())
            if "color" in names and lobe.role == "metal":
                parts = tables.f82(lobe.alpha, lobe.f82) if tables.grid else None
                lobe.affine = _affine(lobe, *_f82_parts(lobe.f82), tables, _key("f82", lobe.f82), parts)
            elif "color" in names and lobe.role == "glossy":
                lobe.affine = _affine(lobe, lambda c: np.ones((len(c), 3)), lambda c: np.zeros((len(c), 3)), tables,
                                      ("glossy",))
            if "coat_normal" in names and any(m.role == "coat" and m.source == lobe.source for m in self.lobes):
                lobe.own_normal = lobe.role == "coat"
                lobe.under_own = lobe.role != "coat" and bool(lobe.layers)
        self.coat_normal = any(lobe.own_normal for lobe in self.lobes)
        """A lobe has its own normal per hit: a bound shader takes it with ``turn_coat``."""
        self.lp, self.lt, self.hp = _pack(self.lobes, self.sampled)
        self.mu = np.ascontiguousarray(mf.MU_TABLE, np.float64)
        self.bound = False
        self.holds_out = any(c.kind == "HOLDOUT" and (bool(c.inputs) or np.any(c.weight > 0))
                             for c in material.closures)
        self.holdout = sum((c.weight for c in material.closures if c.kind == "HOLDOUT"), np.zeros(3))
        """The Holdout closures' summed weight RGB: (3,), or (N, 3) per hit once bound."""

    @property
    def can_continue(self) -> bool:
        return bool(self.sampled)

    @property
    def lambertian(self) -> bool:
        """It has a diffuse part, and that is Lambert about the shading normal (no Oren-Nayar, no
        translucent lobe): what the ratio estimator's closed form is of (core.integrator.ratio)."""
        diffuse = [lobe.kind for lobe in self.lobes if lobe.diffuse]
        return bool(diffuse) and all(kind == "diffuse" for kind in diffuse)

    def bind(self, values: dict) -> "MaterialShader":
        """A copy whose lobes take per-hit values: ``values[closure index]`` maps "weight" and
        "color" to (N, 3) arrays (the shader was built with those set to one)."""
        n = len(next(v for d in values.values() for v in d.values()))
        hp = np.repeat(self.hp, n, axis=0)
        for l, lobe in enumerate(self.lobes):
            v = values.get(lobe.source, {})
            if "weight" in v:
                hp[:, l, layout.H_SCALE:layout.H_SCALE + 3] = v["weight"]
            if "coat_normal" in v and lobe.own_normal:
                hp[:, l, layout.H_NORMAL:layout.H_NORMAL + 3] = v["coat_normal"]  # world, until turn_coat
            if "hair_tangent" in v and lobe.hair:
                hp[:, l, layout.H_HAIR:layout.H_HAIR + 3] = v["hair_tangent"]  # world, until turn_hair
            color = v.get("color")
            if color is None:
                continue
            if lobe.role == "principled_hair":  # its colour is a reflectance: the absorption per hit
                hp[:, l, layout.H_SIGMA:layout.H_SIGMA + 3] = sigma_from_reflectance(color, lobe.hair_radial)
                continue
            if lobe.role == "hair":  # Cycles takes its colour as the weight, unclipped
                hp[:, l, layout.H_COLOUR:layout.H_COLOUR + 3] = color
                continue
            base = np.clip(color, 0.0, 1.0)
            if lobe.role in ("diffuse", "transparent", "translucent", "toon", "sheen"):
                hp[:, l, layout.H_COLOUR:layout.H_COLOUR + 3] = base
            elif lobe.role == "glass":
                hp[:, l, layout.H_TINT_T:layout.H_TINT_T + 3] = np.sqrt(base)
            elif lobe.role == "bsdf_glass":
                hp[:, l, layout.H_TINT_T:layout.H_TINT_T + 3] = base
                hp[:, l, layout.H_TINT_R:layout.H_TINT_R + 3] = base
            elif lobe.affine is not None:
                hp[:, l, layout.H_F0:layout.H_F0 + 3] = base
        bound = copy.copy(self)
        bound.hp, bound.bound = hp, True
        if self.holds_out:
            holdout = np.zeros((n, 3))
            for i, c in enumerate(self.material.closures):
                if c.kind == "HOLDOUT":
                    holdout += values.get(i, {}).get("weight", c.weight)
            bound.holdout = holdout
        return bound

    def coat_normals(self) -> np.ndarray:
        """(N, 3) the coat normal of each hit of its binding, as bound (world) or turned (local)."""
        l = next(l for l, lobe in enumerate(self.lobes) if lobe.own_normal)
        return self.hp[:, l, layout.H_NORMAL:layout.H_NORMAL + 3]

    def turn_coat(self, normal_l: np.ndarray, wo_l: np.ndarray) -> "MaterialShader":
        """The bound shader with its coat normal per hit in the local shading frame (``normal_l``, unit;
        wo may be below it where Bump Map Correction is off) and, for the coat and the lobes under it,
        where wo's cosine to it falls in the tables (``tables.locate``, clamped to them), whose albedos
        Cycles reads there."""
        hp = self.hp.copy()
        mu = self.mu
        c = np.clip(np.einsum("ij,ij->i", normal_l, wo_l), mu[0], mu[-1])
        j = np.clip(np.searchsorted(mu, c, side="right") - 1, 0, len(mu) - 2)
        t = (c - mu[j]) / (mu[j + 1] - mu[j])
        for l, lobe in enumerate(self.lobes):
            if lobe.own_normal:
                hp[:, l, layout.H_NORMAL:layout.H_NORMAL + 3] = normal_l
            if lobe.own_normal or lobe.under_own:
                hp[:, l, layout.H_PLACE], hp[:, l, layout.H_PLACE + 1] = j, t
        turned = copy.copy(self)
        turned.hp = hp
        return turned

    def turn_hair(self, to_local: Callable, ng_l: np.ndarray, n_l: np.ndarray, wo_l: np.ndarray) -> "MaterialShader":
        """The bound shader with each hit's hair frames: its hair lobes' tangents (world, as bound) in
        the shading frame (``to_local``) and what each model derives from them, the geometric normal
        facing wo ``ng_l``, the shading normal ``n_l`` and ``wo_l`` (local; hair_lobes.hair_frames)."""
        hp = self.hp.copy()
        tangent = np.zeros((len(hp), len(self.lobes), 3))
        for l, lobe in enumerate(self.lobes):
            if lobe.hair:
                tangent[:, l] = to_local(hp[:, l, layout.H_HAIR:layout.H_HAIR + 3])
        hair_frames(self.lp, hp, tangent, _floats(ng_l), _floats(n_l), _floats(wo_l))
        turned = copy.copy(self)
        turned.hp = hp
        return turned

    @property
    def blurs(self) -> bool:
        """It has lobes Filter Glossy blurs: GGX reflection and glass (core.bsdf.blur), Principled
        Hair (core.bsdf.hair_lobes)."""
        return any(lobe.kind in BLURRED for lobe in self.lobes)

    def blurred(self, roughness: np.ndarray) -> "MaterialShader":
        """The shader bound to n hits (itself bound to them or constant) whose blurred lobes
        (``BLURRED``) take at least roughness ``roughness`` (n,) at each (Filter Glossy)."""
        n = len(roughness)
        hp = self.hp.copy() if self.bound else np.repeat(self.hp, n, axis=0)
        for l, lobe in enumerate(self.lobes):
            if lobe.kind in BLURRED:
                hp[:, l, layout.H_BLUR] = roughness
        blurred = copy.copy(self)
        blurred.hp, blurred.bound = hp, True
        return blurred

    def take(self, rows) -> "MaterialShader":
        """The shader of the hits ``rows`` of its binding (itself when it is not bound)."""
        if not self.bound:
            return self
        taken = copy.copy(self)
        taken.hp = self.hp[rows]
        if self.holdout.ndim == 2:
            taken.holdout = self.holdout[rows]
        return taken

    def see_through_only(self) -> "MaterialShader":
        """The shader with its transparent lobes alone, no emission: what an object holdout keeps
        where the camera sees it (Cycles' surface_shader_apply_holdout)."""
        keep = [l for l, lobe in enumerate(self.lobes) if lobe.kind == "transparent"]
        clear = copy.copy(self)
        clear.lobes = clear.sampled = [self.lobes[l] for l in keep]
        clear.lp = np.ascontiguousarray(self.lp[keep])
        clear.lp[:, layout.P_SAMPLED] = np.arange(len(keep))
        clear.lt, clear.hp = np.ascontiguousarray(self.lt[keep]), np.ascontiguousarray(self.hp[:, keep])
        clear.emission, clear.has_glass, clear.holds_out, clear.holdout = np.zeros(3), False, False, np.zeros(3)
        clear.coat_normal = False
        return clear

    def holdout_weights(self, n) -> np.ndarray:
        """(n, 3) the Holdout closures' weight at each of the n hits of its binding."""
        return np.broadcast_to(self.holdout, (n, 3)) if self.holdout.ndim == 1 else self.holdout

    def hit_rows(self, n, rows=None) -> np.ndarray:
        """Row of ``hp`` each of n rays reads."""
        if not self.bound:
            return np.zeros(n, np.int64)
        return np.arange(n, dtype=np.int64) if rows is None else np.ascontiguousarray(rows, np.int64)

    # -- lobe selection ---------------------------------------------------------------
    def selection(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """(N, L) probabilities of continuing through each non-diffuse lobe."""
        out = np.zeros((len(mu_o), len(self.sampled)))
        selection_rows(self.lp, self.lt, self.hp, self.hit_rows(len(mu_o), rows), self.mu, _floats(mu_o), out)
        return out

    # -- evaluation -----------------------------------------------------------------
    def evaluate(self, wo: np.ndarray, wi: np.ndarray, above: np.ndarray, inside: np.ndarray, sel=None,
                 rows=None):
        """BSDF times |cos| for light sampling.

        ``above``: wi is on wo's side of the geometric surface; ``inside``: wo arrived
        from the back of the surface (glass sees the inverse IOR). Returns a BsdfValue (diffuse
        part, non-diffuse part, density of continuing in direction wi through the non-diffuse
        lobes, for multiple importance sampling). ``sel``: ``selection(wo[:, 2])`` when the
        caller has it already (it depends on wo only, so every light strategy shares it).
        """
        n = len(wo)
        if sel is None:
            sel = self.selection(wo[:, 2], rows)
        f_diff = np.empty((n, 3))
        f_nd = np.empty((n, 3))
        pdf = np.empty(n)
        evaluate_rows(self.lp, self.lt, self.hp, self.hit_rows(n, rows), self.mu, _floats(wo), _floats(wi),
                      _bools(above), _bools(inside), _floats(sel), f_diff, f_nd, pdf)
        return BsdfValue(diffuse=f_diff, glossy=f_nd, pdf=pdf)

    # -- sampling -------------------------------------------------------------------
    def sample(self, wo: np.ndarray, u_select: np.ndarray, u2: np.ndarray, inside: np.ndarray, rows=None):
        """Continue through one non-diffuse lobe chosen by its albedo.

        Returns a BsdfSample (wi, weight = f |cos| / pdf, pdf (0 for delta), delta flag, valid
        flag, pass-through flag: the transparent lobe was taken).
        For non-delta lobes the weight and pdf are those of the whole non-diffuse
        mixture (one-sample MIS over lobes), which multiple importance sampling with
        light sampling requires.
        """
        n = len(wo)
        wi = np.empty((n, 3))
        weight = np.empty((n, 3))
        pdf = np.empty(n)
        delta = np.empty(n, bool)
        valid = np.empty(n, bool)
        passthrough = np.empty(n, bool)
        sample_rows(self.lp, self.lt, self.hp, self.hit_rows(n, rows), self.mu, _floats(wo), _floats(u_select),
                    _floats(u2), _bools(inside), wi, weight, pdf, delta, valid, passthrough,
                    len(self.sampled))
        return BsdfSample(wi_l=wi, weight=weight, pdf=pdf, delta=delta, valid=valid, passthrough=passthrough)

    # -- albedo passes --------------------------------------------------------------
    def colors(self, mu_o: np.ndarray, rows=None):
        """(diffuse colour, glossy colour) as the DiffCol / GlossCol passes show them."""
        n = len(mu_o)
        diff = np.empty((n, 3))
        gloss = np.empty((n, 3))
        colours_rows(self.lp, self.lt, self.hp, self.hit_rows(n, rows), self.mu, _floats(mu_o), diff, gloss)
        return diff, gloss

    def transmission_color(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """The transmission colour as the TransCol pass shows it (zero without glass or hair transmission lobes)."""
        out = np.zeros((len(mu_o), 3))
        if self.has_glass or any(lobe.kind == "hair_transmission" for lobe in self.lobes):
            transmission_rows(self.lp, self.lt, self.hp, self.hit_rows(len(mu_o), rows), self.mu, _floats(mu_o), out)
        return out

    def denoising_albedos(self, mu_o: np.ndarray, inside: np.ndarray, rows=None):
        """(diffuse-like albedo, specular-like albedo, takes the features) per hit, as Cycles
        splits its closures for the Denoising Albedo pass (``passes.denoising_albedos``)."""
        n = len(mu_o)
        diff = np.empty((n, 3))
        spec = np.empty((n, 3))
        take = np.empty(n, bool)
        denoising_rows(self.lp, self.lt, self.hp, self.hit_rows(n, rows), self.mu, _floats(mu_o), _bools(inside),
                       diff, spec, take)
        return diff, spec, take

    def transparency(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """(N, 3) the transparent lobes' weight per hit: what Mist and the index passes see through."""
        out = np.zeros((len(mu_o), 3))
        if any(lobe.kind == "transparent" for lobe in self.lobes):
            transparency_rows(self.lp, self.lt, self.hp, self.hit_rows(len(mu_o), rows), self.mu, _floats(mu_o), out)
        return out

    def lobe_weights(self, mu_o: np.ndarray, rows=None) -> np.ndarray:
        """(N, L, 3) weight of each lobe at view cosines mu_o: its scale (weight, layers above,
        per-hit scale) times its multiple-scattering factor, what the albedo tables decide."""
        out = np.empty((len(mu_o), len(self.lobes), 3))
        weights_rows(self.lp, self.lt, self.hp, self.hit_rows(len(mu_o), rows), self.mu, _floats(mu_o), out)
        return out
