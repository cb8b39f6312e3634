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

``sample_1d``/``sample_2d`` give one camera sample's value(s) from flat numbers
(``Sampler.params``), so a stage kernel can draw its own; ``Sampler.get``/``get2d`` draw
a wave's in one kernel call. Both are bit-identical to the NumPy versions they replaced.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel

# Integer arithmetic runs on 64-bit ints masked to 32 bits (Python ints when NUMBA_DISABLE_JIT=1):
# the low 32 bits of a product are exact either way, and no unsigned/signed mixing can turn
# an expression into floats in Numba.
_MASK = 0xFFFFFFFF
_GOLDEN = 0x9E3779B9
SOBOL, JITTERED, GRID = 0, 1, 2
_PATTERNS = {"SOBOL": SOBOL, "JITTERED": JITTERED, "GRID": GRID}


@kernel
def hash32(x):
    """A well-mixing 32-bit integer hash (lowbias32)."""
    x &= _MASK
    x ^= x >> 16
    x = (x * 0x7FEB352D) & _MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & _MASK
    x ^= x >> 16
    return x


@kernel
def hash_mix(h, v):
    """One step of ``hash_combine``: h folded with the 32-bit value v."""
    v &= _MASK
    return hash32(h ^ ((v + _GOLDEN + (h << 6) + (h >> 2)) & _MASK))


@kernel
def _hash_rows(values, out):
    for i in range(values.shape[0]):
        h = 0
        for k in range(values.shape[1]):
            h = hash_mix(h, int(values[i, k]))
        out[i] = h


def hash_combine(*values) -> np.ndarray:
    """Hash of several integers or integer arrays (broadcast together), as uint32."""
    arrays = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v)).astype(np.int64) for v in values))
    rows = np.ascontiguousarray(np.stack(arrays, axis=-1).reshape(-1, len(values)))
    out = np.empty(len(rows), np.int64)
    _hash_rows(rows, out)
    return out.astype(np.uint32).reshape(arrays[0].shape)


@kernel
def reverse_bits32(x):
    """Bit reversal by swapping bits, pairs, nibbles, bytes and halves."""
    x = ((x >> 1) & 0x55555555) | ((x & 0x55555555) << 1)
    x = ((x >> 2) & 0x33333333) | ((x & 0x33333333) << 2)
    x = ((x >> 4) & 0x0F0F0F0F) | ((x & 0x0F0F0F0F) << 4)
    x = ((x >> 8) & 0x00FF00FF) | ((x & 0x00FF00FF) << 8)
    return ((x >> 16) | (x << 16)) & _MASK


@kernel
def laine_karras(x, seed):
    """Bit j of the result depends only on bits <= j of x (Laine-Karras, Vegdahl's constants)."""
    x = (x + seed) & _MASK
    x ^= (x * 0x6C50B47C) & _MASK
    x ^= (x * 0xB82F1E52) & _MASK
    x ^= (x * 0xC7AFE638) & _MASK
    x ^= (x * 0x8D22F6E6) & _MASK
    return x


@kernel
def nested_uniform_scramble(x, seed):
    """Owen scrambling of a 32-bit fixed-point value: each bit flips by the bits above it."""
    return reverse_bits32(laine_karras(reverse_bits32(x), seed))


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
    return out.astype(np.uint32)


def _byte_tables(matrices: np.ndarray) -> np.ndarray:
    """(dims, 4, 256): XOR of the generator columns selected by each byte of the index."""
    tables = np.zeros((len(matrices), 4, 256), dtype=np.int64)
    for d, columns in enumerate(matrices):
        for k in range(4):
            for b in range(256):
                v = 0
                for bit in range(8):
                    if b >> bit & 1:
                        v ^= int(columns[8 * k + bit])
                tables[d, k, b] = v
    return tables


SOBOL_TABLES = _byte_tables(_sobol_matrices())
"""(4, 4, 256) int64: what each byte of an index contributes to Sobol dimensions 0-3."""


