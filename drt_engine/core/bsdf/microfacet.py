"""GGX microfacet terms, Fresnel, and their sampling in a local frame; albedo tables.

Local frame: z is the (shading) normal. The microfacet terms are scalar kernels (one
direction's components and numbers in, a few numbers out) that the lobe modules
(``reflection``, ``glass``) and ``passes`` call per ray (vectors and frames are core.base.vectors).
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

from ..base.constants import TINY
from ..base.jit import kernel
from ..base.vectors import unit

DELTA_ALPHA = 1e-4
MU_GRAZING, MU_SPLIT, MU_GEOMETRIC, MU_LINEAR = 1e-5, 1.0 / 64, 12, 32
MU_TABLE = np.unique(np.concatenate([np.geomspace(MU_GRAZING, MU_SPLIT, MU_GEOMETRIC),
                                     np.linspace(MU_SPLIT, 1.0, MU_LINEAR)]))
"""Cosines the albedo tables are computed at: geometric steps toward the horizon, linear above."""


@kernel
def ggx_d(cos_h, alpha):
    """GGX normal distribution D(h) for one microfacet normal (zero below the surface)."""
    if not cos_h > 0.0:
        return 0.0
    a2 = alpha * alpha
    c2 = cos_h * cos_h
    return a2 / (np.pi * max((c2 * (a2 - 1.0) + 1.0) ** 2, TINY))


@kernel
def ggx_lambda(cos_t, alpha):
    c2 = min(max(cos_t * cos_t, TINY), 1.0)
    tan2 = (1.0 - c2) / c2
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


@kernel
def ggx_g1(cos_t, alpha):
    return 1.0 / (1.0 + ggx_lambda(cos_t, alpha))


@kernel
def ggx_g2(cos_o, cos_i, alpha):
    """Height-correlated masking-shadowing."""
    return 1.0 / (1.0 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha))


@kernel
def ggx_d_aniso(hx, hy, hz, alpha_x, alpha_y):
    """Anisotropic GGX D(h), roughness alpha_x along the frame's x and alpha_y along its y
    (Cycles' bsdf_aniso_D); zero below the surface."""
    if not hz > 0.0:
        return 0.0
    x, y = hx / alpha_x, hy / alpha_y
    s = x * x + y * y + hz * hz
    return 1.0 / (np.pi * alpha_x * alpha_y * max(s * s, TINY))


@kernel
def ggx_lambda_aniso(wx, wy, wz, alpha_x, alpha_y):
    """Smith Lambda of anisotropic GGX toward w (either side): the isotropic form with
    alpha² tan² replaced by (alpha_x² x² + alpha_y² y²) / z²."""
    x, y = alpha_x * wx, alpha_y * wy
    return 0.5 * (np.sqrt(1.0 + (x * x + y * y) / max(wz * wz, TINY)) - 1.0)


@kernel
def sample_visible_normal(wx, wy, wz, alpha_x, alpha_y, u0, u1):
    """Heitz 2018: a microfacet normal from the distribution of normals visible from w
    (anisotropic: the view stretched by alpha_x, alpha_y onto the hemisphere configuration)."""
    if wz < 0.0:
        wx, wy, wz = -wx, -wy, -wz
    vx, vy, vz = unit(alpha_x * wx, alpha_y * wy, wz)
    lensq = vx * vx + vy * vy
    if lensq > 0.0:
        inv = 1.0 / np.sqrt(max(lensq, TINY))
        t1x, t1y, t1z = -vy * inv, vx * inv, 0.0
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
    t2x, t2y, t2z = vy * t1z - vz * t1y, vz * t1x - vx * t1z, vx * t1y - vy * t1x
    r = np.sqrt(u0)
    phi = 2.0 * np.pi * u1
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * np.sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0))
    nx = p1 * t1x + p2 * t2x + p3 * vx
    ny = p1 * t1y + p2 * t2y + p3 * vy
    nz = p1 * t1z + p2 * t2z + p3 * vz
    return unit(alpha_x * nx, alpha_y * ny, max(nz, 1e-12))


@kernel
def visible_normal_pdf(wx, wy, wz, hx, hy, hz, alpha):
    """Density of ``sample_visible_normal`` (per solid angle of h); w may be below."""
    cos_o = abs(wz)
    return ggx_g1(cos_o, alpha) * abs(wx * hx + wy * hy + wz * hz) * ggx_d(hz, alpha) / max(cos_o, TINY)


@kernel
def fresnel_dielectric1(cos_i, eta):
    """Exact unpolarised Fresnel reflectance; eta = n_inside / n_outside, cos_i < 0 from inside."""
    if cos_i < 0.0:
        eta = 1.0 / eta
    c = abs(cos_i)
    g2 = eta * eta - 1.0 + c * c
    if g2 <= 0.0:
        return 1.0
    g = np.sqrt(g2)
    a = (g - c) / max(g + c, TINY)
    b = (c * (g + c) - 1.0) / max(c * (g - c) + 1.0, TINY)
    return min(max(0.5 * a * a * (1.0 + b * b), 0.0), 1.0)


@kernel
def _fresnel_dielectric_rows(cos_i, eta, out):
    for i in range(len(cos_i)):
        out[i] = fresnel_dielectric1(cos_i[i], eta[i])


