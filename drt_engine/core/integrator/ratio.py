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

``RatioEstimator`` is the one hook next-event estimation calls, once per shader's hits after the
direct-light kernel traced their shadow rays: D and U of the hits, N of the rays that got
through (the kernel hands it each sample's diffuse part and visibility). It adds
each sample's N, D and U (summed over these lights) to a wave output ``RATIO`` of NDU_CHANNELS
columns; its N is also in Combined, as Monte Carlo has it. A render without the estimator has
no hook and does none of this. The film keeps them as sums (core.film.ratio_sums), over all
samples and over class A (the error estimate's half), and ``resolve`` replaces N by U N / D
when the image is read. With Clamp Direct or Indirect (core.integrator.clamp) a sample's N
is its clamped contributions' (the direct-light kernel hands over each contribution's clamp
factor), D and U are not, so U N / D is clamped as Combined is, and biased as it is.
What stays Monte Carlo:
glossy parts (with MIS), emission, the world, emissive meshes, delta lights (their E_u V
is exact already), moving lights, lights chosen among many, and any light without a
closed form.
"""
from __future__ import annotations

import numpy as np

from ..base import vectors as vec
from ..base.jit import kernel
from ..film.ratio_sums import NDU_CHANNELS
from ..lights.collection import closed_forms
from ..lights.kinds import unoccluded
from ..scene import LIGHT_SETS_ALL
from .direct import VISIBLE


def delta_light(light) -> bool:
    """A light of no extent: one direction per point, nothing to sample or to ratio."""
    if light.kind in ("POINT", "SPOT"):
        return light.radius <= 0
    return light.kind == "SUN" and light.angle <= 0


def ratio_strategies(lights, estimator: str) -> list[int]:
    """The light strategies whose diffuse part the ratio estimator takes: one light each
    (not a choice among many), standing still, of some extent and with a closed form, lighting
    every object (its closed form knows nothing of light linking)."""
    if estimator != "RATIO" or lights.selecting or not lights.lights:
        return []
    closed = closed_forms(lights.table)
    return [k for k in range(lights.light_slots)
            if k not in lights.motions and not delta_light(lights.lights[k]) and closed[k]
            and lights.lights[k].light_set_membership == LIGHT_SETS_ALL]


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

    def direct(self, shader, hits, value, f_diff, visibility, cuts):
        """Direct light computed at ``hits`` (lit by ``shader``): per strategy, the light samples'
        values and the BSDF's diffuse part toward them, what became of their shadow rays and the
        clamp's factor on those that got through (core.integrator.direct; no columns: nothing clamped). For the estimator's strategies, D and U of every hit and the N of
        each ray that got through; a strategy whose samples all came back empty adds nothing."""
        if not shader.lambertian:  # the closed form E_u is of Lambert's cosine about the normal
            return
        albedo = None
        for k in self.strategies:
            if not (vec.max3(value[k]) > 0).any():
                continue
            if albedo is None:
                albedo = _diffuse_albedo(shader, hits)
                if albedo is None:
                    return
            diffuse = hits.throughput * value[k] * f_diff[k]
            add_unoccluded(self.table, k, hits.pos, hits.ns, hits.path, albedo, diffuse, self.ndu)
            seen = visibility[k] == VISIBLE
            self.ndu[hits.path[seen], :3] += diffuse[seen] * cuts[k][seen][:, None] if cuts.shape[1] else diffuse[seen]


def _diffuse_albedo(shader, hits):
    """throughput x the diffuse part's albedo / pi at each hit (None without a diffuse part):
    the diffuse part toward the normal, since it is that times the cosine (the layers above
    attenuate it by factors of wo alone, bsdf.mixture.eval_lobes)."""
    n = len(hits.path)
    normal = np.zeros((n, 3))
    normal[:, 2] = 1.0
    f_diff = shader.evaluate(hits.wo_l, normal, np.ones(n, bool), hits.inside).diffuse
    return hits.throughput * f_diff if (f_diff > 0).any() else None
