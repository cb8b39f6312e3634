"""Blender's Gabor Texture (4.3+) as Cycles' svm_node_tex_gabor computes it: sparse Gabor
convolution (Lagae et al. 2009) with eight impulses of Bernoulli weight per cell (Tavernier et al.
2019), over the 3 x 3 (2D) or 3 x 3 x 3 (3D) cells around the point, as a phasor whose imaginary
part is the value and whose angle and length are the phase and intensity (Tricard et al. 2019).
Impulses come from Cycles' float hashes of the cell and the impulse's number, so the pattern is
Cycles' own."""
from __future__ import annotations

import math

import numpy as np

from ...base.jit import kernel
from .hash import hash_f3, hash_f4

IMPULSES = 8
STD_2D = math.sqrt(IMPULSES * 0.5 * 0.25)
STD_3D = math.sqrt(IMPULSES * 0.5 / (4.0 * math.sqrt(2.0)))
"""Cycles' approximate standard deviations of the noise; it divides by six of them."""


@kernel(inline="always")
def _windowed_phasor(d2, angle):
    """Gaussian envelope times a Hann window at squared distance d2, as a phasor of ``angle``."""
    envelope = math.exp(-math.pi * d2) * (0.5 + 0.5 * math.cos(math.pi * d2))
    return envelope * math.cos(angle), envelope * math.sin(angle)


@kernel(inline="always")
def _cell_2d(cx, cy, px, py, frequency, isotropy, base):
    re, im = 0.0, 0.0
    for i in range(IMPULSES):
        orientation = base + (hash_f3(cx, cy, i * 3.0) - 0.5) * math.pi * isotropy
        kx = px - hash_f3(cx, cy, i * 3.0 + 1.0)
        ky = py - hash_f3(i * 3.0 + 1.0, cx, cy)
        d2 = kx * kx + ky * ky
        if d2 >= 1.0:
            continue
        weight = -1.0 if hash_f3(cx, cy, i * 3.0 + 2.0) < 0.5 else 1.0
        angle = 2.0 * math.pi * frequency * (kx * math.cos(orientation) + ky * math.sin(orientation))
        a, b = _windowed_phasor(d2, angle)
        re += weight * a
        im += weight * b
    return re, im


@kernel(inline="always")
def _orientation_3d(ox, oy, oz, isotropy, cx, cy, cz, w):
    """The impulse's frequency direction: the base one turned by random spherical angles."""
    if isotropy == 0.0:
        return ox, oy, oz
    inclination = math.acos(min(max(oz, -1.0), 1.0))
    across = math.sqrt(ox * ox + oy * oy)
    azimuth = 0.0 if across == 0.0 else (-1.0 if oy < 0.0 else 1.0) * math.acos(min(max(ox / across, -1.0), 1.0))
    inclination += hash_f4(cx, cy, cz, w) * math.pi * isotropy
    azimuth += hash_f4(cz, cx, w, cy) * math.pi * isotropy
    s = math.sin(inclination)
    return s * math.cos(azimuth), s * math.sin(azimuth), math.cos(inclination)


@kernel(inline="always")
def _cell_3d(cx, cy, cz, px, py, pz, frequency, isotropy, ox, oy, oz):
    re, im = 0.0, 0.0
    for i in range(IMPULSES):
        dx, dy, dz = _orientation_3d(ox, oy, oz, isotropy, cx, cy, cz, i * 3.0)
        w = i * 3.0 + 1.0
        kx = px - hash_f4(cx, cy, cz, w)
        ky = py - hash_f4(cz, cx, w, cy)
        kz = pz - hash_f4(w, cz, cy, cx)
        d2 = kx * kx + ky * ky + kz * kz
        if d2 >= 1.0:
            continue
        weight = -1.0 if hash_f4(cx, cy, cz, i * 3.0 + 2.0) < 0.5 else 1.0
        a, b = _windowed_phasor(d2, 2.0 * math.pi * frequency * (kx * dx + ky * dy + kz * dz))
        re += weight * a
        im += weight * b
    return re, im


@kernel
def _gabor(dims, vector, scale, frequency, anisotropy, orientation, direction, out):
    for n in range(len(scale)):
        x, y, z = vector[n, 0] * scale[n], vector[n, 1] * scale[n], vector[n, 2] * scale[n]
        f = max(0.001, frequency[n])
        isotropy = 1.0 - min(max(anisotropy[n], 0.0), 1.0)
        fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
        re, im = 0.0, 0.0
        if dims == 2:
            for j in range(-1, 2):
                for i in range(-1, 2):
                    a, b = _cell_2d(fx + i, fy + j, x - fx - i, y - fy - j, f, isotropy, orientation[n])
                    re, im = re + a, im + b
            norm = 6.0 * STD_2D
        else:
            ox, oy, oz = direction[n, 0], direction[n, 1], direction[n, 2]
            length = math.sqrt(ox * ox + oy * oy + oz * oz)
            ox, oy, oz = (ox / length, oy / length, oz / length) if length > 0.0 else (0.0, 0.0, 0.0)
            for k in range(-1, 2):
                for j in range(-1, 2):
                    for i in range(-1, 2):
                        a, b = _cell_3d(fx + i, fy + j, fz + k, x - fx - i, y - fy - j, z - fz - k, f, isotropy,
                                        ox, oy, oz)
                        re, im = re + a, im + b
            norm = 6.0 * STD_3D
        out[n, 0] = 0.5 * im / norm + 0.5
        out[n, 1] = (math.atan2(im, re) + math.pi) / (2.0 * math.pi)
        out[n, 2] = math.sqrt(re * re + im * im) / norm


def gabor_texture(dims, vector, scale, frequency, anisotropy, orientation, direction):
    """(Value, Phase, Intensity), each (N,), of the Gabor Texture of ``dims`` (2 or 3) dimensions."""
    out = np.empty((len(scale), 3))
    _gabor(dims, vector, scale, frequency, anisotropy, orientation, direction, out)
    return out[:, 0], out[:, 1], out[:, 2]
