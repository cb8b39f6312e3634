"""Bob Jenkins' lookup3 hash as Cycles uses it (util/hash.h), bit for bit.

Procedural textures are only Cycles' textures if the same cell gets the same random value:
the hash works on 32-bit words (integer cell coordinates, or the bits of a float32), and its
result becomes a float32 in [0, 1] exactly as Cycles rounds it. Words are held in int64 and
masked to 32 bits after every step, which is exact in Numba and in plain Python alike.
"""
from __future__ import annotations

import math

import numpy as np

from ...base.jit import kernel

M32 = 0xFFFFFFFF
_SEED = 0xDEADBEEF
_INV_UINT_MAX = np.float32(1.0 / 4294967295.0)


@kernel
def _rot(x, k):
    return ((x << k) | (x >> (32 - k))) & M32


@kernel
def _final(a, b, c):
    c = ((c ^ b) - _rot(b, 14)) & M32
    a = ((a ^ c) - _rot(c, 11)) & M32
    b = ((b ^ a) - _rot(a, 25)) & M32
    c = ((c ^ b) - _rot(b, 16)) & M32
    a = ((a ^ c) - _rot(c, 4)) & M32
    b = ((b ^ a) - _rot(a, 14)) & M32
    c = ((c ^ b) - _rot(b, 24)) & M32
    return c


@kernel
def hash_uint(kx):
    a = (_SEED + (1 << 2) + 13 + (kx & M32)) & M32
    b = c = (_SEED + (1 << 2) + 13) & M32
    return _final(a, b, c)


@kernel
def hash_uint2(kx, ky):
    s = (_SEED + (2 << 2) + 13) & M32
    return _final((s + (kx & M32)) & M32, (s + (ky & M32)) & M32, s)


@kernel
def hash_uint3(kx, ky, kz):
    s = (_SEED + (3 << 2) + 13) & M32
    return _final((s + (kx & M32)) & M32, (s + (ky & M32)) & M32, (s + (kz & M32)) & M32)


@kernel
def hash_uint4(kx, ky, kz, kw):
    s = (_SEED + (4 << 2) + 13) & M32
    a = (s + (kx & M32)) & M32
    b = (s + (ky & M32)) & M32
    c = (s + (kz & M32)) & M32
    # lookup3's mix(a, b, c)
    a = ((a - c) & M32) ^ _rot(c, 4)
    c = (c + b) & M32
    b = ((b - a) & M32) ^ _rot(a, 6)
    a = (a + c) & M32
    c = ((c - b) & M32) ^ _rot(b, 8)
    b = (b + a) & M32
    a = ((a - c) & M32) ^ _rot(c, 16)
    c = (c + b) & M32
    b = ((b - a) & M32) ^ _rot(a, 19)
    a = (a + c) & M32
    c = ((c - b) & M32) ^ _rot(b, 4)
    b = (b + a) & M32
    a = (a + (kw & M32)) & M32
    return _final(a, b, c)


@kernel
def to_unit(n):
    """uint_to_float_incl: the word as a float32 times float32(1 / 0xFFFFFFFF), both rounded."""
    return np.float64(np.float32(np.float32(n) * _INV_UINT_MAX))


@kernel
def float_bits(f):
    """The IEEE-754 bits of ``f`` rounded to float32 (Cycles' __float_as_uint), from frexp
    because Numba has no scalar bit cast."""
    v = np.float64(np.float32(f))
    if v != v:
        return 0x7FC00000
    sign = 0
    if v < 0.0 or (v == 0.0 and math.copysign(1.0, v) < 0.0):
        sign = 1 << 31
        v = -v
    if v == 0.0:
        return sign
    if v == math.inf:
        return sign | 0x7F800000
    m, e = math.frexp(v)
    biased = e + 126
    if biased <= 0:
        return sign | int(v * 2.0 ** 149)
    return sign | (biased << 23) | int((m * 2.0 - 1.0) * 8388608.0)


@kernel
def hash_f1(x):
    return to_unit(hash_uint(float_bits(x)))


@kernel
def hash_f2(x, y):
    return to_unit(hash_uint2(float_bits(x), float_bits(y)))


@kernel
def hash_f3(x, y, z):
    return to_unit(hash_uint3(float_bits(x), float_bits(y), float_bits(z)))


@kernel
def hash_f4(x, y, z, w):
    return to_unit(hash_uint4(float_bits(x), float_bits(y), float_bits(z), float_bits(w)))


