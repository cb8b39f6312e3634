"""Principled Hair BSDF, Huang model, as Cycles defines it (kernel/closure/bsdf_principled_hair_huang.h):
Huang, Hullin and Hanika, "A Microfacet-based Hair Scattering Model" (2022). The fiber is an
elliptic cylinder of GGX microfacets tilted by the cuticle angle; R is integrated over the fiber's
width with Simpson's rule, TT and TRT with Simpson's rule over the width and one sampled
microfacet normal per node, and TRRT+ is a geometric series spread as Chiang's longitudinal lobe.
Each interface's energy lost to single scattering is restored from Cycles' GGX glass albedo
tables (core.bsdf.ggx_glass_tables).

Only the far field is ported: Cycles takes its near field for camera rays on curves alone (a
mesh's pixel coverage is 1 and its projected radius 1), and a triangle mesh is all this engine
has. The frame is the mesh case of bsdf_hair_huang_setup: the tangent Y along dPdu, X = N
across both dPdu and the view (so the view's azimuth is 0) and h = -X . the shading normal; the
aspect ratio's frame swap and inversion apply to curves only, so a mesh keeps a ratio above 1.

Directions: ``wo`` toward the viewer (Cycles' sd->wi), ``wi`` toward the light or the sampled
direction (Cycles' wo argument), all in the caller's frame. As Cycles: eval's value includes the
cosine and its pdf is 1, sample's pdf is 1 and its value the path weight (the sampling density is
folded into it); 1 is no density, but eval and sample agree on it, which is what MIS needs.
They agree in energy on R, TT and TRT, not on TRRT+, as in Cycles: eval's Simpson rule weighs
the fiber's edges by the Jacobian 1 / cos gamma, which that term alone does not cancel with a
cosine, so a white furnace gives 1.64 by eval and 1.01 by sample at roughness 0.3.

Cycles draws the quadrature's and the sampler's further random numbers from an LCG the shading
point seeds from the path's random state (sd->lcg_state); a kernel here has no such state, so it
seeds the same LCG from a hash of its own inputs (eval: wo and wi; sample: its three random
numbers). Where Cycles' arithmetic gives inf or NaN (sigma infinite, a fiber seen along its
tangent, a zero dPdu, terms at exactly grazing microfacets) the term is 0 here, and a zero or
non-finite dPdu takes a tangent across the shading normal.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel
from ..base.vectors import cross3, dot3, safe_unit
from ..base.warps import concentric_disk
from .ggx_glass_tables import GLASS_E
from .hair_chiang import longitudinal
from .microfacet import fresnel_dielectric1

ROUGH_MIN = 1e-3
"""bsdf_hair_huang_setup clamps the roughness to [1e-3, 1]."""
_M32 = 0xFFFFFFFF


def huang_constants(roughness, tilt, ior, aspect_ratio, r_gain, tt_gain, trt_gain):
    """(roughness, tilt, eta, aspect ratio, R, TT, TRT) as svm_node_closure and bsdf_hair_huang_setup
    leave them: the roughness (Random Roughness already applied, hair_absorption.random_factor) clamped to
    [0.001, 1], the Offset negated, the gains at least 0; IOR and aspect ratio as given (only a
    curve swaps its axes for a ratio above 1). Floats or NumPy arrays."""
    def value(x):
        return np.asarray(x, np.float64)[()]

    return (np.clip(value(roughness), ROUGH_MIN, 1.0), -value(tilt), value(ior), value(aspect_ratio),
            np.maximum(value(r_gain), 0.0), np.maximum(value(tt_gain), 0.0), np.maximum(value(trt_gain), 0.0))


def huang_present(r_gain, tt_gain, trt_gain):
    """Whether the svm makes the closure at all: not where R, TT and TRT are all at most 0 (the
    kernels then give 0 and sample nothing)."""
    return ~((np.asarray(r_gain) <= 0.0) & (np.asarray(tt_gain) <= 0.0) & (np.asarray(trt_gain) <= 0.0))


# -- Cycles' small helpers (util/math, sample/mapping, sample/lcg, util/hash) --

@kernel(inline="always")
def _usable(x, y, z):
    """Neither zero nor with a non-finite component."""
    return (x != 0.0 or y != 0.0 or z != 0.0) and math.isfinite(x) and math.isfinite(y) and math.isfinite(z)


@kernel(inline="always")
def _orthonormals(nx, ny, nz):
    """make_orthonormals: a unit a across the unit n (from (1, 1, 1) x n, or (-1, 1, 1) x n), and n x a."""
    if nx != ny or nx != nz:
        ax, ay, az = safe_unit(nz - ny, nx - nz, ny - nx)
    else:
        ax, ay, az = safe_unit(nz - ny, nx + nz, -ny - nx)
    bx, by, bz = cross3(nx, ny, nz, ax, ay, az)
    return ax, ay, az, bx, by, bz


@kernel(inline="always")
def _reflect(ix, iy, iz, nx, ny, nz):
    """reflect: incident - 2 (incident . n) n."""
    d = 2.0 * dot3(ix, iy, iz, nx, ny, nz)
    return ix - d * nx, iy - d * ny, iz - d * nz


@kernel(inline="always")
def _refract_angle(ix, iy, iz, nx, ny, nz, cos_t, inv_eta):
    """refract_angle: the refracted direction from the cosine of the refraction angle."""
    s = inv_eta * dot3(nx, ny, nz, ix, iy, iz) + cos_t
    return s * nx - inv_eta * ix, s * ny - inv_eta * iy, s * nz - inv_eta * iz


@kernel(inline="always")
def _visible(vx, vy, vz, mx, my, mz, hx, hy, hz):
    """microfacet_visible: both the micronormal h and the mesonormal m face v."""
    return dot3(vx, vy, vz, hx, hy, hz) > 0.0 and dot3(vx, vy, vz, mx, my, mz) > 0.0


@kernel(inline="always")
def _lcg(state):
    """lcg_step_float: (the next state, its number in [0, 1])."""
    state = (1103515245 * state + 12345) & _M32
    return state, state * (1.0 / 4294967295.0)


@kernel(inline="always")
def _rot(x, k):
    """A 32-bit rotation left by k."""
    return ((x << k) | (x >> (32 - k))) & _M32


@kernel(inline="always")
def _hash3(kx, ky, kz):
    """hash_uint3: Jenkins' lookup3 final mix of three 32-bit integers."""
    a = b = c = (0xDEADBEEF + (3 << 2) + 13) & _M32
    c = (c + kz) & _M32
    b = (b + ky) & _M32
    a = (a + kx) & _M32
    c ^= b
    c = (c - _rot(b, 14)) & _M32
    a ^= c
    a = (a - _rot(c, 11)) & _M32
    b ^= a
    b = (b - _rot(a, 25)) & _M32
    c ^= b
    c = (c - _rot(b, 16)) & _M32
    a ^= c
    a = (a - _rot(c, 4)) & _M32
    b ^= a
    b = (b - _rot(a, 14)) & _M32
    c ^= b
    c = (c - _rot(b, 24)) & _M32
    return c


