"""Holdouts, as Cycles' integrate_surface_holdout: where a camera ray, or one gone straight on
through transparent surfaces (Cycles' PATH_RAY_TRANSPARENT_BACKGROUND, ``straight`` here), hits
a holdout, the path's throughput times the holdout's weight leaves the pixel's alpha, whether
Film Transparent is on or off, and adds no colour. A Holdout closure's weight is its share of the
material (mixed with other shaders, those keep theirs and the path goes on with them); an object
holdout is the whole hit. A hit held out whole ends its path there: no emission, no light, no
bounce, no data passes. Reflected and refracted rays see holdouts as their other closures are."""
from __future__ import annotations

import numpy as np


class Holdouts:
    """The scene's holdouts: ``objects`` per instance, whether the whole object is one."""

    def __init__(self, objects: np.ndarray, geometry):
        self.objects = objects
        self.geometry = geometry

    def whole(self, surf) -> np.ndarray:
        """Per hit of ``surf``: the camera sees an object holdout there (held out whole)."""
        return surf.straight & self.objects[self.geometry.source_of(surf.prim)[:, 0]]

    def write(self, bound, alpha: np.ndarray) -> list:
        """Take the holdouts' share of the hits in ``bound`` ((hits, samples, shader) per shader)
        from ``alpha``; returns ``bound`` without the hits held out whole."""
        out = []
        for group, u, shader in bound:
            held = self.whole(group)
            if not shader.holds_out and not held.any():
                out.append((group, u, shader))
                continue
            weight = shader.holdout_weights(len(group)) * group.straight[:, None]
            weight = np.where(held[:, None], 1.0, weight)
            alpha[group.path] -= (weight * group.throughput).mean(axis=1)
            keep = np.flatnonzero(~(weight == 1.0).all(axis=1))
            if len(keep) == len(group):
                out.append((group, u, shader))
            elif len(keep):
                out.append((group.take(keep), u.take(keep), shader.take(keep)))
        return out
