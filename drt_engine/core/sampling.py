"""Sample values as a pure function of (pixel, sample id, dimension, seed).

Every random number of a render comes from here, so the same settings give the same
image whatever the thread count, chunking or tile order. A camera sample keeps its
sample id down its whole ray tree (ray-id chaining); each effect draws from its own
dimension, so pixel, lens, time, light and lobe are stratified and decorrelated.

Patterns:
- SOBOL: Owen-scrambled Sobol (Burley 2020, "Practical Hash-based Owen Scrambling").
  Pixel and lens (dimensions 0-3) form one 4D Sobol net; later dimensions are padded in
  pairs, each from Sobol dimensions 0 and 1 (a (0, 2) sequence) with the sample index
  shuffled by a nested uniform scramble seeded per pixel and pair, so every pair is
  perfectly stratified and pairs are decorrelated.
- JITTERED: n x n stratified jitter for each pair of dimensions, strata visited in a
  per-pixel, per-pair random order.
- GRID: regular n x n supersampling (stratum centres); only square counts.
"""
from __future__ import annotations

import math

import numpy as np

_U32 = np.uint32


def hash_u32(x: np.ndarray) -> np.ndarray:
    """A well-mixing 32-bit integer hash (lowbias32), vectorised."""
    x = np.array(x, dtype=_U32, copy=True, ndmin=1)
    x ^= x >> _U32(16)
    x *= _U32(0x7FEB352D)
    x ^= x >> _U32(15)
    x *= _U32(0x846CA68B)
    x ^= x >> _U32(16)
    return x


def hash_combine(*values) -> np.ndarray:
    """Hash of several integers or integer arrays (broadcast together)."""
    h = np.zeros(1, dtype=_U32)
    for v in values:
        v = np.atleast_1d(np.asarray(v))  # arrays wrap silently; 0-d scalars would warn
        v = (v.astype(np.int64) & 0xFFFFFFFF).astype(_U32) if v.dtype != _U32 else v
        h = hash_u32(h ^ (v + _U32(0x9E3779B9) + (h << _U32(6)) + (h >> _U32(2))))
    return h


_M1, _M2, _M4 = _U32(0x55555555), _U32(0x33333333), _U32(0x0F0F0F0F)


def _reverse_bits(x: np.ndarray) -> np.ndarray:
    """Bit reversal by swapping bits, pairs and nibbles, then bytes (arithmetic runs ~3x
    faster than byte-table lookups, which are gathers)."""
    y = (x >> _U32(1)) & _M1
    y |= (x & _M1) << _U32(1)
    z = (y >> _U32(2)) & _M2
    z |= (y & _M2) << _U32(2)
    y = (z >> _U32(4)) & _M4
    y |= (z & _M4) << _U32(4)
    return y.byteswap(inplace=True)