@kernel(inline="always")
def _bits(x):
    """A 32-bit integer from a number in [-1, 1] (0 for anything else), to hash into a seed."""
    if not abs(x) <= 1.0:
        return 0
    return int((x + 1.0) * 2147483647.5)


# -- microfacet terms (bsdf_microfacet.h, GGX) and Fresnel (bsdf_util.h) --

@kernel(inline="always")
def _lambda(alpha2, cos_n):
    """bsdf_lambda: Smith's GGX Lambda."""
    return 0.5 * (math.sqrt(1.0 + alpha2 * max(1.0 / (cos_n * cos_n) - 1.0, 0.0)) - 1.0)


@kernel(inline="always")
def _g(alpha2, cos_i, cos_o):
    """bsdf_G: height-correlated shadowing-masking."""
    return 1.0 / (1.0 + _lambda(alpha2, cos_i) + _lambda(alpha2, cos_o))


@kernel(inline="always")
def _go(alpha2, cos_i, cos_o):
    """bsdf_Go: shadowing-masking divided by the masking toward i."""
    lambda_i = _lambda(alpha2, cos_i)
    return (1.0 + lambda_i) / (1.0 + lambda_i + _lambda(alpha2, cos_o))


@kernel(inline="always")
def _d(alpha2, cos_h):
    """bsdf_D: the GGX distribution (of cos_h squared)."""
    c2 = min(cos_h * cos_h, 1.0)
    s = 1.0 - c2 + alpha2 * c2
    return alpha2 / (math.pi * s * s)


@kernel(inline="always")
def _sample_vndf(wx, wy, wz, alpha, u0, u1):
    """microfacet_ggx_sample_vndf (isotropic): Heitz 2018's visible normal toward w."""
    vx, vy, vz = safe_unit(alpha * wx, alpha * wy, wz)
    lensq = vx * vx + vy * vy
    if lensq > 1e-7:
        inv = 1.0 / math.sqrt(lensq)
        t1x, t1y, t1z = -vy * inv, vx * inv, 0.0
        t2x, t2y, t2z = cross3(vx, vy, vz, t1x, t1y, t1z)
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
        t2x, t2y, t2z = 0.0, 1.0, 0.0
    px, py = concentric_disk(u0, u1)
    py = math.sqrt(max(1.0 - px * px, 0.0)) + 0.5 * (1.0 + vz) * (py - math.sqrt(max(1.0 - px * px, 0.0)))
    pz = math.sqrt(max(1.0 - px * px - py * py, 0.0))
    hx = px * t1x + py * t2x + pz * vx
    hy = px * t1y + py * t2y + pz * vy
    hz = px * t1z + py * t2z + pz * vz
    return safe_unit(alpha * hx, alpha * hy, max(0.0, hz))


@kernel(inline="always")
def _sample_wh(roughness, wx, wy, wz, mx, my, mz, u0, u1):
    """sample_wh: a GGX microfacet normal visible from w about the mesonormal m."""
    sx, sy, sz, tx, ty, tz = _orthonormals(mx, my, mz)
    hx, hy, hz = _sample_vndf(dot3(wx, wy, wz, sx, sy, sz), dot3(wx, wy, wz, tx, ty, tz),
                              dot3(wx, wy, wz, mx, my, mz), roughness, u0, u1)
    return hx * sx + hy * tx + hz * mx, hx * sy + hy * ty + hz * my, hx * sz + hy * tz + hz * mz


@kernel(inline="always")
def _fresnel(cos_i, eta):
    """fresnel_dielectric: (unpolarised reflectance, cosine of the refracted ray to the normal);
    total internal reflection gives (1, 0) (Cycles leaves that cosine unset)."""
    s = eta * eta - (1.0 - cos_i * cos_i)
    if not s > 0.0:
        return 1.0, 0.0
    c = abs(cos_i)
    cos_t = -math.sqrt(s) / eta
    r_s = (c + eta * cos_t) / (c - eta * cos_t)
    r_p = (cos_t + eta * c) / (eta * c - cos_t)
    return 0.5 * (r_s * r_s + r_p * r_p), cos_t


@kernel(inline="always")
def _read(k, base, x):
    """lookup_table_read: row ``base`` of table k (16 values over [0, 1]), linear in x."""
    x = min(max(x, 0.0), 1.0) * 15.0 if x == x else 0.0
    i = min(int(x), 15)
    n = min(i + 1, 15)
    t = x - i
    return (1.0 - t) * GLASS_E[k, base + i] + t * GLASS_E[k, base + n]


@kernel(inline="always")
def _read2(k, base, x, y):
    """lookup_table_read_2D: x along a row, y across the 16 rows."""
    y = min(max(y, 0.0), 1.0) * 15.0 if y == y else 0.0
    i = min(int(y), 15)
    n = min(i + 1, 15)
    t = y - i
    return (1.0 - t) * _read(k, base + 16 * i, x) + t * _read(k, base + 16 * n, x)


