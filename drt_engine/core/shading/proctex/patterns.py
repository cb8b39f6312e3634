"""Wave, Gradient, Magic, White Noise and Brick textures as Cycles' SVM defines them
(svm/wave.h, gradient.h, magic.h, white_noise.h, brick.h), one compiled loop per texture.
"""
from __future__ import annotations

import math

import numpy as np

from ...base.jit import kernel
from .hash import M32, hash_to_color, hash_value
from .noise import fbm

BANDS, RINGS = 0, 1
WAVE_TYPES = {"BANDS": BANDS, "RINGS": RINGS}
BANDS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "DIAGONAL": 3}
RINGS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "SPHERICAL": 3}
WAVE_PROFILES = {"SIN": 0, "SAW": 1, "TRI": 2}
GRADIENT_TYPES = {"LINEAR": 0, "QUADRATIC": 1, "EASING": 2, "DIAGONAL": 3, "RADIAL": 4,
                  "QUADRATIC_SPHERE": 5, "SPHERICAL": 6}
_TWO_PI = 2.0 * math.pi
_MAX_DETAIL = 15.0
"""The Detail socket's own limit; a linked value beyond it would only make the loop longer."""


@kernel
def wave(kind, bands_dir, rings_dir, profile, vector, scale, distortion, detail, dscale, droughness, phase):
    """Cycles' svm_wave for every point: the factor (N,)."""
    n = len(scale)
    out = np.empty(n)
    for i in range(n):
        s = scale[i]
        # Cycles nudges coordinates off exact integers, as here
        x = (vector[i, 0] * s + 0.000001) * 0.999999
        y = (vector[i, 1] * s + 0.000001) * 0.999999
        z = (vector[i, 2] * s + 0.000001) * 0.999999
        if kind == BANDS:
            if bands_dir == 0:
                t = x * 20.0
            elif bands_dir == 1:
                t = y * 20.0
            elif bands_dir == 2:
                t = z * 20.0
            else:
                t = (x + y + z) * 10.0
        else:
            rx = 0.0 if rings_dir == 0 else x
            ry = 0.0 if rings_dir == 1 else y
            rz = 0.0 if rings_dir == 2 else z
            t = math.sqrt(rx * rx + ry * ry + rz * rz) * 20.0
        t += phase[i]
        if distortion[i] != 0.0:
            ds = dscale[i]
            d = min(detail[i], _MAX_DETAIL)
            t += distortion[i] * (fbm(3, x * ds, y * ds, z * ds, 0.0, d, droughness[i], 2.0, True) * 2.0 - 1.0)
        if profile == 0:
            out[i] = 0.5 + 0.5 * math.sin(t - 0.5 * math.pi)
        elif profile == 1:
            t /= _TWO_PI
            out[i] = t - math.floor(t)
        else:
            t /= _TWO_PI
            out[i] = abs(t - math.floor(t + 0.5)) * 2.0
    return out


@kernel
def gradient(kind, vector):
    """Cycles' svm_gradient, saturated: the factor (N,)."""
    n = len(vector)
    out = np.empty(n)
    for i in range(n):
        x, y, z = vector[i, 0], vector[i, 1], vector[i, 2]
        if kind == 0:
            f = x
        elif kind == 1:
            r = max(x, 0.0)
            f = r * r
        elif kind == 2:
            r = min(max(x, 0.0), 1.0)
            t = r * r
            f = 3.0 * t - 2.0 * t * r
        elif kind == 3:
            f = (x + y) * 0.5
        elif kind == 4:
            f = math.atan2(y, x) / _TWO_PI + 0.5
        else:
            # biased so that a unit vector gives exactly 0
            r = max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)
            f = r * r if kind == 5 else r
        out[i] = min(max(f, 0.0), 1.0)
    return out


