"""GGX microfacet terms, Fresnel, and their sampling, vectorised in a local frame.

Local frame: z is the (shading) normal. All functions take arrays of shape (N, 3) for
directions and scalar material parameters (one material is shaded at a time).
Alpha below ``DELTA_ALPHA`` is treated as a perfect mirror or smooth interface: the
microfacet normal is the macro normal, but the lobe keeps the albedo of GGX at its own
alpha (masking matters within a fraction of a degree of grazing, where alpha·tanθ is no
longer small), so brightness is continuous across the switch at every view angle.
Albedo tables are dense near grazing (``MU_TABLE``) for the same reason: a nearly smooth
lobe changes within mu ~ alpha of the horizon.
"""
from __future__ import annotations

import functools

import numpy as np

DELTA_ALPHA = 1e-4
MU_TABLE = np.unique(np.concatenate([np.geomspace(1e-5, 1.0 / 64, 12), np.linspace(1.0 / 64, 1.0, 32)]))
"""Cosines the albedo tables are computed at: geometric steps toward the horizon, linear above."""
_TINY = 1e-30


def dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def dot_with(v, w):
    """Rows of v (N, 3) dotted with one vector w, written out: BLAS (``v @ w``) spends more on
    waking its threads than on such products (2x slower renders measured on a loaded 2-core
    machine), and its rounding depends on the build."""
    return v[:, 0] * w[0] + v[:, 1] * w[1] + v[:, 2] * w[2]


def transform(v, m):
    """Rows of v (N, 3) times a 3x3 matrix: ``v @ m.T`` without BLAS (see ``dot_with``)."""
    return v[:, 0:1] * m[:, 0] + v[:, 1:2] * m[:, 1] + v[:, 2:3] * m[:, 2]


def norm(v):
    """Lengths of 3-vectors along the last axis, summed in np.linalg.norm's order (a NumPy
    reduction over a length-3 axis costs ~10x these three products)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.sqrt(x * x + y * y + z * z)


def max3(v):
    """Largest of the three components along the last axis (~30x faster than .max(axis=-1))."""
    return np.maximum(np.maximum(v[..., 0], v[..., 1]), v[..., 2])


def orthonormal_basis(n):
    """Two unit vectors completing each unit row of n to a right-handed frame (Duff et al. 2017)."""
    s = np.where(n[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (s + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + s * n[:, 0] ** 2 * a, s * b, -s * n[:, 0]], axis=1)
    bt = np.stack([b, s + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bt


def normalize(v, tiny: float = _TINY):
    """Unit vectors along the last axis; lengths under ``tiny`` count as ``tiny``."""
    return v / np.maximum(norm(v)[..., None], tiny)


def ggx_d(cos_h: np.ndarray, alpha: float) -> np.ndarray:
    a2 = alpha * alpha
    c2 = cos_h * cos_h
    return np.where(cos_h > 0, a2 / (np.pi * np.maximum((c2 * (a2 - 1.0) + 1.0) ** 2, _TINY)), 0.0)


def ggx_lambda(cos_t: np.ndarray, alpha: float) -> np.ndarray:
    c2 = np.clip(cos_t * cos_t, _TINY, 1.0)
    tan2 = (1.0 - c2) / c2
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


def ggx_g1(cos_t, alpha):
    return 1.0 / (1.0 + ggx_lambda(cos_t, alpha))


def ggx_g2(cos_o, cos_i, alpha):
    """Height-correlated masking-shadowing."""
    return 1.0 / (1.0 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha))


def sample_visible_normal(wo: np.ndarray, alpha: float, u: np.ndarray) -> np.ndarray:
    """Heitz 2018: sample a microfacet normal from the distribution of visible normals."""
    flip = wo[:, 2] < 0
    w = np.where(flip[:, None], -wo, wo)
    vh = normalize(np.stack([alpha * w[:, 0], alpha * w[:, 1], w[:, 2]], axis=1))
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    inv = 1.0 / np.sqrt(np.maximum(lensq, _TINY))
    t1 = np.where((lensq > 0)[:, None], np.stack([-vh[:, 1] * inv, vh[:, 0] * inv, np.zeros_like(inv)], 1),
                  np.array([1.0, 0.0, 0.0]))
    t2 = np.cross(vh, t1)
    r = np.sqrt(u[:, 0])
    phi = 2.0 * np.pi * u[:, 1]
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vh[:, 2])
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    nh = p1[:, None] * t1 + p2[:, None] * t2 + np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))[:, None] * vh
    return normalize(np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(nh[:, 2], 1e-12)], axis=1))


def visible_normal_pdf(wo, h, alpha):
    """Density of ``sample_visible_normal`` (per solid angle of h); wo may be below."""
    cos_o = np.abs(wo[:, 2])
    return ggx_g1(cos_o, alpha) * np.abs(dot(wo, h)) * ggx_d(h[:, 2], alpha) / np.maximum(cos_o, _TINY)


def fresnel_dielectric(cos_i: np.ndarray, eta: float | np.ndarray) -> np.ndarray:
    """Exact unpolarised Fresnel reflectance; eta = n_inside / n_outside, cos_i < 0 from inside."""
    eta = np.where(cos_i < 0, 1.0 / eta, eta)
    c = np.abs(cos_i)
    g2 = eta * eta - 1.0 + c * c
    tir = g2 <= 0
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / np.maximum(g + c, _TINY)
    b = (c * (g + c) - 1.0) / np.maximum(c * (g - c) + 1.0, _TINY)
    f = 0.5 * a * a * (1.0 + b * b)
    return np.where(tir, 1.0, np.clip(f, 0.0, 1.0))


def f0_from_ior(ior):
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def ior_from_f0(f0):
    s = np.sqrt(np.clip(f0, 0.0, 0.9999))
    return (1.0 + s) / (1.0 - s)


F82_K = (1.0 - 1.0 / 7.0) ** 5
"""Schlick's (1 - c)^5 at the F82 cosine c = 1/7."""
F82_M = (1.0 / 7.0) * (1.0 - 1.0 / 7.0) ** 6
"""The F82 correction's c (1 - c)^6 at c = 1/7."""