@kernel(inline="always")
def _energy_scale(mu, rough, ior):
    """bsdf_hair_huang_energy_scale: 1 / the GGX glass albedo (lookup_table_read_3D of ggx_glass_E,
    or ggx_glass_inv_E for an IOR below 1) at sqrt(roughness) ``rough``, cosine mu and sqrt|F0|'s root."""
    k = 1 if ior < 1.0 else 0
    z = math.sqrt(abs((ior - 1.0) / (ior + 1.0)))
    z = min(max(z, 0.0), 1.0) * 15.0 if z == z else 0.0
    i = min(int(z), 15)
    n = min(i + 1, 15)
    t = z - i
    return 1.0 / ((1.0 - t) * _read2(k, 256 * i, rough, mu) + t * _read2(k, 256 * n, rough, mu))


# -- hair geometry (the top of bsdf_principled_hair_huang.h); the local frame is (X, Y, Z), Y the tangent --

@kernel(inline="always")
def _cos_theta(x, z):
    """cos_theta of a local direction: its length across the tangent."""
    return math.sqrt(x * x + z * z)


@kernel(inline="always")
def _to_phi(gamma, b):
    """to_phi: the azimuth of the ellipse's normal at parameter gamma."""
    if b == 1.0:
        return gamma
    return math.atan2(b * math.sin(gamma), math.cos(gamma))


@kernel(inline="always")
def _to_gamma(phi, b):
    """to_gamma: the ellipse parameter where the normal has azimuth phi."""
    if b == 1.0:
        return phi
    return math.atan2(math.sin(phi), b * math.cos(phi))


@kernel(inline="always")
def _phi_to_h(phi, b, sin_phi_i, cos_phi_i):
    """phi_to_h: the offset h across the view of the point whose normal has azimuth phi."""
    if b == 1.0:
        return -math.sin(phi)
    gamma = _to_gamma(phi, b)
    return -cos_phi_i * math.sin(gamma) + b * sin_phi_i * math.cos(gamma)


@kernel(inline="always")
def _h_to_gamma(h, b, ix, iz):
    """h_to_gamma: the ellipse parameter hit at offset h (divided by the radius) across the view."""
    if b == 1.0:
        return -math.asin(h)
    return math.atan2(iz, -b * ix) - math.acos(-h)


@kernel(inline="always")
def _d_gamma_d_h(sin_phi_i, cos_phi_i, gamma, b):
    """d_gamma_d_h: the Jacobian |d gamma / d h| (0 where it diverges, as safe_divide)."""
    if b == 1.0:
        d = math.cos(gamma)
    else:
        d = cos_phi_i * math.cos(gamma) + b * sin_phi_i * math.sin(gamma)
    return 1.0 / d if d != 0.0 else 0.0


@kernel(inline="always")
def _sphg_dir(theta, gamma, b):
    """sphg_dir: the direction at longitude theta whose azimuth is the ellipse's normal at gamma."""
    st, ct = math.sin(theta), math.cos(theta)
    sg, cg = math.sin(gamma), math.cos(gamma)
    if b == 1.0 or abs(cg) < 1e-6:
        sp, cp = sg, cg
    else:
        tan_phi = b * sg / cg
        cp = (-1.0 if cg < 0.0 else 1.0) / math.sqrt(tan_phi * tan_phi + 1.0)
        sp = cp * tan_phi
    return sp * ct, st, cp * ct


@kernel(inline="always")
def _chord(gamma0, gamma1, b):
    """|to_point(gamma0) - to_point(gamma1)|: the length between two points of the ellipse."""
    dx = math.sin(gamma0) - math.sin(gamma1)
    dz = b * (math.cos(gamma0) - math.cos(gamma1))
    return math.sqrt(dx * dx + dz * dz)


@kernel(inline="always")
def _arc_length(e2, gamma):
    """arc_length: the ellipse's length element at gamma (1 for a circle)."""
    if e2 == 0.0:
        return 1.0
    s = math.sin(gamma)
    return math.sqrt(max(1.0 - e2 * s * s, 0.0))


@kernel(inline="always")
def _radius(e2, ix, iz):
    """extra->radius: the ellipse's projected half width seen from the local view (ix, iz) (not both 0)."""
    if e2 == 0.0:
        return 1.0
    return math.sqrt(max(1.0 - e2 * ix * ix / (ix * ix + iz * iz), 0.0))


@kernel(inline="always")
def _absorption(sigma, cos_t, length):
    """exp(sigma / cos_t * length) as Cycles writes its A terms (``length`` signed as there); 1 for no absorption."""
    if sigma == 0.0:
        return 1.0
    return math.exp(sigma / cos_t * length)


@kernel(inline="always")
def _trrt(t, r, a):
    """bsdf_hair_huang_eval_trrt: the series of bounces beyond TRT for one channel."""
    t_avg = max(1.0 - r, 1e-5)
    return t * r * r * t_avg * a * a * a / (1.0 - a * (1.0 - t_avg))


# -- per hit --

@kernel(inline="always")
def huang_frame(dx, dy, dz, nx, ny, nz, wox, woy, woz):
    """(Y, X, h) = (yx, yy, yz, xx, xy, xz, h) of the hit from dPdu d, the shading normal n and wo:
    Y = safe_normalize(d), X = safe_normalize(d x wo), h = -X . n, then X made from Y where it is
    zero or not finite (make_orthonormals(Y, &Z, &X), Cycles' arbitrary frame). A zero or
    non-finite d takes the make_orthonormals tangent of n instead (Cycles' frame is NaN there),
    and a non-finite h is 0."""
    if not _usable(dx, dy, dz):
        if _usable(nx, ny, nz):
            ux, uy, uz = safe_unit(nx, ny, nz)
            dx, dy, dz, _, _, _ = _orthonormals(ux, uy, uz)
        else:
            dx, dy, dz = 1.0, 0.0, 0.0
    yx, yy, yz = safe_unit(dx, dy, dz)
    cx, cy, cz = cross3(dx, dy, dz, wox, woy, woz)
    xx, xy, xz = safe_unit(cx, cy, cz)
    h = -dot3(xx, xy, xz, nx, ny, nz)
    if not math.isfinite(h):
        h = 0.0
    if not _usable(xx, xy, xz):
        _, _, _, xx, xy, xz = _orthonormals(yx, yy, yz)
    return yx, yy, yz, xx, xy, xz, h