@kernel
def sobol32(index, dim, tables):
    """Unscrambled Sobol point ``index`` in dimension ``dim`` (0-3) as 32-bit fixed point."""
    return int(tables[dim, 0, index & 0xFF] ^ tables[dim, 1, (index >> 8) & 0xFF]
               ^ tables[dim, 2, (index >> 16) & 0xFF] ^ tables[dim, 3, (index >> 24) & 0xFF])


@kernel
def to_unit(x):
    """32-bit fixed point to a float in [0, 1), never 1.0."""
    return (x >> 8) * (1.0 / (1 << 24))


@kernel
def permute(i, n, seed):
    """Random permutation of [0, n) applied to i, one per seed (Kensler 2013, cycle walking)."""
    w = n - 1
    w |= w >> 1
    w |= w >> 2
    w |= w >> 4
    w |= w >> 8
    w |= w >> 16
    p = seed & _MASK
    x = i & _MASK
    while True:
        x ^= p
        x = (x * 0xE170893D) & _MASK
        x ^= p >> 16
        x ^= (x & w) >> 4
        x ^= p >> 8
        x = (x * 0x0929EB3F) & _MASK
        x ^= p >> 23
        x ^= (x & w) >> 1
        x = (x * (1 | (p >> 27))) & _MASK
        x = (x * 0x6935FA69) & _MASK
        x ^= (x & w) >> 11
        x = (x * 0x74DCB303) & _MASK
        x ^= (x & w) >> 2
        x = (x * 0x9E501CC3) & _MASK
        x ^= (x & w) >> 2
        x = (x * 0xC860A3DF) & _MASK
        x &= w
        x ^= x >> 5
        if x < n:
            return ((x + p) & _MASK) % n


@kernel
def _sobol_component(pixel_seed, index, dim, c, tables):
    """Component c of the pair at ``dim`` from its shuffled index.

    The pixel and lens pairs (dimensions 0-3) are one 4D Sobol net, so defocus, whose
    integrand couples image position and lens position, is stratified jointly; later
    pairs are padded from Sobol dimensions 0 and 1 with their own shuffles.
    """
    scramble = hash32(pixel_seed ^ (((dim + c) * 0x85EBCA6B) & _MASK) ^ 0x0A11)
    source = dim + c if dim < 4 else c
    if source == 0:  # Sobol dimension 0 is the bit reversal, which the scramble undoes first
        return to_unit(reverse_bits32(laine_karras(index, scramble)))
    return to_unit(nested_uniform_scramble(sobol32(index, source, tables), scramble))


@kernel
def _sobol_index(pixel_seed, sample, dim):
    """The sample index shuffled for the pair at even ``dim`` (one shuffle for dimensions 0-3)."""
    group = 0 if dim < 4 else dim
    return nested_uniform_scramble(sample & _MASK, hash32(pixel_seed ^ ((group * _GOLDEN) & _MASK)))


