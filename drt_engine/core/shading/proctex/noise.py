"""Perlin noise and its fractal sums, as Cycles' SVM computes them (svm/noise.h,
fractal_noise.h, noisetex.h): the same lattice hash, gradients, fade curve, scale factors,
octave loops and seeds. Arithmetic is in float64; what Cycles hashes (integer lattice
coordinates) is exact either way, so values differ from Cycles' float32 only in the last bits.
"""
from __future__ import annotations

import math

import numpy as np

from ...base.jit import kernel
from .hash import hash_f1, hash_f2, hash_uint, hash_uint2, hash_uint3, hash_uint4

FBM, MULTIFRACTAL, HYBRID_MULTIFRACTAL, RIDGED_MULTIFRACTAL, HETERO_TERRAIN = 0, 1, 2, 3, 4
NOISE_TYPES = {"FBM": FBM, "MULTIFRACTAL": MULTIFRACTAL, "HYBRID_MULTIFRACTAL": HYBRID_MULTIFRACTAL,
               "RIDGED_MULTIFRACTAL": RIDGED_MULTIFRACTAL, "HETERO_TERRAIN": HETERO_TERRAIN}
_PERIOD = 100000.0
"""Cycles repeats the noise every 100000 units on each axis (fmod) to keep float32 precision."""


@kernel
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@kernel
def _neg(v, cond):
    return -v if cond else v


@kernel
def _grad1(h, x):
    h = h & 15
    return _neg(1.0 + (h & 7), h & 8) * x


@kernel
def _grad2(h, x, y):
    h = h & 7
    u = x if h < 4 else y
    v = 2.0 * (y if h < 4 else x)
    return _neg(u, h & 1) + _neg(v, h & 2)


@kernel
def _grad3(h, x, y, z):
    h = h & 15
    u = x if h < 8 else y
    vt = x if (h == 12 or h == 14) else z
    v = y if h < 4 else vt
    return _neg(u, h & 1) + _neg(v, h & 2)


@kernel
def _grad4(h, x, y, z, w):
    h = h & 31
    u = x if h < 24 else y
    v = y if h < 16 else z
    s = z if h < 8 else w
    return _neg(u, h & 1) + _neg(v, h & 2) + _neg(s, h & 4)


@kernel
def _mix(a, b, t):
    return a + t * (b - a)


@kernel
def _perlin1(x):
    fl = math.floor(x)
    X = int(fl)
    fx = x - fl
    return _mix(_grad1(hash_uint(X), fx), _grad1(hash_uint(X + 1), fx - 1.0), _fade(fx))


@kernel
def _perlin2(x, y):
    flx, fly = math.floor(x), math.floor(y)
    X, Y = int(flx), int(fly)
    fx, fy = x - flx, y - fly
    u, v = _fade(fx), _fade(fy)
    v0 = _grad2(hash_uint2(X, Y), fx, fy)
    v1 = _grad2(hash_uint2(X + 1, Y), fx - 1.0, fy)
    v2 = _grad2(hash_uint2(X, Y + 1), fx, fy - 1.0)
    v3 = _grad2(hash_uint2(X + 1, Y + 1), fx - 1.0, fy - 1.0)
    return (1.0 - v) * (v0 * (1.0 - u) + v1 * u) + v * (v2 * (1.0 - u) + v3 * u)


@kernel
def _trilerp(v0, v1, v2, v3, v4, v5, v6, v7, x, y, z):
    x1, y1, z1 = 1.0 - x, 1.0 - y, 1.0 - z
    return (z1 * (y1 * (v0 * x1 + v1 * x) + y * (v2 * x1 + v3 * x))
            + z * (y1 * (v4 * x1 + v5 * x) + y * (v6 * x1 + v7 * x)))


@kernel
def _perlin3(x, y, z):
    flx, fly, flz = math.floor(x), math.floor(y), math.floor(z)
    X, Y, Z = int(flx), int(fly), int(flz)
    fx, fy, fz = x - flx, y - fly, z - flz
    return _trilerp(
        _grad3(hash_uint3(X, Y, Z), fx, fy, fz),
        _grad3(hash_uint3(X + 1, Y, Z), fx - 1.0, fy, fz),
        _grad3(hash_uint3(X, Y + 1, Z), fx, fy - 1.0, fz),
        _grad3(hash_uint3(X + 1, Y + 1, Z), fx - 1.0, fy - 1.0, fz),
        _grad3(hash_uint3(X, Y, Z + 1), fx, fy, fz - 1.0),
        _grad3(hash_uint3(X + 1, Y, Z + 1), fx - 1.0, fy, fz - 1.0),
        _grad3(hash_uint3(X, Y + 1, Z + 1), fx, fy - 1.0, fz - 1.0),
        _grad3(hash_uint3(X + 1, Y + 1, Z + 1), fx - 1.0, fy - 1.0, fz - 1.0),
        _fade(fx), _fade(fy), _fade(fz))