@kernel(inline="always")
def _local(yx, yy, yz, xx, xy, xz, x, y, z):
    """The caller's direction (x, y, z) in the hair frame (X, Y, Z = X x Y)."""
    zx, zy, zz = cross3(xx, xy, xz, yx, yy, yz)
    return dot3(x, y, z, xx, xy, xz), dot3(x, y, z, yx, yy, yz), dot3(x, y, z, zx, zy, zz)


@kernel(inline="always")
def _series(f, sigma, cos_t, spread):
    """One channel of ``huang_albedo``: (A - 2 f A + f) / (1 - f A), A the absorption of the path
    across the fiber (1 without absorption, 0 along a refracted ray with no spread)."""
    x = 2.0 * sigma * cos_t
    if x != x:  # an infinite absorption at total internal reflection: nothing crosses
        x = -math.inf
    a = math.exp(x / spread) if spread > 0.0 else (1.0 if x == 0.0 else 0.0)
    d = 1.0 - f * a
    return (a - 2.0 * f * a + f) / d if d != 0.0 else 0.0


@kernel(inline="always")
def huang_albedo(eta, sg0, sg1, sg2, yx, yy, yz, xx, xy, xz, h, wox, woy, woz):
    """bsdf_hair_huang_albedo, RGB: Cycles' estimate of the closure's albedo for its passes (GlossCol,
    the denoising albedo), the geometric series of specular bounces inside a circular fiber hit at
    offset h. Arguments: the IOR, the absorption sigma RGB, ``huang_frame``'s seven values, wo.

    (bsdf_hair_huang_setup also turns the closure into a transparent one where |h| reaches the
    projected radius; on a mesh that radius is 1 and |h| = |X . N| reaches it only where the
    shading normal lies across both dPdu and wo: a view exactly grazing the surface, never made.)"""
    ix, iy, iz = _local(yx, yy, yz, xx, xy, xz, wox, woy, woz)
    ch = math.sqrt(max(1.0 - h * h, 0.0))
    f, cos_t = _fresnel(h * ix + ch * iz, eta)
    _, wty, _ = _refract_angle(ix, iy, iz, h, 0.0, ch, cos_t, 1.0 / eta)
    spread = 1.0 - wty * wty
    return _series(f, sg0, cos_t, spread), _series(f, sg1, cos_t, spread), _series(f, sg2, cos_t, spread)


# -- eval (bsdf_hair_huang_eval, far field) --

@kernel(inline="always")
def _eval_r(rough, tilt, eta, b, gain, hmin, hmax, ix, iy, iz, ox, oy, oz, cos_i):
    """bsdf_hair_huang_eval_r: the primary reflection, Simpson's rule over h in [hmin, hmax]."""
    if gain <= 0.0:
        return 0.0
    hx, hy, hz = safe_unit(ix + ox, iy + oy, iz + oz)
    if hx == 0.0 and hy == 0.0 and hz == 0.0:  # wi opposite wo: no half vector
        return 0.0
    alpha2 = rough * rough
    sqrt_rough = math.sqrt(rough)
    e2 = 1.0 - b * b
    sin_phi_i, cos_phi_i = ix / cos_i, iz / cos_i
    h_range = hmax - hmin
    intervals = 2 * int(math.ceil(h_range / (rough * 0.7) * 0.5))
    res = h_range / intervals
    integral = 0.0
    for i in range(intervals + 1):
        gamma = _h_to_gamma(hmin + i * res, b, ix, iz)
        mx, my, mz = _sphg_dir(tilt, gamma, b)
        if _visible(ix, iy, iz, mx, 0.0, mz, hx, hy, hz) and _visible(ox, oy, oz, mx, 0.0, mz, hx, hy, hz):
            weight = (0.5 if i == 0 or i == intervals else i % 2 + 1.0) * _d_gamma_d_h(sin_phi_i, cos_phi_i, gamma, b)
            cos_mi = dot3(mx, my, mz, ix, iy, iz)
            term = (weight * _d(alpha2, dot3(mx, my, mz, hx, hy, hz)) * _g(alpha2, cos_mi, dot3(mx, my, mz, ox, oy, oz))
                    * _arc_length(e2, gamma) * _energy_scale(cos_mi, sqrt_rough, eta))
            if math.isfinite(term):
                integral += term
    integral *= 2.0 / 3.0 * res
    return gain * 0.25 * fresnel_dielectric1(abs(dot3(ix, iy, iz, hx, hy, hz)), eta) * integral


