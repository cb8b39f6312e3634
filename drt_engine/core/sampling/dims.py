"""The sample-dimension layout of a path, in one place (pbrt-v4's ``6 + 7 * depth`` idea).

A sample value is a function of (pixel, sample id, dimension), so which dimension a
decision reads decides which decisions are stratified together and which images stay the
same when the scene changes. The layout:

- camera: pixel offset (0, 1), lens (2, 3), shutter time (4);
- path, per depth d from ``PATH + 4 d``: the lobe's direction (2D), the lobe choice (drawn as a
  pair whose second value nothing reads);
- light strategies, per depth: a block of 4 (the point on the light (2D), the choice of a
  light or triangle) at a dimension hashed from the strategy's identity (a light's kind and
  name, "emissive", "world", a selection slot) and the depth, above every path dimension;
- the Ambient Occlusion node, per depth: one 2D dimension per ray (up to 128), in a block of 256
  above every light block;
- the Bevel node, per depth: one 2D dimension above every Ambient Occlusion block (depths below
  65536), its disk samples drawn at consecutive sample ids (Cycles' branched samples, so a hit's
  disk samples are stratified together);
- Russian roulette's decision, per depth: one 1D dimension above every Bevel one. It used to be the
  lobe choice's pair's second value: correlated with the choice, it left the roulette's paths
  noisier than Cycles' (4x4-block variance 1.3x Cycles' on test_light_passes_cycles' scene at
  diffuse bounces 2, 8 seeds of 128 samples; 1.0x from a dimension of its own).

So adding a light leaves every other light's numbers, and the path's, as they were.
Sobol pairs past the first four dimensions are independently scrambled padding (see
sampling.Sampler), so a hashed dimension is as good as a consecutive one.
"""
from __future__ import annotations

import zlib

PIXEL, LENS, TIME = 0, 2, 4
PATH = 6
PATH_STRIDE = 4

_LIGHT_BASE = 1 << 24  # above any path dimension (depth < 4 million)
_LIGHT_BLOCKS = 1 << 22  # hashed blocks of 4 dimensions: room for lights x depths without collisions
_AO_BASE = _LIGHT_BASE + 4 * _LIGHT_BLOCKS  # above every light block
_AO_STRIDE = 256  # 2D dimensions for the node's 128 rays at most
_BEVEL_BASE = _AO_BASE + _AO_STRIDE * (1 << 16)  # above the AO blocks of every depth below 65536
_ROULETTE_BASE = _BEVEL_BASE + 2 * (1 << 16)  # above the Bevel dimensions of every depth below 65536


def lobe(depth: int) -> int:
    """2D: the direction of the lobe a path continues through at this depth."""
    return PATH + PATH_STRIDE * depth


def lobe_choice(depth: int) -> int:
    """1D: which lobe the path continues through (drawn as a pair)."""
    return PATH + PATH_STRIDE * depth + 2


def roulette(depth: int) -> int:
    """1D: Russian roulette's decision on the ray that leaves a hit of this depth (with diffuse bounces)."""
    return _ROULETTE_BASE + 2 * depth


def ao(depth: int, ray: int) -> int:
    """2D: the direction of the Ambient Occlusion node's ray ``ray`` at a hit of this depth."""
    return _AO_BASE + _AO_STRIDE * depth + 2 * ray


def bevel(depth: int) -> int:
    """2D: the axis and point on the disk of the Bevel node's samples at a hit of this depth; sample k
    of S draws at sample id ``S * id + k`` (Cycles' path_branched_rng_2D)."""
    return _BEVEL_BASE + 2 * depth


def strategy_keys(lights) -> list[str]:
    """A stable identity per light strategy of ``lights`` (core.lights.Lights), in strategy order."""
    if lights.selecting:
        keys = [f"slot {k}" for k in range(lights.light_slots)]
    else:
        seen: dict[str, int] = {}
        keys = []
        for light in lights.lights[:lights.light_slots]:
            key = f"light {light.kind} {light.name}"
            seen[key] = seen.get(key, -1) + 1
            keys.append(key if seen[key] == 0 else f"{key} #{seen[key]}")  # unnamed or repeated names
    if len(lights.emissive):
        keys.append("emissive")
    if lights.world is not None:
        keys.append("world")
    return keys


class LightDims:
    """First dimension of each (depth, strategy) block of 4: the point (2D) at +0, the choice at +2."""

    def __init__(self, keys: list[str], max_depth: int):
        self.keys = keys
        taken: set[int] = set()
        self._base = []
        for depth in range(max_depth + 1):
            row = []
            for key in keys:
                block = zlib.crc32(f"{key}/{depth}".encode()) % _LIGHT_BLOCKS
                while block in taken:  # a collision (rare): the next free block, deterministically
                    block = (block + 1) % _LIGHT_BLOCKS
                taken.add(block)
                row.append(_LIGHT_BASE + 4 * block)
            self._base.append(row)

    def point(self, depth: int, k: int) -> int:
        """2D: the point strategy k samples on its light."""
        return self._base[depth][k]

    def choice(self, depth: int, k: int) -> int:
        """1D: which light (selection slots) or which emissive triangle strategy k picks."""
        return self._base[depth][k] + 2
