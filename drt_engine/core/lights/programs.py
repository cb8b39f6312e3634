"""Light node trees: a light's Emission colour x strength from its shader program, per sample and hit.

Cycles evaluates a light's shader where light sampling picks a point on it and where a ray hits it
(kernel/light/sample.h: shader_setup_from_sample, with the ray flags of an emission alone), the
light's object the shading object. Ng: from the light toward the shaded point for a point or spot
light without radius or with soft falloff, the sphere's normal at the point for a sphere, the
direction an area light shines, from the sun for a sun; P the point on the light (a sun's: its Ng);
the incoming direction from the light toward the shaded point; the ray length the distance.
Texture Coordinate's Normal is Ng in the object's space (through its transposed matrix, scale
included) and Object the point there: what an IES Texture reads unless its Vector is linked. Light
Path and Light Falloff read the rays as light samples do (core.shading.lightpath).
"""
from __future__ import annotations

import numpy as np

from ..scene import Light
from ..shading.lightpath import BACKGROUND_LENGTH, RayPath, camera_bounces
from ..shading.nodes import DirectionContext, Evaluator

COORDS = ("normal", "object", "position", "normal_world", "true_normal", "incoming")
"""The coordinates a light's shader has (the export names a tree that asks for another)."""


def _unit(v):
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(length > 0, length, 1.0)


class LightContext(DirectionContext):
    """Shader coordinates at points on a light: ``ng`` and ``p`` in world space, ``ng_local`` and
    ``p_local`` in the light's unscaled frame, ``scale`` its object's axis lengths, ``rotation`` and
    ``centre`` (per point) its frame in the world."""

    def __init__(self, ng, ng_local, p, p_local, incoming, scale, rotation, centre, light_path):
        super().__init__(incoming, light_path)
        self.normal = ng
        scale = np.where(np.asarray(scale, float) > 0, scale, 1.0)
        self._coords = {"normal": _unit(ng_local * scale), "object": p_local / scale, "position": p,
                        "normal_world": ng, "true_normal": ng, "incoming": incoming}
        self._matrix = np.zeros((self.n, 4, 4))
        self._matrix[:, :3, :3] = rotation * scale
        self._matrix[:, :3, 3] = centre
        self._matrix[:, 3, 3] = 1.0

    def coord(self, name, uv_map=""):
        return self._coords[name]

    def object_matrix(self):
        return self._matrix

    def shifted(self, dp):
        return self  # no footprint at a light: its images are looked up at the point


def light_geometry(light: Light, local, dloc, dist):
    """(Ng, P) in the light's frame for rays from ``local`` along ``dloc`` that reach it at ``dist``
    (inf: a sun)."""
    n = len(local)
    if light.kind == "SUN":
        return -dloc, -dloc
    p = local + dloc * dist[:, None]
    if light.kind == "AREA":
        return np.broadcast_to([0.0, 0.0, -1.0], (n, 3)), p
    if light.radius > 0 and not light.soft_falloff:
        return _unit(p), p
    return -dloc, p


def emission(light: Light, textures, ng, ng_local, p, p_local, wi, dist, rotation, centre, bounces) -> np.ndarray:
    """The light's program output (N, 3) at points reached along ``wi`` (world, toward the light)
    at ``dist`` (LightContext's arguments); ``bounces`` the paths' (None: camera rays')."""
    n = len(wi)
    length = np.where(np.isfinite(dist), dist, BACKGROUND_LENGTH)
    path = RayPath.light_samples(camera_bounces(n) if bounces is None else bounces, length)
    ctx = LightContext(ng, ng_local, p, p_local, -wi, light.object_scale, rotation, centre, path)
    out = np.asarray(Evaluator(light.program, ctx, textures)(light.emission), float)
    return np.broadcast_to(out if out.ndim == 2 else out[:, None], (n, 3))