@kernel(inline="always")
def _eval_residual(rough, tilt, eta, b, gtt, gtrt, sg0, sg1, sg2, hmin, hmax, ix, iy, iz, ox, oy, oz, cos_i, state):
    """bsdf_hair_huang_eval_residual: TT and TRT by Simpson's rule over h with one sampled
    microfacet normal per node and interface (the LCG from ``state``), TRRT+ as a series spread
    by Chiang's longitudinal lobe; RGB."""
    if gtt <= 0.0 and gtrt <= 0.0:
        return 0.0, 0.0, 0.0
    inv_eta = 1.0 / eta
    alpha2 = rough * rough
    sqrt_rough = math.sqrt(rough)
    e2 = 1.0 - b * b
    sin_phi_i, cos_phi_i = ix / cos_i, iz / cos_i
    h_range = hmax - hmin
    intervals = 2 * int(math.ceil(h_range / (rough * 0.8) * 0.5))
    res = h_range / intervals
    tt0 = tt1 = tt2 = trt0 = trt1 = trt2 = rr0 = rr1 = rr2 = 0.0
    for i in range(intervals + 1):
        gamma_mi = _h_to_gamma(hmin + i * res, b, ix, iz)
        mix_, miy, miz = _sphg_dir(tilt, gamma_mi, b)
        nix, niy, niz = _sphg_dir(0.0, gamma_mi, b)
        state, r0 = _lcg(state)
        state, r1 = _lcg(state)
        h1x, h1y, h1z = _sample_wh(rough, ix, iy, iz, mix_, miy, miz, r0, r1)
        cos_hi1 = dot3(ix, iy, iz, h1x, h1y, h1z)
        if not cos_hi1 > 0.0:
            continue
        cos_mi1 = dot3(ix, iy, iz, mix_, miy, miz)
        f1, cos_t1 = _fresnel(cos_hi1, eta)
        t1 = 1.0 - f1
        scale1 = _energy_scale(cos_mi1, sqrt_rough, eta)
        # refraction at the first interface
        wtx, wty, wtz = _refract_angle(ix, iy, iz, h1x, h1y, h1z, cos_t1, inv_eta)
        phi_t = math.atan2(wtx, wtz)
        gamma_mt = 2.0 * _to_phi(phi_t, b) - gamma_mi
        mtx, mty, mtz = _sphg_dir(-tilt, gamma_mt, b)
        ntx, nty, ntz = _sphg_dir(0.0, gamma_mt, b)
        cos_mo1 = -dot3(wtx, wty, wtz, mix_, miy, miz)
        cos_mi2 = -dot3(wtx, wty, wtz, mtx, mty, mtz)
        g1o = _go(alpha2, cos_mi1, cos_mo1)
        if not (_visible(ix, iy, iz, mix_, miy, miz, h1x, h1y, h1z)
                and _visible(-wtx, -wty, -wtz, mix_, miy, miz, h1x, h1y, h1z)
                and _visible(ix, iy, iz, nix, niy, niz, h1x, h1y, h1z)
                and _visible(-wtx, -wty, -wtz, nix, niy, niz, h1x, h1y, h1z)):
            continue
        weight = (0.5 if i == 0 or i == intervals else i % 2 + 1.0) * _d_gamma_d_h(sin_phi_i, cos_phi_i, gamma_mi, b)
        cos_wt = _cos_theta(wtx, wtz)
        length_t = 2.0 * math.cos(gamma_mi - phi_t) if b == 1.0 else -_chord(gamma_mi, gamma_mt + math.pi, b)
        at0 = _absorption(sg0, cos_wt, length_t)
        at1 = _absorption(sg1, cos_wt, length_t)
        at2 = _absorption(sg2, cos_wt, length_t)
        scale2 = _energy_scale(cos_mi2, sqrt_rough, inv_eta)
        if gtt > 0.0 and dot3(ox, oy, oz, wtx, wty, wtz) >= inv_eta - 1e-5:  # total internal reflection otherwise
            w2x, w2y, w2z = -wtx + inv_eta * ox, -wty + inv_eta * oy, -wtz + inv_eta * oz
            rcp_norm = 1.0 / math.sqrt(w2x * w2x + w2y * w2y + w2z * w2z)
            w2x, w2y, w2z = w2x * rcp_norm, w2y * rcp_norm, w2z * rcp_norm
            cos_mh2 = dot3(mtx, mty, mtz, w2x, w2y, w2z)
            if cos_mh2 >= 0.0:  # microfacet visible from the macronormal
                cos_hi2 = -dot3(wtx, wty, wtz, w2x, w2y, w2z)
                cos_ho2 = -dot3(ox, oy, oz, w2x, w2y, w2z)
                cos_mo2 = -dot3(ox, oy, oz, mtx, mty, mtz)
                t2 = (1.0 - fresnel_dielectric1(abs(cos_hi2), inv_eta)) * scale2
                common = (weight * t1 * scale1 * t2 * _d(alpha2, cos_mh2) * g1o * _g(alpha2, cos_mi2, cos_mo2) / cos_mo1
                          * cos_mi1 * cos_hi2 * cos_ho2 * rcp_norm * rcp_norm)
                arc = gtt * _arc_length(e2, gamma_mt)
                r_0, r_1, r_2 = common * at0, common * at1, common * at2
                if math.isfinite(r_0) and math.isfinite(r_1) and math.isfinite(r_2):
                    tt0 += arc * r_0
                    tt1 += arc * r_1
                    tt2 += arc * r_2
        if gtrt > 0.0:
            state, r0 = _lcg(state)
            state, r1 = _lcg(state)
            h2x, h2y, h2z = _sample_wh(rough, -wtx, -wty, -wtz, mtx, mty, mtz, r0, r1)
            cos_hi2 = -dot3(wtx, wty, wtz, h2x, h2y, h2z)
            if not cos_hi2 > 0.0:
                continue
            r2 = fresnel_dielectric1(abs(cos_hi2), inv_eta)
            q0, q1, q2 = _trrt(t1, r2, at0), _trrt(t1, r2, at1), _trrt(t1, r2, at2)
            trrt_ok = math.isfinite(q0) and math.isfinite(q1) and math.isfinite(q2)
            rx, ry, rz = _reflect(wtx, wty, wtz, h2x, h2y, h2z)
            wrx, wry, wrz = -rx, -ry, -rz
            if -dot3(wrx, wry, wrz, ox, oy, oz) < inv_eta - 1e-5:  # total internal reflection
                if trrt_ok:
                    rr0, rr1, rr2 = rr0 + weight * q0, rr1 + weight * q1, rr2 + weight * q2
                continue
            if not (_visible(-wtx, -wty, -wtz, mtx, mty, mtz, h2x, h2y, h2z)
                    and _visible(-wrx, -wry, -wrz, mtx, mty, mtz, h2x, h2y, h2z)
                    and _visible(-wtx, -wty, -wtz, ntx, nty, ntz, h2x, h2y, h2z)
                    and _visible(-wrx, -wry, -wrz, ntx, nty, ntz, h2x, h2y, h2z)):
                continue
            phi_tr = math.atan2(wrx, wrz)
            gamma_mtr = gamma_mi - 2.0 * (_to_phi(phi_t, b) - _to_phi(phi_tr, b)) + math.pi
            mrx, mry, mrz = _sphg_dir(-tilt, gamma_mtr, b)
            nrx, nry, nrz = _sphg_dir(0.0, gamma_mtr, b)
            w3x, w3y, w3z = wrx + inv_eta * ox, wry + inv_eta * oy, wrz + inv_eta * oz
            rcp_norm3 = 1.0 / math.sqrt(w3x * w3x + w3y * w3y + w3z * w3z)
            w3x, w3y, w3z = w3x * rcp_norm3, w3y * rcp_norm3, w3z * rcp_norm3
            cos_mh3 = dot3(mrx, mry, mrz, w3x, w3y, w3z)
            if (cos_mh3 < 0.0 or not _visible(wrx, wry, wrz, mrx, mry, mrz, w3x, w3y, w3z)
                    or not _visible(-ox, -oy, -oz, mrx, mry, mrz, w3x, w3y, w3z)
                    or not _visible(wrx, wry, wrz, nrx, nry, nrz, w3x, w3y, w3z)
                    or not _visible(-ox, -oy, -oz, nrx, nry, nrz, w3x, w3y, w3z)):
                if trrt_ok:
                    rr0, rr1, rr2 = rr0 + weight * q0, rr1 + weight * q1, rr2 + weight * q2
                continue
            cos_hi3 = dot3(w3x, w3y, w3z, wrx, wry, wrz)
            cos_ho3 = -dot3(w3x, w3y, w3z, ox, oy, oz)
            cos_mi3 = dot3(mrx, mry, mrz, wrx, wry, wrz)
            t3 = (1.0 - fresnel_dielectric1(abs(cos_hi3), inv_eta)) * _energy_scale(cos_mi3, sqrt_rough, inv_eta)
            cos_wr = _cos_theta(wrx, wrz)
            length_r = -(2.0 * abs(math.cos(phi_tr - gamma_mt)) if b == 1.0 else _chord(gamma_mtr, gamma_mt, b))
            cos_mo2 = -dot3(mtx, mty, mtz, wrx, wry, wrz)
            common = (weight * t1 * scale1 * r2 * scale2 * t3 * _d(alpha2, cos_mh3) * g1o
                      * _go(alpha2, cos_mi2, cos_mo2)
                      * _g(alpha2, cos_mi3, -dot3(mrx, mry, mrz, ox, oy, oz)) / (cos_mo1 * cos_mo2)
                      * cos_mi1 * cos_mi2 * cos_hi3 * cos_ho3 * rcp_norm3 * rcp_norm3)
            r_0 = common * at0 * _absorption(sg0, cos_wr, length_r)
            r_1 = common * at1 * _absorption(sg1, cos_wr, length_r)
            r_2 = common * at2 * _absorption(sg2, cos_wr, length_r)
            if math.isfinite(r_0) and math.isfinite(r_1) and math.isfinite(r_2):
                arc = gtrt * _arc_length(e2, gamma_mtr)
                trt0 += arc * r_0
                trt1 += arc * r_1
                trt2 += arc * r_2
            if trrt_ok:
                rr0, rr1, rr2 = rr0 + weight * q0, rr1 + weight * q1, rr2 + weight * q2
    spread = (longitudinal(iy, cos_i, oy, _cos_theta(ox, oz), 4.0 * rough)
              * (1.0 / (2.0 * math.pi)) * (2.0 / math.pi))
    k = inv_eta * inv_eta
    simpson = 2.0 / 3.0 * res
    return ((tt0 + trt0) * k + rr0 * spread) * simpson, ((tt1 + trt1) * k + rr1 * spread) * simpson, \
        ((tt2 + trt2) * k + rr2 * spread) * simpson