@kernel
def hash_to_color(dims, x, y, z, w):
    """hash_float{,2,3,4}_to_float3 of the first ``dims`` coordinates."""
    if dims == 1:
        return hash_f1(x), hash_f2(x, 1.0), hash_f2(x, 2.0)
    if dims == 2:
        return hash_f2(x, y), hash_f3(x, y, 1.0), hash_f3(x, y, 2.0)
    if dims == 3:
        return hash_f3(x, y, z), hash_f4(x, y, z, 1.0), hash_f4(x, y, z, 2.0)
    return hash_f4(x, y, z, w), hash_f4(z, x, w, y), hash_f4(w, z, y, x)


@kernel
def hash_to_point(dims, x, y, z, w):
    """hash_float{,2,3,4}_to_float{,2,3,4}: a Voronoi cell's random point (unused lanes 0)."""
    if dims == 1:
        return hash_f1(x), 0.0, 0.0, 0.0
    if dims == 2:
        return hash_f2(x, y), hash_f3(x, y, 1.0), 0.0, 0.0
    if dims == 3:
        return hash_f3(x, y, z), hash_f4(x, y, z, 1.0), hash_f4(x, y, z, 2.0), 0.0
    return hash_f4(x, y, z, w), hash_f4(w, x, y, z), hash_f4(z, w, x, y), hash_f4(y, z, w, x)


@kernel
def hash_value(dims, x, y, z, w):
    """hash_float{,2,3,4}_to_float of the first ``dims`` coordinates."""
    if dims == 1:
        return hash_f1(x)
    if dims == 2:
        return hash_f2(x, y)
    if dims == 3:
        return hash_f3(x, y, z)
    return hash_f4(x, y, z, w)


# PCG hashes on signed 32-bit integers ("Hash Functions for GPU Rendering", JCGT 2020, as
# Cycles modifies them for OSL): Voronoi's cell points in 2D to 4D since Blender 5.0.
_PCG_MUL = 1664525
_PCG_ADD = 1013904223
_INV_INT_MAX = 1.0 / 2147483648.0  # 1 / float32(0x7FFFFFFF), exactly 2^-31


@kernel
def _i32(x):
    """Wrap to a signed 32-bit integer, as C's int arithmetic does on every target Cycles runs on."""
    return ((x + (1 << 31)) & M32) - (1 << 31)


@kernel
def _pcg_unit(h):
    return np.float64(np.float32(h & 0x7FFFFFFF)) * _INV_INT_MAX


@kernel
def pcg2(x, y):
    x = _i32(x * _PCG_MUL + _PCG_ADD)
    y = _i32(y * _PCG_MUL + _PCG_ADD)
    x = _i32(x + y * _PCG_MUL)
    y = _i32(y + x * _PCG_MUL)
    x = x ^ (x >> 16)
    y = y ^ (y >> 16)
    x = _i32(x + y * _PCG_MUL)
    y = _i32(y + x * _PCG_MUL)
    return _pcg_unit(x), _pcg_unit(y)


@kernel
def pcg3(x, y, z):
    x = _i32(x * _PCG_MUL + _PCG_ADD)
    y = _i32(y * _PCG_MUL + _PCG_ADD)
    z = _i32(z * _PCG_MUL + _PCG_ADD)
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    x, y, z = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16)
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    return _pcg_unit(x), _pcg_unit(y), _pcg_unit(z)


@kernel
def pcg4(x, y, z, w):
    x = _i32(x * _PCG_MUL + _PCG_ADD)
    y = _i32(y * _PCG_MUL + _PCG_ADD)
    z = _i32(z * _PCG_MUL + _PCG_ADD)
    w = _i32(w * _PCG_MUL + _PCG_ADD)
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    x, y, z, w = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16), w ^ (w >> 16)
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    return _pcg_unit(x), _pcg_unit(y), _pcg_unit(z), _pcg_unit(w)


@kernel
def pcg_point(dims, x, y, z, w):
    """hash_int{2,3,4}_to_float{2,3,4} of integer cell coordinates (unused lanes 0)."""
    if dims == 2:
        a, b = pcg2(x, y)
        return a, b, 0.0, 0.0
    if dims == 3:
        a, b, c = pcg3(x, y, z)
        return a, b, c, 0.0
    return pcg4(x, y, z, w)


@kernel
def pcg_color(dims, x, y, z, w):
    """hash_int{2,3,4}_to_float3: 2D hashes (x, y, 0) in 3D, 4D keeps the first three."""
    if dims == 2:
        return pcg3(x, y, 0)
    if dims == 3:
        return pcg3(x, y, z)
    a, b, c, _ = pcg4(x, y, z, w)
    return a, b, c