@kernel
def _stratified(pixel, sample, dim, seed, nx, ny, pattern):
    """Pair ``dim`` of a jittered or grid sample: a stratum in a per-pixel, per-pair order."""
    if dim == 0 and pattern == GRID:
        stratum = sample & _MASK  # the full grid in raster order
    else:
        stratum = permute(sample, nx * ny,
                          hash_mix(hash_mix(hash_mix(hash_mix(0, pixel), dim), seed), 0x57A7))
    if pattern == GRID:
        o0 = o1 = 0.5
    else:
        h = hash_mix(hash_mix(0, pixel), sample)
        o0 = to_unit(hash_mix(hash_mix(hash_mix(h, dim), seed), 0x1177))
        o1 = to_unit(hash_mix(hash_mix(hash_mix(h, dim + 1), seed), 0x1177))
    return ((stratum % nx) + o0) / nx, ((stratum // nx) + o1) / ny


@kernel
def sample_2d(pattern, seed, nx, ny, tables, pixel, sample, dim):
    """Dimensions (dim, dim + 1), dim even, of camera sample ``sample`` of ``pixel``."""
    if pattern == SOBOL:
        pixel_seed = hash_mix(hash_mix(0, pixel), seed)
        index = _sobol_index(pixel_seed, sample, dim)
        return (_sobol_component(pixel_seed, index, dim, 0, tables),
                _sobol_component(pixel_seed, index, dim, 1, tables))
    return _stratified(pixel, sample, dim, seed, nx, ny, pattern)


@kernel
def sample_1d(pattern, seed, nx, ny, tables, pixel, sample, dim):
    """Dimension ``dim`` alone (it shares the stratification of its pair)."""
    pair = dim - dim % 2
    if pattern == SOBOL:
        pixel_seed = hash_mix(hash_mix(0, pixel), seed)
        return _sobol_component(pixel_seed, _sobol_index(pixel_seed, sample, pair), pair, dim % 2, tables)
    u0, u1 = _stratified(pixel, sample, pair, seed, nx, ny, pattern)
    return u1 if dim % 2 else u0


@kernel
def _fill_1d(pattern, seed, nx, ny, tables, pixel, sample, dim, out):
    for i in range(len(pixel)):
        out[i] = sample_1d(pattern, seed, nx, ny, tables, int(pixel[i]), int(sample[i]), dim)


@kernel
def _fill_2d(pattern, seed, nx, ny, tables, pixel, sample, dim, out):
    for i in range(len(pixel)):
        out[i, 0], out[i, 1] = sample_2d(pattern, seed, nx, ny, tables, int(pixel[i]), int(sample[i]), dim)


@kernel
def _fill_pairs(pattern, seed, nx, ny, tables, pixel, sample, dims, rows, out):
    """``out[r, p]`` = dimensions (dims[p], dims[p] + 1) for the rows ``rows`` (empty: every row);
    pairs with dims[p] < 0 are left as they are."""
    count = len(rows) if len(rows) else len(pixel)
    for i in range(count):
        r = rows[i] if len(rows) else i
        for p in range(len(dims)):
            if dims[p] >= 0:
                out[r, p, 0], out[r, p, 1] = sample_2d(pattern, seed, nx, ny, tables, int(pixel[r]), int(sample[r]),
                                                       dims[p])


class Sampler:
    """Hands out sample values for explicit dimensions.

    ``get(pixel, sample, dim)`` returns float64 values in [0, 1) for arrays of pixel
    ids and sample ids; ``get2d`` returns dims (dim, dim + 1) as an (N, 2) array and
    must be called with an even ``dim`` so both values share a stratification.
    ``params`` are the numbers ``sample_1d``/``sample_2d`` take before (pixel, sample, dim),
    for kernels that draw values themselves.
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
        self.params = (_PATTERNS[pattern], self.seed, self.strata[0], self.strata[1], SOBOL_TABLES)

    def get(self, pixel: np.ndarray, sample: np.ndarray, dim: int) -> np.ndarray:
        out = np.empty(len(pixel))
        _fill_1d(*self.params, _ints(pixel), _ints(sample), int(dim), out)
        return out

    def get2d(self, pixel: np.ndarray, sample: np.ndarray, dim: int) -> np.ndarray:
        assert dim % 2 == 0, "2D dimensions start at an even index"
        out = np.empty((len(pixel), 2))
        _fill_2d(*self.params, _ints(pixel), _ints(sample), int(dim), out)
        return out

    def pairs(self, pixel: np.ndarray, sample: np.ndarray, dims: np.ndarray, rows=None, out=None) -> np.ndarray:
        """(N, P, 2): the 2D dimensions starting at each even ``dims[p]`` (a 1D dimension d, even,
        is column 0 of the pair at d), drawn in one call, for ``rows`` only if given (the other
        rows zero); pairs with dims[p] < 0 are skipped (zero)."""
        dims = np.asarray(dims, np.int64).ravel()
        assert (dims[dims >= 0] % 2 == 0).all(), "2D dimensions start at an even index"
        if out is None:
            out = np.zeros((len(pixel), len(dims), 2))
        _fill_pairs(*self.params, _ints(pixel), _ints(sample), dims,
                    np.zeros(0, np.int64) if rows is None else _ints(rows), out)
        return out


def _ints(a) -> np.ndarray:
    """int64 ids (one kernel specialisation whatever integer type the caller has)."""
    a = np.asarray(a)
    return a if a.dtype == np.int64 else a.astype(np.int64)