@kernel(inline="always")
def huang_eval(rough, tilt, eta, aspect_ratio, r_gain, tt_gain, trt_gain, sg0, sg1, sg2,
               yx, yy, yz, xx, xy, xz, wox, woy, woz, wix, wiy, wiz):
    """(f0, f1, f2, pdf): bsdf_hair_huang_eval toward wi, f |cos| RGB without the closure's weight,
    pdf 1 (0 where the svm makes no closure: all gains 0). Arguments in order: ``huang_constants``'
    seven (roughness, tilt, eta, aspect ratio, R, TT, TRT gains), the absorption sigma RGB,
    ``huang_frame``'s Y and X (its h is for ``huang_albedo``), wo, wi."""
    if r_gain <= 0.0 and tt_gain <= 0.0 and trt_gain <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    ix, iy, iz = _local(yx, yy, yz, xx, xy, xz, wox, woy, woz)
    ox, oy, oz = _local(yx, yy, yz, xx, xy, xz, wix, wiy, wiz)
    cos_i = _cos_theta(ix, iz)
    if not cos_i > 0.0:  # the view along the tangent: no projected area (Cycles divides by 0)
        return 0.0, 0.0, 0.0, 1.0
    tan_tilt = math.tan(tilt)
    cos_o = _cos_theta(ox, oz)
    below = tan_tilt * oy / cos_o < -1.0 if cos_o > 0.0 else tan_tilt * oy < 0.0
    if below:  # the light below every mesonormal
        return 0.0, 0.0, 0.0, 1.0
    v = -tan_tilt * (iy / cos_i)
    if not v > 0.0:
        v = 0.0
    if v > 1.0:  # the view below every mesonormal
        return 0.0, 0.0, 0.0, 1.0
    half_span = math.acos(v)
    b = aspect_ratio
    e2 = 1.0 - b * b
    phi_i = 0.0 if b == 1.0 else math.atan2(ix, iz)
    r = _radius(e2, ix, iz)
    hmin = max(_phi_to_h(phi_i + half_span, b, ix / cos_i, iz / cos_i) / r, -0.999)
    hmax = min(_phi_to_h(phi_i - half_span, b, ix / cos_i, iz / cos_i) / r, 0.999)
    if not hmin < hmax:  # the visible range misses the fiber (grazing theta)
        return 0.0, 0.0, 0.0, 1.0
    state = _hash3(_hash3(_bits(wix), _bits(wiy), _bits(wiz)) ^ _bits(woz), _bits(wox), _bits(woy))
    fr = _eval_r(rough, tilt, eta, b, r_gain, hmin, hmax, ix, iy, iz, ox, oy, oz, cos_i)
    f0, f1, f2 = _eval_residual(rough, tilt, eta, b, tt_gain, trt_gain, sg0, sg1, sg2, hmin, hmax,
                                ix, iy, iz, ox, oy, oz, cos_i, state)
    area = 2.0 * cos_i
    f0, f1, f2 = (fr + f0) / area, (fr + f1) / area, (fr + f2) / area
    if not (math.isfinite(f0) and math.isfinite(f1) and math.isfinite(f2)):
        return 0.0, 0.0, 0.0, 1.0
    return f0, f1, f2, 1.0