def fresnel_f82(cos_i: np.ndarray, f0: np.ndarray, f82: np.ndarray) -> np.ndarray:
    """Metal Fresnel: Schlick with the F82-tint correction (Hoffman 2019), as Cycles."""
    c = np.clip(cos_i, 0.0, 1.0)[:, None]
    schlick = f0 + (1.0 - f0) * (1.0 - c) ** 5
    schlick_mu = f0 + (1.0 - f0) * F82_K
    b = schlick_mu * (1.0 - f82) / F82_M
    return np.clip(schlick - b * c * (1.0 - c) ** 6, 0.0, 1.0)


def reflect(wo, h):
    return 2.0 * dot(wo, h)[:, None] * h - wo


def refract(wo, h, eta):
    """Refract wo about h; eta = n_(wi side) / n_(wo side). Returns (wi, valid)."""
    eta = np.broadcast_to(eta, (len(wo),))
    c = dot(wo, h)
    k = 1.0 - (1.0 - c * c) / (eta * eta)
    valid = k > 0
    wi = -wo / eta[:, None] + (c / eta - np.sign(c) * np.sqrt(np.maximum(k, 0.0)))[:, None] * h
    return normalize(wi), valid


def cosine_hemisphere(u: np.ndarray) -> np.ndarray:
    """Concentric-disk mapping lifted to the hemisphere (local z up)."""
    d = concentric_disk(u)
    z = np.sqrt(np.maximum(1.0 - (d * d).sum(axis=1), 0.0))
    return np.concatenate([d, z[:, None]], axis=1)


def concentric_disk(u: np.ndarray) -> np.ndarray:
    a = 2.0 * u[:, 0] - 1.0
    b = 2.0 * u[:, 1] - 1.0
    first = np.abs(a) > np.abs(b)
    r = np.where(first, a, b)
    safe_a = np.where(a == 0, 1.0, a)
    safe_b = np.where(b == 0, 1.0, b)
    phi = np.where(first, (np.pi / 4) * (b / safe_a), np.pi / 2 - (np.pi / 4) * (a / safe_b))
    phi = np.where((a == 0) & (b == 0), 0.0, phi)
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)


def directional_albedo(alpha: float, fresnel, n_samples: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Albedo E(mu) of a GGX reflection lobe with the given Fresnel(cos_h) -> (N,) or (N,3).

    Computed once per material with a fixed stratified pattern (deterministic),
    tabulated at the cosines ``MU_TABLE``; returns (mu, E).
    """
    mu = MU_TABLE
    n_mu = len(mu)
    from .sampling import Sampler  # deterministic Owen-scrambled Sobol points

    g = Sampler("SOBOL", n_samples, seed=0x5AB1E).get2d(np.zeros(n_samples, np.int64), np.arange(n_samples), 0)
    m = len(g)
    wo = np.stack([np.sqrt(1 - mu * mu), np.zeros_like(mu), mu], axis=1)
    wo_r = np.repeat(wo, m, axis=0)
    u = np.tile(g, (n_mu, 1))
    h = sample_visible_normal(wo_r, alpha, u)  # also below DELTA_ALPHA: sampling stays exact there
    wi = reflect(wo_r, h)
    ok = wi[:, 2] > 0
    weight = np.where(ok, ggx_g2(wo_r[:, 2], wi[:, 2], alpha) / ggx_g1(wo_r[:, 2], alpha), 0.0)
    f = np.asarray(fresnel(dot(wo_r, h)))
    if f.ndim == 2:
        e = (f * weight[:, None]).reshape(n_mu, m, -1).mean(axis=1)
    else:
        e = (f * weight).reshape(n_mu, m).mean(axis=1)
    return mu, e


@functools.lru_cache(maxsize=256)
def white_albedo(alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Single-scatter albedo of GGX with F = 1, shared by every lobe of that roughness."""
    return directional_albedo(alpha, lambda c: np.ones_like(c))


def lookup(mu_table: np.ndarray, values: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Linear interpolation of a per-material albedo table at cosines ``mu``."""
    mu = np.clip(mu, 0.0, 1.0)
    if values.ndim == 1:
        return np.interp(mu, mu_table, values)
    return np.stack([np.interp(mu, mu_table, values[:, k]) for k in range(values.shape[1])], axis=1)
