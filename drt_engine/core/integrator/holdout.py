"""Holdouts, as Cycles' integrate_surface_holdout: where a camera ray, or one gone straight on
through transparent surfaces (Cycles' PATH_RAY_TRANSPARENT_BACKGROUND, ``straight`` here), hits
a holdout, the path's throughput times the holdout's weight leaves the pixel's alpha, whether
Film Transparent is on or off, and adds no colour. A Holdout closure's weight is its share of the
material (mixed with other shaders, those keep theirs and the path goes on with them); an object
holdout is all of the hit but what its material lets through, and the path goes on through its
transparent closures alone. A hit held out whole ends its path there: no emission, no light, no
bounce, no data passes. Reflected and refracted rays see holdouts as their other closures are."""
from __future__ import annotations

import numpy as np


class Holdouts:
    """The scene's holdouts: ``objects`` per instance, whether the whole object is one."""

    def __init__(self, objects: np.ndarray, geometry):
        self.objects = objects
        self.geometry = geometry

    def whole(self, surf) -> np.ndarray:
        """Per hit of ``surf``: the camera sees an object holdout there."""
        return surf.straight & self.objects[self.geometry.source_of(surf.prim)[:, 0]]

    def write(self, bound, alpha: np.ndarray) -> list:
        """Take the holdouts' share of the hits in ``bound`` ((hits, samples, shader) per shader)
        from ``alpha``; returns ``bound`` without the hits held out whole, object holdouts' hits
        with their shader's transparent lobes alone."""
        out = []
        for group, u, shader in bound:
            held = self.whole(group)
            if not shader.holds_out and not held.any():
                out.append((group, u, shader))
                continue
            weight = shader.holdout_weights(len(group)) * group.straight[:, None]
            if held.any():
                weight = np.where(held[:, None], 1.0 - shader.transparency(group.wo_l[:, 2]), weight)
            alpha[group.path] -= (weight * group.throughput).mean(axis=1)
            partly = ~(weight == 1.0).all(axis=1)
            rest, through = np.flatnonzero(partly & ~held), np.flatnonzero(partly & held)
            if len(rest) == len(group):
                out.append((group, u, shader))
            elif len(rest):
                out.append((group.take(rest), u.take(rest), shader.take(rest)))
            if len(through):
                out.append((group.take(through), u.take(through), shader.take(through).see_through_only()))
        return out
