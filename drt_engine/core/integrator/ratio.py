"""The ratio estimator of direct diffuse light (Heitz, Hill and McGuire 2018).

For a light whose unoccluded light has a closed form (``unoccluded``, core.lights.kinds), the
diffuse direct light of a pixel is the analytic unoccluded light times the fraction of it the
shadow rays let through, both taken over the pixel's own samples:

    L = U * N / D,  N = sum a f V / p,  D = sum a f / p,  U = sum a E_u,

with a = path throughput x diffuse albedo / pi, f / p the light sample's weight times
the cosine, V its visibility and E_u the unoccluded cosine-weighted light. Where the light
is wholly visible N = D and L = U, exactly; where it is hidden N = 0; in penumbrae the
ratio of two sums is biased, and the bias shrinks as the pixel's samples grow (the ratio
of means converges to the ratio of expectations). A per-hit ratio over one shadow ray would
be E_u V, biased at any sample count, hence sums per pixel.

``RatioEstimator`` is the one hook next-event estimation calls: with each batch of shadow rays
as it is built (D and U of the hits at once, the N each ray would add kept aside) and with the
visibility of a depth step's rays once they are traced (N of those that got through). It adds
each sample's N, D and U (summed over these lights) to a wave output ``RATIO`` of NDU_CHANNELS
columns; its N is also in Combined, as Monte Carlo has it. A render without the estimator has
no hook and does none of this. The film keeps them as sums (core.film.ratio_sums), over all
samples and over class A (the error estimate's half), and ``resolve`` replaces N by U N / D
when the image is read. What stays Monte Carlo:
glossy parts (with MIS), emission, the world, emissive meshes, delta lights (their E_u V
is exact already), moving lights, lights chosen among many, and any light without a
closed form.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..film.ratio_sums import NDU_CHANNELS
from ..lights.collection import closed_forms
from ..lights.kinds import unoccluded


def delta_light(light) -> bool:
    """A light of no extent: one direction per point, nothing to sample or to ratio."""
    if light.kind in ("POINT", "SPOT"):
        return light.radius <= 0
    return light.kind == "SUN" and light.angle <= 0


def ratio_strategies(lights, estimator: str) -> list[int]:
    """The light strategies whose diffuse part the ratio estimator takes: one light each
    (not a choice among many), standing still, of some extent and with a closed form."""
    if estimator != "RATIO" or lights.selecting or not lights.lights:
        return []
    closed = closed_forms(lights.table)
    return [k for k in range(lights.light_slots)
            if k not in lights.motions and not delta_light(lights.lights[k]) and closed[k]]


@kernel
def add_unoccluded(table, k, pos, normal, path, albedo, diffuse, ndu):
    """Per hit j of path ``path[j]``: D += ``diffuse[j]`` (throughput x light sample value x the
    diffuse part, unoccluded) and U += ``albedo[j]`` (throughput x albedo / pi) x E_u, light k's
    unoccluded light at ``pos[j]`` about the unit normal ``normal[j]`` (core.lights.kinds)."""
    for j in range(len(path)):
        r, g, b = unoccluded(table, k, pos[j, 0], pos[j, 1], pos[j, 2], normal[j, 0], normal[j, 1], normal[j, 2])
        p = path[j]
        ndu[p, 3] += diffuse[j, 0]
        ndu[p, 4] += diffuse[j, 1]
        ndu[p, 5] += diffuse[j, 2]
        ndu[p, 6] += albedo[j, 0] * r
        ndu[p, 7] += albedo[j, 1] * g
        ndu[p, 8] += albedo[j, 2] * b


class RatioEstimator:
    """The ratio estimator's N, D and U of one wave (``ndu``, one row per camera sample), hooked
    on next-event estimation for the light strategies ``strategies`` (``ratio_strategies``)."""

    def __init__(self, table, strategies, n):
        self.table, self.strategies = table, strategies
        self.ndu = np.zeros((n, NDU_CHANNELS))
        self._hits, self._albedo = None, None  # the hits of the shader being lit, and their albedo
        self._shares = []  # per batch built since the last resolve: the N of each of its rays

    def shadow_rays(self, k, shader, hits, sel_lobes, value, f_diff, sel):
        """Light strategy k sampled at ``hits`` (light sample values ``value``, the BSDF's diffuse
        part ``f_diff`` toward them; ``sel_lobes`` the lobe selection ``shader`` evaluated with),
        shadow rays built from the hits ``sel``: for strategies of the estimator, D and U of every
        hit now and the share of N each ray adds if unblocked; zero shares for the other lights."""
        diffuse = None
        if k in self.strategies:
            if hits is not self._hits:
                self._hits, self._albedo = hits, _diffuse_albedo(shader, hits, sel_lobes)
            if self._albedo is not None:
                diffuse = hits.throughput * value * f_diff
                add_unoccluded(self.table, k, hits.pos, hits.ns, hits.path, self._albedo, diffuse, self.ndu)
        if len(sel):
            self._shares.append(diffuse[sel] if diffuse is not None else np.zeros((len(sel), 3)))

    def resolved(self, path, visible):
        """The shadow rays built since the last call, traced (rays of ``path``, in the order they
        were built, ``visible`` where unblocked): their N to the sums."""
        share = np.concatenate(self._shares)
        self._shares = []
        n = len(self.ndu)
        for c in range(3):
            self.ndu[:, c] += np.bincount(path[visible], weights=share[visible, c], minlength=n)


def _diffuse_albedo(shader, hits, sel_lobes):
    """throughput x the diffuse part's albedo / pi at each hit (None without a diffuse part):
    the diffuse part toward the normal, since it is that times the cosine (the layers above
    attenuate it by factors of wo alone, bsdf.mixture.eval_lobes)."""
    n = len(hits.path)
    normal = np.zeros((n, 3))
    normal[:, 2] = 1.0
    f_diff = shader.evaluate(hits.wo_l, normal, np.ones(n, bool), hits.inside, sel_lobes).diffuse
    return hits.throughput * f_diff if (f_diff > 0).any() else None
