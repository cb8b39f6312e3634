"""The Mist pass's ramp: how far into the world's mist a point is, as Cycles computes it.

Cycles (kernel/film/data_passes.h) takes the distance from the camera's position (orthographic
cameras: along the view axis), maps [start, start + depth] to [0, 1], clamps, and raises it to the
falloff exponent; each hit the camera sees adds (1 - that) times its share of the pixel, and the
pass is one minus the sum (so the background reads 1).
"""
from __future__ import annotations

import numpy as np


class Mist:
    """The mist ramp of one camera under one world's mist settings."""

    def __init__(self, camera, world):
        matrix = camera.matrix
        self.position = matrix[:3, 3].copy()
        self.axis = matrix[:3, 2] / max(np.linalg.norm(matrix[:3, 2]), 1e-30) if camera.type == "ORTHO" else None
        self.start = float(world.mist_start)
        self.inv_depth = 1.0 / world.mist_depth if world.mist_depth > 0 else 0.0
        self.falloff = float(world.mist_falloff)

    def amount(self, points: np.ndarray) -> np.ndarray:
        """(N,) mist at world points ``points`` (N, 3): 0 before the start, 1 past start + depth."""
        d = points - self.position
        distance = np.abs(d @ self.axis) if self.axis is not None else np.sqrt((d * d).sum(axis=1))
        return np.clip((distance - self.start) * self.inv_depth, 0.0, 1.0) ** self.falloff