# -- sample (bsdf_hair_huang_sample, far field) --

@kernel(inline="always")
def _finite_or_0(a, b, c):
    """(a, b, c), or zeros where any is not finite."""
    if math.isfinite(a) and math.isfinite(b) and math.isfinite(c):
        return a, b, c
    return 0.0, 0.0, 0.0


@kernel(inline="always")
def _residual(tr, k, a_t, a_tr, t_avg):
    """The sampled TRRT+ weight of one channel: TR R3 Go times the series A T + A^2 R T + ... with
    A the geometric mean of the two attenuations and T the mean transmission."""
    a_avg = math.sqrt(a_t * a_tr)
    return tr * k * a_avg * t_avg / (1.0 - a_avg * (1.0 - t_avg))


@kernel(inline="always")
def huang_sample(rough, tilt, eta, aspect_ratio, r_gain, tt_gain, trt_gain, sg0, sg1, sg2,
                 yx, yy, yz, xx, xy, xz, wox, woy, woz, u0, u1, u2):
    """(wix, wiy, wiz, f0, f1, f2, pdf, reflect): bsdf_hair_huang_sample with rand = (u0, u1, u2):
    a lobe chosen by energy (u0), h across the fiber (u1), the first microfacet normal (u2 and the
    LCG), the rest from the LCG. f is the path weight RGB without the closure's weight, pdf 1,
    ``reflect`` True (Cycles' LABEL_GLOSSY | LABEL_REFLECT); nothing sampled: zeros and False.
    Arguments as ``huang_eval``'s with the random numbers in wi's place."""
    none = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False)
    if r_gain <= 0.0 and tt_gain <= 0.0 and trt_gain <= 0.0:
        return none
    ix, iy, iz = _local(yx, yy, yz, xx, xy, xz, wox, woy, woz)
    if not _cos_theta(ix, iz) > 0.0:
        return none
    state = _hash3(_bits(u0), _bits(u1), _bits(u2))
    state, v = _lcg(state)
    sample_h1 = (u2, v)
    state, a = _lcg(state)
    state, c = _lcg(state)
    sample_h2 = (a, c)
    state, a = _lcg(state)
    state, c = _lcg(state)
    sample_h3 = (a, c)
    b = aspect_ratio
    gamma_mi = _h_to_gamma(u1 * 2.0 - 1.0, b, ix, iz)
    nix, niy, niz = _sphg_dir(0.0, gamma_mi, b)  # macronormal
    st, ct = math.sin(tilt), math.cos(tilt)
    mix_, miy, miz = nix * ct, st, niz * ct  # mesonormal
    cos_mi1 = dot3(mix_, miy, miz, ix, iy, iz)
    if cos_mi1 < 0.0 or dot3(nix, niy, niz, ix, iy, iz) < 0.0:
        return none
    # R
    alpha2 = rough * rough
    sqrt_rough = math.sqrt(rough)
    h1x, h1y, h1z = _sample_wh(rough, ix, iy, iz, mix_, miy, miz, sample_h1[0], sample_h1[1])
    rx, ry, rz = _reflect(ix, iy, iz, h1x, h1y, h1z)
    wrx, wry, wrz = -rx, -ry, -rz
    if not _visible(ix, iy, iz, nix, niy, niz, h1x, h1y, h1z):
        return none
    r1, cos_t1 = _fresnel(dot3(ix, iy, iz, h1x, h1y, h1z), eta)
    scale1 = _energy_scale(cos_mi1, sqrt_rough, eta)
    lobe_r = (r_gain * r1 * scale1 * (1.0 if _visible(wrx, wry, wrz, nix, niy, niz, h1x, h1y, h1z) else 0.0)
              * _go(alpha2, cos_mi1, dot3(mix_, miy, miz, wrx, wry, wrz)))
    if not math.isfinite(lobe_r):
        lobe_r = 0.0
    # TT
    inv_eta = 1.0 / eta
    wtx, wty, wtz = _refract_angle(ix, iy, iz, h1x, h1y, h1z, cos_t1, inv_eta)
    phi_t = math.atan2(wtx, wtz)
    gamma_mt = 2.0 * _to_phi(phi_t, b) - gamma_mi
    mtx, mty, mtz = _sphg_dir(-tilt, gamma_mt, b)
    ntx, nty, ntz = _sphg_dir(0.0, gamma_mt, b)
    h2x, h2y, h2z = _sample_wh(rough, -wtx, -wty, -wtz, mtx, mty, mtz, sample_h2[0], sample_h2[1])
    qx, qy, qz = _reflect(wtx, wty, wtz, h2x, h2y, h2z)
    wrx2, wry2, wrz2 = -qx, -qy, -qz  # wtr
    ttx = tty = ttz = trtx = trty = trtz = rrx = rry = rrz = 0.0
    tt0 = tt1 = tt2 = trt0 = trt1 = trt2 = rr0 = rr1 = rr2 = 0.0
    cos_mi2 = -dot3(wtx, wty, wtz, mtx, mty, mtz)
    if (cos_mi2 > 0.0 and _visible(-wtx, -wty, -wtz, nix, niy, niz, h1x, h1y, h1z)
            and _visible(-wtx, -wty, -wtz, ntx, nty, ntz, h2x, h2y, h2z)):
        cos_wt = _cos_theta(wtx, wtz)
        length_t = 2.0 * math.cos(phi_t - gamma_mi) if b == 1.0 else -_chord(gamma_mi, gamma_mt + math.pi, b)
        at0 = _absorption(sg0, cos_wt, length_t)
        at1 = _absorption(sg1, cos_wt, length_t)
        at2 = _absorption(sg2, cos_wt, length_t)
        r2, cos_t2 = _fresnel(-dot3(wtx, wty, wtz, h2x, h2y, h2z), inv_eta)
        t1 = (1.0 - r1) * scale1 * _go(alpha2, cos_mi1, -dot3(mix_, miy, miz, wtx, wty, wtz))
        t2 = 1.0 - r2
        scale2 = _energy_scale(cos_mi2, sqrt_rough, inv_eta)
        ttx, tty, ttz = _refract_angle(-wtx, -wty, -wtz, h2x, h2y, h2z, cos_t2, eta)
        if (-dot3(mtx, mty, mtz, ttx, tty, ttz) > 0.0 and t2 > 0.0
                and _visible(-ttx, -tty, -ttz, ntx, nty, ntz, h2x, h2y, h2z)):
            k = tt_gain * t1 * t2 * scale2 * _go(alpha2, cos_mi2, -dot3(mtx, mty, mtz, ttx, tty, ttz))
            tt0, tt1, tt2 = _finite_or_0(k * at0, k * at1, k * at2)
        # TRT
        phi_tr = math.atan2(wrx2, wrz2)
        gamma_mtr = gamma_mi - 2.0 * (_to_phi(phi_t, b) - _to_phi(phi_tr, b)) + math.pi
        mrx, mry, mrz = _sphg_dir(-tilt, gamma_mtr, b)
        h3x, h3y, h3z = _sample_wh(rough, wrx2, wry2, wrz2, mrx, mry, mrz, sample_h3[0], sample_h3[1])
        r3, cos_t3 = _fresnel(dot3(wrx2, wry2, wrz2, h3x, h3y, h3z), inv_eta)
        trtx, trty, trtz = _refract_angle(wrx2, wry2, wrz2, h3x, h3y, h3z, cos_t3, eta)
        cos_mi3 = dot3(mrx, mry, mrz, wrx2, wry2, wrz2)
        if cos_mi3 > 0.0:
            cos_wr = _cos_theta(wrx2, wrz2)
            length_r = -(2.0 * abs(math.cos(phi_tr - gamma_mt)) if b == 1.0 else _chord(gamma_mt, gamma_mtr, b))
            atr0 = _absorption(sg0, cos_wr, length_r)
            atr1 = _absorption(sg1, cos_wr, length_r)
            atr2 = _absorption(sg2, cos_wr, length_r)
            k = (t1 * r2 * scale2 * _energy_scale(cos_mi3, sqrt_rough, inv_eta)
                 * _go(alpha2, cos_mi2, -dot3(mtx, mty, mtz, wrx2, wry2, wrz2)))
            tr0, tr1, tr2 = k * at0 * atr0, k * at1 * atr1, k * at2 * atr2
            t3 = 1.0 - r3
            if t3 > 0.0 and _visible(wrx2, wry2, wrz2, mrx, 0.0, mrz, h3x, h3y, h3z) \
                    and _visible(-trtx, -trty, -trtz, mrx, 0.0, mrz, h3x, h3y, h3z):
                k = trt_gain * t3 * _go(alpha2, cos_mi3, -dot3(mrx, mry, mrz, trtx, trty, trtz))
                trt0, trt1, trt2 = _finite_or_0(k * tr0, k * tr1, k * tr2)
            # TRRT+: theta from Chiang's longitudinal lobe, phi uniform
            state, v = _lcg(state)
            rand_theta = max(v, 1e-5)
            fac = 1.0 + 4.0 * rough * math.log(rand_theta + (1.0 - rand_theta) * math.exp(-0.5 / rough))
            state, v = _lcg(state)
            sin_theta_o = (-fac * iy + math.sqrt(max(1.0 - fac * fac, 0.0)) * math.cos(2.0 * math.pi * v)
                           * _cos_theta(ix, iz))
            cos_theta_o = math.sqrt(max(1.0 - sin_theta_o * sin_theta_o, 0.0))
            state, v = _lcg(state)
            phi_o = 2.0 * math.pi * v
            rrx, rry, rrz = math.sin(phi_o) * cos_theta_o, sin_theta_o, math.cos(phi_o) * cos_theta_o
            t_avg = max(0.5 * (t2 + t3), 1e-5)
            fx, fy, fz = _reflect(wrx2, wry2, wrz2, h3x, h3y, h3z)
            k = r3 * _go(alpha2, cos_mi3, dot3(mrx, mry, mrz, fx, fy, fz))
            rr0, rr1, rr2 = _finite_or_0(_residual(tr0, k, at0, atr0, t_avg), _residual(tr1, k, at1, atr1, t_avg),
                                         _residual(tr2, k, at2, atr2, t_avg))
    # the lobe by energy
    tt = (tt0 + tt1 + tt2) / 3.0
    trt = (trt0 + trt1 + trt2) / 3.0
    trrt = (rr0 + rr1 + rr2) / 3.0
    total = lobe_r + tt + trt + trrt
    if not total > 0.0:
        return none
    pick = u0 * total
    if pick < lobe_r:
        ox, oy, oz, f0, f1, f2 = wrx, wry, wrz, total, total, total
    elif pick < lobe_r + tt:
        ox, oy, oz, f0, f1, f2 = ttx, tty, ttz, tt0 / tt * total, tt1 / tt * total, tt2 / tt * total
    elif pick < lobe_r + tt + trt:
        ox, oy, oz, f0, f1, f2 = trtx, trty, trtz, trt0 / trt * total, trt1 / trt * total, trt2 / trt * total
    elif trrt > 0.0:
        ox, oy, oz, f0, f1, f2 = rrx, rry, rrz, rr0 / trrt * total, rr1 / trrt * total, rr2 / trrt * total
    else:  # u0 * total rounded up to total with no TRRT+
        return none
    zx, zy, zz = cross3(xx, xy, xz, yx, yy, yz)
    return (ox * xx + oy * yx + oz * zx, ox * xy + oy * yy + oz * zy, ox * xz + oy * yz + oz * zz,
            f0, f1, f2, 1.0, True)
