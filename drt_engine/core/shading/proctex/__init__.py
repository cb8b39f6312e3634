"""Blender's procedural textures, evaluated over all hits as Cycles' SVM kernel evaluates them.

``evaluate(op, params, inputs)`` is the shader-program entry (core.shading.nodes): ``inputs``
are the node's sockets in the order listed in ``INPUTS``, (N,) for values and (N, 3) for
vectors and colours; it returns the node's outputs in the order listed in ``OUTPUTS``.
"""
from __future__ import annotations

import numpy as np

from . import gabor, noise, patterns, voronoi

INPUTS = {
    "noise": ("Vector", "W", "Scale", "Detail", "Roughness", "Lacunarity", "Offset", "Gain", "Distortion"),
    "voronoi": ("Vector", "W", "Scale", "Detail", "Roughness", "Lacunarity", "Smoothness", "Exponent",
                "Randomness"),
    "wave": ("Vector", "Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness", "Phase Offset"),
    "gradient": ("Vector",),
    "magic": ("Vector", "Scale", "Distortion"),
    "white_noise": ("Vector", "W"),
    "brick": ("Vector", "Color1", "Color2", "Mortar", "Scale", "Mortar Size", "Mortar Smooth", "Bias",
              "Brick Width", "Row Height"),
    "gabor": ("Vector", "Scale", "Frequency", "Anisotropy", "Orientation 2D", "Orientation 3D"),
}
OUTPUTS = {
    "noise": ("Fac", "Color"),
    "voronoi": ("Distance", "Color", "Position", "W", "Radius"),
    "wave": ("Color", "Fac"),
    "gradient": ("Color", "Fac"),
    "magic": ("Color", "Fac"),
    "white_noise": ("Value", "Color"),
    "brick": ("Color", "Fac"),
    "gabor": ("Value", "Phase", "Intensity"),
}
OPS = tuple(INPUTS)
HASH_PCG = "pcg"
"""Voronoi's cell hash in 2D to 4D from Blender 5.0 on; the exporter names Blender's ("lookup3" before)."""


def _grey(f):
    return np.repeat(f[:, None], 3, axis=1)


def evaluate(op: str, p: dict, x: list) -> tuple:
    x = [np.ascontiguousarray(v, dtype=np.float64) for v in x]
    if op == "noise":
        value, color = noise.noise_texture(noise.NOISE_TYPES[p["type"]], p["dims"], p["normalize"],
                                           p.get("color", True), *x)
        return value, color
    if op == "voronoi":
        return voronoi.voronoi_texture(p["dims"], voronoi.FEATURES[p["feature"]], voronoi.METRICS[p["metric"]],
                                       p["normalize"], p.get("hash", HASH_PCG) == HASH_PCG, *x)
    if op == "wave":
        fac = patterns.wave(patterns.WAVE_TYPES[p["type"]], patterns.BANDS_DIRECTIONS[p["bands"]],
                            patterns.RINGS_DIRECTIONS[p["rings"]], patterns.WAVE_PROFILES[p["profile"]], *x)
        return _grey(fac), fac
    if op == "gradient":
        fac = patterns.gradient(patterns.GRADIENT_TYPES[p["type"]], *x)
        return _grey(fac), fac
    if op == "magic":
        color = patterns.magic(p["depth"], *x)
        return color, color.mean(axis=1)
    if op == "white_noise":
        return patterns.white_noise(p["dims"], *x)
    if op == "gabor":  # the orientation of the other dimension count is a disabled socket, read as 0
        direction = x[5] if x[5].ndim == 2 else np.zeros((len(x[5]), 3))
        return gabor.gabor_texture(p["dims"], *x[:5], direction)
    if op == "brick":
        return patterns.brick(*x, p["offset"], p["offset_frequency"], p["squash"], p["squash_frequency"])
    raise KeyError(op)
