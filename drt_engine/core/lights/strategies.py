"""Every next-event strategy sampled at once: one kernel call per depth step fills, strategy by
hit, the direction, distance, value and density of each strategy's sample (the lights of the
table, or those picked among many, emissive triangles, the world). What only a shader program
or a moving frame can give (textured emission, the environment's radiance, moving lights) the
caller fills in after, from what the kernel leaves (picks, barycentrics, ``lit``)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel
from ..geometry.accel import offset_scale
from .choice import pick_light
from .kinds import sample_light
from .emitter_tree import pick_emitter
from .triangles import sample_triangle
from .environment import map_pdf
from .world import cosine_direction, sample_world_direction

UNRESTRICTED = -1
"""A strategy that lights every BSDF part (``LightSamples.restrict[k, 0]``); otherwise the row
holds whether it lights the diffuse, reflection and transmission parts (the world's ray visibility)."""

NO_WORLD, UNIFORM_WORLD, MAP_WORLD = 0, 1, 2
NO_SHADOW = 8
"""A bit of ``LightSamples.exclude`` beside bsdf.mixture's ``UNLIT_*``: the sample's light casts no
shadow (Cycles' Cast Shadow off), its shadow ray is not traced."""
NO_MIS = 16
"""Another: the sample's light is light sampling's alone, not weighed against BSDF rays, which do
not count it (an emitter with shadow linking: Cycles finds it behind the objects that cast none of
its shadows with a dedicated light ray, weighed against light sampling; light sampling alone has
the same expectation)."""
_NOTHING_EXCLUDED = np.zeros((0, 0), np.int8)
_NO_GROUPS = np.zeros((0, 0), np.int64)
_NO_MASKS = np.zeros((0, 0), np.int32)


@dataclass
class LightSamples:
    """Every light strategy's sample at the hits of one depth step, strategy by hit: direction,
    distance (inf for distant), value (radiance / pdf; zero where nothing was sampled), pdf, the
    distance to stop short of an emitter that is geometry, per strategy the BSDF parts it
    lights (core.integrator.direct's ``restrict``) and per sample what its light leaves out
    (``exclude``: bsdf.mixture's ``UNLIT_*`` bits and ``NO_SHADOW``, from the ray visibility of
    the light or emissive object sampled; empty when no light leaves anything out) and each
    sample's light group (``group``, core.integrator.lightgroups; empty without light groups) and
    each sample's shadow-ray Embree mask (``mask``, shadow linking; empty: the scene's). ``cycles_pdf``:
    the density Cycles' light sampling has for the sample, where it differs from DRT's (a uniform
    world's: 0, Cycles leaves a world that does not vary out of light sampling, scene/light.cpp's
    "Background MIS has been disabled"; a map's: the map's alone), which weighs a sample that
    Cycles' BSDF rays cannot reach (core.integrator.direct)."""

    wi: np.ndarray
    dist: np.ndarray
    value: np.ndarray
    pdf: np.ndarray
    cycles_pdf: np.ndarray
    stop: np.ndarray
    restrict: np.ndarray
    exclude: np.ndarray = field(default_factory=lambda: _NOTHING_EXCLUDED)
    group: np.ndarray = field(default_factory=lambda: _NO_GROUPS)
    mask: np.ndarray = field(default_factory=lambda: _NO_MASKS)

    @classmethod
    def empty(cls, strategies: int, n: int) -> "LightSamples":
        return cls(np.zeros((strategies, n, 3)), np.zeros((strategies, n)), np.zeros((strategies, n, 3)),
                   np.zeros((strategies, n)), np.zeros((strategies, n)), np.zeros((strategies, n)),
                   np.full((strategies, 3), UNRESTRICTED, np.int8))

    @property
    def strategies(self) -> int:
        return len(self.wi)

    def put(self, k: int, rows, sample) -> None:
        """Strategy k's sample (a core.lights.collection.LightSample) at hits ``rows``."""
        self.wi[k, rows], self.dist[k, rows], self.value[k, rows], self.pdf[k, rows], self.cycles_pdf[k, rows] = \
            sample.wi, sample.dist, sample.value, sample.pdf, sample.pdf

    def take(self, rows) -> "LightSamples":
        return LightSamples(self.wi[:, rows], self.dist[:, rows], self.value[:, rows], self.pdf[:, rows],
                            self.cycles_pdf[:, rows], self.stop[:, rows], self.restrict, self.exclude[:, rows] if self.exclude.size else
                            self.exclude, self.group[:, rows] if self.group.size else self.group,
                            self.mask[:, rows] if self.mask.size else self.mask)

    def arrays(self) -> tuple:
        """The fields, contiguous, in the order core.integrator.direct's kernel takes them."""
        return tuple(np.ascontiguousarray(getattr(self, f.name)) for f in fields(self))


@kernel
def sample_strategies(table, slots, selecting, vertices, triangles, tri_ng, area, emissive, tree, order, emission,
                      geo, world, radiance, share, row_cdf, col_cdf, cell, cell_area, sun, pos, normal, u, wi, dist,
                      value, pdf, cycles_pdf, stop, pick, chosen, bary, lit):
    """Strategies in order: ``slots`` table lights (light k, or with ``selecting`` one picked per
    hit by contribution, its value and pdf the slot's: divided and multiplied by ``chosen``, the
    expected picks of it), emissive triangles when there are (``emissive``: their global ids,
    each picked down lights.emitter_tree's ``tree``, whose leaves are ``order``; ``vertices`` to
    ``emission`` are per emissive triangle),
    the world (``world``: NO_WORLD, UNIFORM_WORLD of ``radiance``, MAP_WORLD: directions from the
    map (and its sun cone, ``sun``) with probability ``share``, value left to the caller). ``u`` (N, S, 2, 2): per strategy
    the point [k, 0] and the choice [k, 1, 0]. Fills the strategy-by-hit outputs; ``pick`` the
    light or triangle sampled, ``bary`` the triangle's barycentrics, ``lit`` where the caller's
    value applies (a triangle's front seen, a map direction of some density: below the normal too,
    where a transmitting lobe takes it, as the escaping rays' MIS weighs against it)."""
    for j in range(len(pos)):
        px, py, pz = pos[j, 0], pos[j, 1], pos[j, 2]
        for k in range(slots):
            i, c = k, 1.0
            if selecting:
                i, p_pick = pick_light(table, px, py, pz, u[j, k, 1, 0])
                c = p_pick * slots
            wx, wy, wz, d, r, g, b, p = sample_light(table, i, px, py, pz, u[j, k, 0, 0], u[j, k, 0, 1])
            wi[k, j, 0], wi[k, j, 1], wi[k, j, 2], dist[k, j] = wx, wy, wz, d
            if selecting:
                r, g, b, p = r / c, g / c, b / c, p * c
            value[k, j, 0], value[k, j, 1], value[k, j, 2], pdf[k, j] = r, g, b, p
            cycles_pdf[k, j] = p
            pick[k, j], chosen[k, j] = i, c
        k = slots
        if len(emissive):
            leaf, c = pick_emitter(tree, px, py, pz, u[j, k, 1, 0])
            i = order[leaf]
            wx, wy, wz, d, p, b0, b1, cos_l = sample_triangle(vertices, triangles, tri_ng, area, c, i, px, py, pz,
                                                              u[j, k, 0, 0], u[j, k, 0, 1])
            wi[k, j, 0], wi[k, j, 1], wi[k, j, 2], dist[k, j], pdf[k, j] = wx, wy, wz, d, p
            cycles_pdf[k, j] = p
            pick[k, j], lit[k, j] = emissive[i], cos_l > 0
            bary[j, 0], bary[j, 1], bary[j, 2] = b0, b1, 1.0 - b0 - b1
            if cos_l > 0:
                s = 1.0 / max(p, TINY)
                value[k, j, 0], value[k, j, 1], value[k, j, 2] = emission[i, 0] * s, emission[i, 1] * s, emission[i, 2] * s
            stop[k, j] = offset_scale(geo, emissive[i], px + wx * d, py + wy * d, pz + wz * d)
            k += 1
        if world == NO_WORLD:
            continue
        nx, ny, nz = normal[j, 0], normal[j, 1], normal[j, 2]
        if world == UNIFORM_WORLD:
            wx, wy, wz, z = cosine_direction(nx, ny, nz, u[j, k, 0, 0], u[j, k, 0, 1])
            p = z / math.pi
            cycles_pdf[k, j] = 0.0  # Cycles finds a world that does not vary by BSDF rays alone
            if p > 0:
                s = 1.0 / max(p, TINY)
                value[k, j, 0], value[k, j, 1], value[k, j, 2] = radiance[0] * s, radiance[1] * s, radiance[2] * s
        else:
            wx, wy, wz, p = sample_world_direction(nx, ny, nz, u[j, k, 0, 0], u[j, k, 0, 1], share, row_cdf, col_cdf,
                                                   cell, cell_area, sun)
            lit[k, j] = p > 0
            cycles_pdf[k, j] = map_pdf(cell, cell_area, sun, wx, wy, wz)
        wi[k, j, 0], wi[k, j, 1], wi[k, j, 2], dist[k, j], pdf[k, j] = wx, wy, wz, math.inf, p
