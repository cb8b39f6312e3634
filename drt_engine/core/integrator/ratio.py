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

The integrator adds each sample's N, D and U (summed over these lights) to a wave output
``RATIO`` of NDU_CHANNELS columns; its N is also in Combined, as Monte Carlo has it. The
film keeps them as sums (core.film.ratio_sums), over all samples and over class A (the error estimate's half),
and ``resolve`` replaces N by U N / D when the image is read. What stays Monte Carlo:
glossy parts (with MIS), emission, the world, emissive meshes, delta lights (their E_u V
is exact already), moving lights, lights chosen among many, and any light without a
closed form.
"""
from __future__ import annotations

from ..base.jit import kernel
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