@kernel
def magic(depth, vector, scale, distortion):
    """Cycles' svm_magic: the colour (N, 3)."""
    n = len(scale)
    out = np.empty((n, 3))
    for i in range(n):
        px = np.fmod(vector[i, 0], _TWO_PI)
        py = np.fmod(vector[i, 1], _TWO_PI)
        pz = np.fmod(vector[i, 2], _TWO_PI)
        s = scale[i]
        d = distortion[i]
        x = math.sin((px + py + pz) * 5.0 * s)
        y = math.cos((-px + py - pz) * 5.0 * s)
        z = -math.cos((-px - py + pz) * 5.0 * s)
        if depth > 0:
            x *= d
            y *= d
            z *= d
            y = -math.cos(x - y + z) * d
            if depth > 1:
                x = math.cos(x - y - z) * d
                if depth > 2:
                    z = math.sin(-x - y - z) * d
                    if depth > 3:
                        x = -math.cos(-x + y - z) * d
                        if depth > 4:
                            y = -math.sin(-x + y + z) * d
                            if depth > 5:
                                y = -math.cos(-x + y + z) * d
                                if depth > 6:
                                    x = math.cos(x + y + z) * d
                                    if depth > 7:
                                        z = math.sin(x + y - z) * d
                                        if depth > 8:
                                            x = -math.cos(-x - y + z) * d
                                            if depth > 9:
                                                y = -math.sin(x - y + z) * d
        if d != 0.0:
            x /= 2.0 * d
            y /= 2.0 * d
            z /= 2.0 * d
        out[i, 0], out[i, 1], out[i, 2] = 0.5 - x, 0.5 - y, 0.5 - z
    return out


@kernel
def white_noise(dims, vector, w):
    """Cycles' svm_node_tex_white_noise: (value (N,), colour (N, 3)), hashing the float32 bits."""
    n = len(w)
    value = np.empty(n)
    color = np.empty((n, 3))
    for i in range(n):
        x, y, z, t = vector[i, 0], vector[i, 1], vector[i, 2], w[i]
        if dims == 1:
            x = t
        value[i] = hash_value(dims, x, y, z, t)
        color[i, 0], color[i, 1], color[i, 2] = hash_to_color(dims, x, y, z, t)
    return value, color


@kernel
def _brick_noise(n):
    """Cycles' fast integer noise for a brick's tint, in 32-bit unsigned arithmetic."""
    n = (n + 1013) & 0x7FFFFFFF
    n = ((n >> 13) ^ n) & M32
    nn = (n * n) & M32
    nn = (nn * 60493 + 19990303) & M32
    nn = ((n * nn) & M32) + 1376312589
    return 0.5 * ((nn & 0x7FFFFFFF) / 1073741824.0)


@kernel
def brick(vector, color1, color2, mortar, scale, mortar_size, mortar_smooth, bias, brick_width, row_height,
          offset_amount, offset_frequency, squash_amount, squash_frequency):
    """Cycles' svm_brick and its colour mix: (colour (N, 3), mortar factor (N,))."""
    n = len(scale)
    color = np.empty((n, 3))
    fac = np.empty(n)
    for i in range(n):
        px = vector[i, 0] * scale[i]
        py = vector[i, 1] * scale[i]
        width = brick_width[i]
        height = row_height[i]
        rownum = int(math.floor(py / height))
        offset = 0.0
        if offset_frequency != 0 and squash_frequency != 0:
            if rownum % squash_frequency == 0:
                width *= squash_amount
            if rownum % offset_frequency == 0:
                offset = width * offset_amount
        bricknum = int(math.floor((px + offset) / width))
        x = (px + offset) - width * bricknum
        y = py - height * rownum
        tint = min(max(_brick_noise(((rownum << 16) + (bricknum & 0xFFFF)) & M32) + bias[i], 0.0), 1.0)
        min_dist = min(min(x, y), min(width - x, height - y))
        if min_dist >= mortar_size[i]:
            f = 0.0
        elif mortar_smooth[i] == 0.0:
            f = 1.0
        else:
            t = (1.0 - min_dist / mortar_size[i]) / mortar_smooth[i]
            f = 0.0 if t <= 0.0 else (1.0 if t >= 1.0 else 3.0 * t * t - 2.0 * t * t * t)
        for c in range(3):
            base = color1[i, c]
            if f != 1.0:
                base = (1.0 - tint) * color1[i, c] + tint * color2[i, c]
            color[i, c] = base * (1.0 - f) + mortar[i, c] * f
        fac[i] = f
    return color, fac