def fresnel_dielectric(cos_i: np.ndarray, eta) -> np.ndarray:
    """``fresnel_dielectric1`` over an array of cosines (eta: one number or one per cosine)."""
    cos_i = np.ascontiguousarray(cos_i, np.float64)
    out = np.empty(len(cos_i))
    _fresnel_dielectric_rows(cos_i, np.ascontiguousarray(np.broadcast_to(eta, cos_i.shape), np.float64), out)
    return out


def f0_from_ior(ior):
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def ior_from_f0(f0):
    s = np.sqrt(np.clip(f0, 0.0, 0.9999))
    return (1.0 + s) / (1.0 - s)


F82_K = (1.0 - 1.0 / 7.0) ** 5
"""Schlick's (1 - c)^5 at the F82 cosine c = 1/7."""
F82_M = (1.0 / 7.0) * (1.0 - 1.0 / 7.0) ** 6
"""The F82 correction's c (1 - c)^6 at c = 1/7."""


def conductor_f82(n, k) -> tuple[np.ndarray, np.ndarray]:
    """(f0, F82 tint) per channel of a conductor of complex IOR n + ik: its exact Fresnel at normal
    incidence, and at the F82 cosine 1/7 its ratio to Schlick's from that f0 (Hoffman's F82-tint
    fit of a measured metal; for Blender's Metallic BSDF in Physical Conductor mode)."""
    eta = np.asarray(n, np.float64) + 1j * np.asarray(k, np.float64)

    def fresnel(c):
        cos_t = np.sqrt(1.0 - (1.0 - c * c) / (eta * eta))
        r_s = (c - eta * cos_t) / (c + eta * cos_t)
        r_p = (eta * c - cos_t) / (eta * c + cos_t)
        return 0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2)

    f0 = fresnel(1.0)
    return f0, fresnel(1.0 / 7.0) / (f0 + (1.0 - f0) * F82_K)


@kernel
def f82_parts(cos_i, f82):
    """Metal Fresnel (Schlick with the F82-tint correction, Hoffman 2019, as Cycles) of one colour
    channel, before clipping, as f0 A + B: returns (A, B). Affine in f0, so its albedo tables
    split in two that a per-hit colour f0 combines."""
    c = min(max(cos_i, 0.0), 1.0)
    scale = (1.0 - f82) / F82_M
    schlick = (1.0 - c) ** 5
    bump = scale * c * (1.0 - c) ** 6
    return 1.0 - schlick - (1.0 - F82_K) * bump, schlick - F82_K * bump


@kernel
def fresnel_f82(cos_i, f0, f82):
    """Metal Fresnel of one colour channel: clip(f0 A + B) (see ``f82_parts``)."""
    a, b = f82_parts(cos_i, f82)
    return min(max(f0 * a + b, 0.0), 1.0)


@kernel
def refract(wx, wy, wz, hx, hy, hz, eta):
    """Refract w about h; eta = n_(refracted side) / n_(w side). Returns (x, y, z, valid)."""
    c = wx * hx + wy * hy + wz * hz
    k = 1.0 - (1.0 - c * c) / (eta * eta)
    s = c / eta - np.sign(c) * np.sqrt(max(k, 0.0))
    x, y, z = unit(-wx / eta + s * hx, -wy / eta + s * hy, -wz / eta + s * hz)
    return x, y, z, k > 0.0


@kernel
def _albedo_samples(mu, u, alpha, cos_oh, weight):
    """For each view cosine and sample point: cos(wo, h) of a sampled visible normal h and
    the masking weight G2/G1 of its mirror direction (0 below the horizon)."""
    m = len(u)
    for k in range(len(mu)):
        wx, wz = np.sqrt(1.0 - mu[k] * mu[k]), mu[k]
        for j in range(m):
            hx, hy, hz = sample_visible_normal(wx, 0.0, wz, alpha, alpha, u[j, 0], u[j, 1])
            c = wx * hx + wz * hz
            i = k * m + j
            cos_oh[i] = c
            wiz = 2.0 * c * hz - wz
            weight[i] = ggx_g2(wz, wiz, alpha) / ggx_g1(wz, alpha) if wiz > 0.0 else 0.0


def directional_albedo(alpha: float, fresnel, n_samples: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Albedo E(mu) of a GGX reflection lobe with the given Fresnel(cos_h) -> (N,) or (N,3).

    Computed once per material with a fixed stratified pattern (deterministic),
    tabulated at the cosines ``MU_TABLE``; returns (mu, E).
    """
    mu = MU_TABLE
    n_mu = len(mu)
    from ..sampling.sampler import Sampler  # deterministic Owen-scrambled Sobol points

    g = Sampler("SOBOL", n_samples, seed=0x5AB1E).get2d(np.zeros(n_samples, np.int64), np.arange(n_samples), 0)
    m = len(g)
    cos_oh = np.empty(n_mu * m)
    weight = np.empty(n_mu * m)
    # also below DELTA_ALPHA: sampling stays exact there
    _albedo_samples(mu, np.ascontiguousarray(g, np.float64), float(alpha), cos_oh, weight)
    f = np.asarray(fresnel(cos_oh))
    if f.ndim == 2:
        e = (f * weight[:, None]).reshape(n_mu, m, -1).mean(axis=1)
    else:
        e = (f * weight).reshape(n_mu, m).mean(axis=1)
    return mu, e


@functools.lru_cache(maxsize=256)
def white_albedo(alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Single-scatter albedo of GGX with F = 1, shared by every lobe of that roughness."""
    return directional_albedo(alpha, lambda c: np.ones_like(c))
