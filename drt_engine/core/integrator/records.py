"""Named records of arrays that flow between the integrator's stages (pbrt-v4's work items,
Mitsuba 3's loop state): one field per quantity, one row per ray, instead of long positional
argument lists and tuples. A stage takes records and returns new ones; ``take`` gathers rows
(a slice gives views, so a material's hits cost nothing to cut out)."""
from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cache

import numpy as np

from ..base.vectors import Frame


@cache
def _names(kind: type) -> tuple[str, ...]:
    """A record type's field names, found once: ``dataclasses.fields`` walks every field per call,
    and records are cut and joined many times per wave (a third of a glossy render's Python calls)."""
    return tuple(f.name for f in fields(kind))


class Rows:
    """A record of arrays with one row per ray: its length is its first field's, ``take`` gathers
    rows (an index array, a mask or a slice) field by field, a field nobody asked for (None) staying None."""

    def __len__(self):
        return len(getattr(self, _names(type(self))[0]))

    def take(self, rows):
        def rows_of(name):
            value = getattr(self, name)
            return None if value is None else value[rows]

        return type(self)(**{name: rows_of(name) for name in _names(type(self))})

    @staticmethod
    def concat(records: list):
        """One record of the rows of ``records`` (of one type), in order; a field that none of
        them has (None: nobody asked for it) stays None."""
        def joined(name):
            parts = [getattr(r, name) for r in records]
            return None if parts[0] is None else np.concatenate(parts)

        return type(records[0])(**{name: joined(name) for name in _names(type(records[0]))})


@dataclass
class Samples(Rows):
    """Which camera samples a wave traces: ``index`` the film pixel (window), ``pixel`` the
    pixel's id in the whole image (seeds its numbers whatever the window), ``sample`` the
    sample id in the sampler's sequence."""

    index: np.ndarray
    pixel: np.ndarray
    sample: np.ndarray


@dataclass
class PathState(Rows):
    """Live paths of a wave at one depth, one row per path.

    ``path`` is the row of the camera sample in the wave; ``prev_pdf`` the solid-angle pdf of
    the direction that brought the ray here (inf: camera ray or delta lobe); ``prev_normal``
    and ``prev_shading`` the geometric and shading normals of the surface it left (facing
    where it came from; the first decides which world visibility applies, the second is the
    one the world's light sampling is cosine-weighted around); ``straight`` whether the
    camera sees through to here only through transparent surfaces (Cycles' camera ray);
    ``bounces`` the ray's kind and the path's depths (core.shading.lightpath), None unless a
    shader program reads Light Path; ``mis_origin`` (with transparent shadows) where the
    direction that ``prev_pdf`` is of was sampled: a transparent pass-through keeps the previous
    bounce's pdf, normals and origin, as Cycles keeps its MIS state through transparent bounces,
    since light sampling from there reaches through the transparent surface too; ``min_pdf`` (with
    Filter Glossy) the least density of the path's non-transparent bounces so far (inf: none or
    only delta ones; core.bsdf.blur); ``receiver`` (with light linking) the receiver light set of
    the object the path last bounced off, not counting transparent pass-throughs (Cycles'
    mis_ray_object; 0 for camera rays, which see every emitter); ``continuation`` (with Russian
    roulette) what the ray's hit divides the throughput by before it lights and bounces, 0 where the
    path ends there after the ray saw what it found (Cycles' continuation_probability,
    core.integrator.continuation); ``world_pdf`` (under a world that does not vary) the density
    its light sample has toward the ray from the surface it left, or world_lobes.COSINE where that
    is the cosine about ``prev_shading`` (core.integrator.world_lobes)."""

    path: np.ndarray
    origins: np.ndarray
    dirs: np.ndarray
    tmax: np.ndarray
    throughput: np.ndarray
    prev_pdf: np.ndarray
    prev_normal: np.ndarray
    prev_shading: np.ndarray
    straight: np.ndarray
    time: np.ndarray  # shutter time of each ray (zeros when nothing moves)
    bounces: np.ndarray | None = None
    mis_origin: np.ndarray | None = None
    min_pdf: np.ndarray | None = None
    receiver: np.ndarray | None = None
    continuation: np.ndarray | None = None
    world_pdf: np.ndarray | None = None

    def mis_ray(self, rows, t):
        """(origins, distances) of rays ``rows`` whose hits lie ``t`` away, as the lights' pdfs
        take them: from ``mis_origin`` when there is one (the direction is the same)."""
        if self.mis_origin is None:
            return self.origins[rows], t
        o = self.mis_origin[rows]
        return o, t + np.linalg.norm(self.origins[rows] - o, axis=1)



@dataclass
class SurfaceHits(Rows):
    """Rays that hit a surface, in shading order: the frame faces the incoming ray
    (``inside``: it came from the back), about the normal of the lobes but the diffuse ones,
    ``ns`` the shading normal facing it as the diffuse lobes have it (Cycles' sd->N: where wo lies
    below it, the frame's is raised from it, core.integrator.hits), ``dn`` that normal in the frame
    ((0, 0, 1) where they are one), ``wo_l`` is the outgoing direction in that frame,
    ``scale`` the offset that clears the surface, ``row`` the hit's row in its depth's
    intersection results, ``normal`` the mesh's shading normal as interpolated (the Normal pass),
    ``bounces`` the path state's, ``smooth`` the shading normal a bump or normal map replaced
    (facing the ray; None where none did), which shadows the diffuse lobes (bsdf.bump_shadowing)."""

    path: np.ndarray
    row: np.ndarray
    prim: np.ndarray
    mat: np.ndarray
    pos: np.ndarray
    ng: np.ndarray
    frame: Frame
    ns: np.ndarray
    dn: np.ndarray
    wo: np.ndarray
    wo_l: np.ndarray
    inside: np.ndarray
    scale: np.ndarray
    throughput: np.ndarray
    straight: np.ndarray
    time: np.ndarray
    normal: np.ndarray
    bounces: np.ndarray | None = None
    smooth: np.ndarray | None = None


@dataclass
class ShadowRays(Rows):
    """Shadow rays stopped on see-through surfaces: a queue's rows (``f``: floats, ``i``: ints,
    the columns core.integrator.shadows lays out) and the depths of the paths that cast them
    (core.shading.lightpath)."""

    f: np.ndarray
    i: np.ndarray
    bounces: np.ndarray