def _laine_karras(x: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """Bit j of the result depends only on bits <= j of x (Laine-Karras, Vegdahl's constants)."""
    x = x + seed
    x ^= x * _U32(0x6C50B47C)
    x ^= x * _U32(0xB82F1E52)
    x ^= x * _U32(0xC7AFE638)
    x ^= x * _U32(0x8D22F6E6)
    return x


def nested_uniform_scramble(x: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """Owen scrambling of 32-bit fixed-point values: each bit flips by the bits above it."""
    return _reverse_bits(_laine_karras(_reverse_bits(x), seed))


def _sobol_matrices() -> np.ndarray:
    """Generator matrices (4, 32) of Sobol dimensions 0-3 (Joe-Kuo direction numbers)."""
    params = [(1, 0, [1]), (2, 1, [1, 3]), (3, 1, [1, 3, 1])]
    out = np.zeros((4, 32), dtype=np.uint64)
    out[0] = [1 << (31 - k) for k in range(32)]
    for d, (deg, a, m) in enumerate(params, start=1):
        v = [0] * 33
        for i in range(1, 33):
            if i <= deg:
                v[i] = m[i - 1] << (32 - i)
            else:
                v[i] = v[i - deg] ^ (v[i - deg] >> deg)
                for k in range(1, deg):
                    v[i] ^= ((a >> (deg - 1 - k)) & 1) * v[i - k]
        out[d] = v[1:]
    return out.astype(_U32)


def _byte_tables(matrices: np.ndarray) -> np.ndarray:
    """(dims, 4, 256): XOR of the generator columns selected by each byte of the index."""
    tables = np.zeros((len(matrices), 4, 256), dtype=_U32)
    for d, columns in enumerate(matrices):
        for k in range(4):
            for b in range(256):
                v = 0
                for bit in range(8):
                    if b >> bit & 1:
                        v ^= int(columns[8 * k + bit])
                tables[d, k, b] = v
    return tables


_SOBOL = _byte_tables(_sobol_matrices())


def sobol_u32(index: np.ndarray, dim: int) -> np.ndarray:
    """Unscrambled Sobol point ``index`` in dimension ``dim`` (1-3; dimension 0, the bit reversal, is
    Sampler._sobol's own) as 32-bit fixed point."""
    index = np.asarray(index, dtype=_U32)
    t = _SOBOL[dim]
    out = np.take(t[0], index & _U32(0xFF))
    out ^= np.take(t[1], (index >> _U32(8)) & _U32(0xFF))
    out ^= np.take(t[2], (index >> _U32(16)) & _U32(0xFF))
    out ^= np.take(t[3], index >> _U32(24))
    return out


def _to_unit(x: np.ndarray) -> np.ndarray:
    """32-bit fixed point to float64 in [0, 1), never 1.0."""
    return (x >> _U32(8)).astype(np.float64) * (1.0 / (1 << 24))


def permute(i: np.ndarray, n: int, seed: np.ndarray) -> np.ndarray:
    """Random permutation of [0, n) applied to i, one per seed (Kensler 2013, cycle walking)."""
    i = np.array(i, dtype=_U32, copy=True)
    seed = np.broadcast_to(np.asarray(seed, dtype=_U32), i.shape)
    w = _U32(n - 1)
    for s in (1, 2, 4, 8, 16):
        w |= w >> _U32(s)
    todo = np.ones(i.shape, dtype=bool)
    out = np.empty_like(i)
    while todo.any():
        x, p = i[todo], seed[todo]
        x ^= p
        x *= _U32(0xE170893D)
        x ^= p >> _U32(16)
        x ^= (x & w) >> _U32(4)
        x ^= p >> _U32(8)
        x *= _U32(0x0929EB3F)
        x ^= p >> _U32(23)
        x ^= (x & w) >> _U32(1)
        x *= _U32(1) | (p >> _U32(27))
        x *= _U32(0x6935FA69)
        x ^= (x & w) >> _U32(11)
        x *= _U32(0x74DCB303)
        x ^= (x & w) >> _U32(2)
        x *= _U32(0x9E501CC3)
        x ^= (x & w) >> _U32(2)
        x *= _U32(0xC860A3DF)
        x &= w
        x ^= x >> _U32(5)
        done = x < _U32(n)
        idx = np.flatnonzero(todo)
        out[idx[done]] = (x[done] + p[done]) % _U32(n)
        i[idx[~done]] = x[~done]
        todo[idx[done]] = False
    return out


class Sampler:
    """Hands out sample values for explicit dimensions.

    ``get(pixel, sample, dim)`` returns float64 values in [0, 1) for arrays of pixel
    ids and sample ids; ``get2d`` returns dims (dim, dim + 1) as an (N, 2) array and
    must be called with an even ``dim`` so both values share a stratification.
    """

    def __init__(self, pattern: str, samples: int, seed: int = 0):
        self.pattern = pattern
        self.seed = int(seed) & 0xFFFFFFFF
        if pattern == "GRID":
            n = math.isqrt(samples)
            n = n if n * n == samples else n + 1
            self.strata = (n, n)
        else:
            nx = math.isqrt(samples)
            nx = nx if nx * nx >= samples else nx + 1
            self.strata = (nx, -(-samples // nx))
        self.samples = self.strata[0] * self.strata[1] if pattern == "GRID" else samples

    def get(self, pixel: np.ndarray, sample: np.ndarray, dim: int) -> np.ndarray:
        if self.pattern == "SOBOL":
            return self._sobol(pixel, sample, dim - dim % 2, (dim % 2,))[:, 0]
        return self._stratified(pixel, sample, dim - dim % 2)[:, dim % 2]

    def get2d(self, pixel: np.ndarray, sample: np.ndarray, dim: int) -> np.ndarray:
        assert dim % 2 == 0, "2D dimensions start at an even index"
        if self.pattern == "SOBOL":
            return self._sobol(pixel, sample, dim, (0, 1))
        return self._stratified(pixel, sample, dim)

    def _sobol(self, pixel, sample, dim, components):
        """Dimensions dim + c for c in components, sharing one shuffled index.

        The pixel and lens pairs (dimensions 0-3) are one 4D Sobol net, so defocus, whose
        integrand couples image position and lens position, is stratified jointly; later
        pairs are padded from Sobol dimensions 0 and 1 with their own shuffles.
        """
        pixel_seed = hash_combine(pixel, self.seed)
        group = 0 if dim < 4 else dim
        index = nested_uniform_scramble(np.asarray(sample, dtype=_U32),
                                        hash_u32(pixel_seed ^ _U32(group * 0x9E3779B9 & 0xFFFFFFFF)))
        out = np.empty((len(index), len(components)))
        for k, c in enumerate(components):
            scramble = hash_u32(pixel_seed ^ _U32((dim + c) * 0x85EBCA6B & 0xFFFFFFFF) ^ _U32(0x0A11))
            source = dim + c if dim < 4 else c
            if source == 0:  # Sobol dimension 0 is the bit reversal, which the scramble undoes first
                out[:, k] = _to_unit(_reverse_bits(_laine_karras(index, scramble)))
            else:
                out[:, k] = _to_unit(nested_uniform_scramble(sobol_u32(index, source), scramble))
        return out

    def _stratified(self, pixel, sample, dim):
        nx, ny = self.strata
        pixel = np.asarray(pixel)
        sample = np.asarray(sample, dtype=_U32)
        if dim == 0 and self.pattern == "GRID":
            stratum = sample  # the full grid in raster order
        else:
            stratum = permute(sample, nx * ny, hash_combine(pixel, dim, self.seed, 0x57A7))
        cell = np.stack([stratum % _U32(nx), stratum // _U32(nx)], axis=1).astype(np.float64)
        if self.pattern == "GRID":
            offset = 0.5
        else:
            offset = np.stack(
                [_to_unit(hash_combine(pixel, sample, dim + k, self.seed, 0x1177)) for k in (0, 1)], axis=1
            )
        return (cell + offset) / np.array([nx, ny], dtype=np.float64)