@kernel
def _perlin4_slice(X, Y, Z, W, fx, fy, fz, fw, u, v, t):
    return _trilerp(
        _grad4(hash_uint4(X, Y, Z, W), fx, fy, fz, fw),
        _grad4(hash_uint4(X + 1, Y, Z, W), fx - 1.0, fy, fz, fw),
        _grad4(hash_uint4(X, Y + 1, Z, W), fx, fy - 1.0, fz, fw),
        _grad4(hash_uint4(X + 1, Y + 1, Z, W), fx - 1.0, fy - 1.0, fz, fw),
        _grad4(hash_uint4(X, Y, Z + 1, W), fx, fy, fz - 1.0, fw),
        _grad4(hash_uint4(X + 1, Y, Z + 1, W), fx - 1.0, fy, fz - 1.0, fw),
        _grad4(hash_uint4(X, Y + 1, Z + 1, W), fx, fy - 1.0, fz - 1.0, fw),
        _grad4(hash_uint4(X + 1, Y + 1, Z + 1, W), fx - 1.0, fy - 1.0, fz - 1.0, fw),
        u, v, t)


@kernel
def _perlin4(x, y, z, w):
    flx, fly, flz, flw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    X, Y, Z, W = int(flx), int(fly), int(flz), int(flw)
    fx, fy, fz, fw = x - flx, y - fly, z - flz, w - flw
    u, v, t = _fade(fx), _fade(fy), _fade(fz)
    a = _perlin4_slice(X, Y, Z, W, fx, fy, fz, fw, u, v, t)
    b = _perlin4_slice(X, Y, Z, W + 1, fx, fy, fz, fw - 1.0, u, v, t)
    return _mix(a, b, _fade(fw))


@kernel
def snoise(dims, x, y, z, w):
    """Signed noise in about [-1, 1] of the first ``dims`` coordinates (Cycles' snoise_Nd)."""
    x = np.fmod(x, _PERIOD)
    if dims == 1:
        return 0.25 * _perlin1(x)
    y = np.fmod(y, _PERIOD)
    if dims == 2:
        return 0.6616 * _perlin2(x, y)
    z = np.fmod(z, _PERIOD)
    if dims == 3:
        return 0.9820 * _perlin3(x, y, z)
    return 0.8344 * _perlin4(x, y, z, np.fmod(w, _PERIOD))


@kernel
def fbm(dims, x, y, z, w, detail, roughness, lacunarity, normalize):
    fscale = 1.0
    amp = 1.0
    maxamp = 0.0
    total = 0.0
    for _ in range(int(detail) + 1):
        total += snoise(dims, fscale * x, fscale * y, fscale * z, fscale * w) * amp
        maxamp += amp
        amp *= roughness
        fscale *= lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        t = snoise(dims, fscale * x, fscale * y, fscale * z, fscale * w)
        total2 = total + t * amp
        if normalize:
            return _mix(0.5 * total / maxamp + 0.5, 0.5 * total2 / (maxamp + amp) + 0.5, rmd)
        return _mix(total, total2, rmd)
    return 0.5 * total / maxamp + 0.5 if normalize else total


@kernel
def _multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity):
    value = 1.0
    pwr = 1.0
    for _ in range(int(detail) + 1):
        value *= pwr * snoise(dims, x, y, z, w) + 1.0
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value *= rmd * pwr * snoise(dims, x, y, z, w) + 1.0
    return value


@kernel
def _hetero_terrain(dims, x, y, z, w, detail, roughness, lacunarity, offset):
    pwr = roughness
    value = offset + snoise(dims, x, y, z, w)
    x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    for _ in range(1, int(detail) + 1):
        value += (snoise(dims, x, y, z, w) + offset) * pwr * value
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value += rmd * ((snoise(dims, x, y, z, w) + offset) * pwr * value)
    return value


@kernel
def _hybrid_multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = 1.0
    value = 0.0
    weight = 1.0
    octaves = int(detail)
    i = 0
    while weight > 0.001 and i <= octaves:
        weight = min(weight, 1.0)
        signal = (snoise(dims, x, y, z, w) + offset) * pwr
        pwr *= roughness
        value += weight * signal
        weight *= gain * signal
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
        i += 1
    rmd = detail - math.floor(detail)
    if rmd != 0.0 and weight > 0.001:
        weight = min(weight, 1.0)
        value += rmd * weight * ((snoise(dims, x, y, z, w) + offset) * pwr)
    return value


@kernel
def _ridged_multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = roughness
    signal = offset - abs(snoise(dims, x, y, z, w))
    signal *= signal
    value = signal
    for _ in range(1, int(detail) + 1):
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
        weight = min(max(signal * gain, 0.0), 1.0)
        signal = offset - abs(snoise(dims, x, y, z, w))
        signal *= signal
        signal *= weight
        value += signal * pwr
        pwr *= roughness
    return value


@kernel
def fractal(kind, dims, x, y, z, w, detail, roughness, lacunarity, offset, gain, normalize):
    """Cycles' noise_select: one of the five fractal sums."""
    if kind == FBM:
        return fbm(dims, x, y, z, w, detail, roughness, lacunarity, normalize)
    if kind == MULTIFRACTAL:
        return _multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity)
    if kind == HYBRID_MULTIFRACTAL:
        return _hybrid_multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity, offset, gain)
    if kind == RIDGED_MULTIFRACTAL:
        return _ridged_multi_fractal(dims, x, y, z, w, detail, roughness, lacunarity, offset, gain)
    return _hetero_terrain(dims, x, y, z, w, detail, roughness, lacunarity, offset)


@kernel
def _seed_offset(dims, seed, axis):
    """Cycles' random_float{,2,3,4}_offset: a fixed shift in [100, 200] per seed and axis."""
    if dims == 1:
        return 100.0 + hash_f1(seed) * 100.0
    return 100.0 + hash_f2(seed, float(axis)) * 100.0


@kernel
def _shifted(kind, dims, x, y, z, w, seed, detail, roughness, lacunarity, offset, gain, normalize):
    """The fractal at the point moved by the offsets of ``seed``, ``seed + 1``... per axis
    (dims 2 to 4 take one seed for all axes and the axis index; 1D takes the seed)."""
    return fractal(kind, dims, x + _seed_offset(dims, seed, 0), y + _seed_offset(dims, seed, 1),
                   z + _seed_offset(dims, seed, 2), w + _seed_offset(dims, seed, 3),
                   detail, roughness, lacunarity, offset, gain, normalize)


@kernel
def noise_texture(kind, dims, normalize, want_color, vector, w_in, scale, detail, roughness, lacunarity,
                  offset, gain, distortion):
    """Cycles' svm_node_tex_noise over all points: (value (N,), colour (N, 3))."""
    n = len(scale)
    value = np.empty(n)
    color = np.zeros((n, 3))
    for i in range(n):
        s = scale[i]
        x, y, z, w = vector[i, 0] * s, vector[i, 1] * s, vector[i, 2] * s, w_in[i] * s
        if dims == 1:
            x = w
        d = min(max(detail[i], 0.0), 15.0)
        r = max(roughness[i], 0.0)
        dist = distortion[i]
        if dist != 0.0:
            if dims == 1:
                x += snoise(1, x + _seed_offset(1, 0.0, 0), 0.0, 0.0, 0.0) * dist
            else:
                dx = snoise(dims, x + _seed_offset(dims, 0.0, 0), y + _seed_offset(dims, 0.0, 1),
                            z + _seed_offset(dims, 0.0, 2), w + _seed_offset(dims, 0.0, 3)) * dist
                dy = snoise(dims, x + _seed_offset(dims, 1.0, 0), y + _seed_offset(dims, 1.0, 1),
                            z + _seed_offset(dims, 1.0, 2), w + _seed_offset(dims, 1.0, 3)) * dist
                dz = 0.0
                dw = 0.0
                if dims >= 3:
                    dz = snoise(dims, x + _seed_offset(dims, 2.0, 0), y + _seed_offset(dims, 2.0, 1),
                                z + _seed_offset(dims, 2.0, 2), w + _seed_offset(dims, 2.0, 3)) * dist
                if dims == 4:
                    dw = snoise(dims, x + _seed_offset(dims, 3.0, 0), y + _seed_offset(dims, 3.0, 1),
                                z + _seed_offset(dims, 3.0, 2), w + _seed_offset(dims, 3.0, 3)) * dist
                x, y, z, w = x + dx, y + dy, z + dz, w + dw
        v = fractal(kind, dims, x, y, z, w, d, r, lacunarity[i], offset[i], gain[i], normalize)
        value[i] = v
        if want_color:
            first = float(dims)  # the colour's seeds follow the distortion's (0 to dims - 1)
            color[i, 0] = v
            color[i, 1] = _shifted(kind, dims, x, y, z, w, first, d, r, lacunarity[i], offset[i], gain[i],
                                   normalize)
            color[i, 2] = _shifted(kind, dims, x, y, z, w, first + 1.0, d, r, lacunarity[i], offset[i],
                                   gain[i], normalize)
    return value, color
