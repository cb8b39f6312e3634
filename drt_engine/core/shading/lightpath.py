"""Blender's Light Path and Light Falloff nodes as Cycles' svm_node_light_path and
svm_node_light_falloff compute them, over a batch of shading points.

What a point needs is the ray that brought it there (``RayPath``): whether the camera sees it
straight (through transparent surfaces only, which keep a ray's kind in Cycles), the kind of
lobe that spawned the ray otherwise, the ray's length, and the depths counted along the path:
ray depth (every bounce but transparent ones), glossy (non-diffuse reflections), transmission,
transparent and diffuse (diffuse reflections, with diffuse bounces on). The integrator carries the kind and the depths per path in one small int
array (``KIND`` bits and depth columns, updated by core.integrator.continuation).

A shadow ray's surfaces (transparent shadows, core.integrator.shadows) are shaded as Cycles
shades them: Is Shadow Ray 1 and no other ray kind, the path's depths with the surfaces the
shadow ray passed added to its Transparent Depth, Ray Length from the shaded point.

Outputs that are 0 at every point DRT shades, as Cycles' would be for the same path:
- Is Diffuse Ray and Diffuse Depth with diffuse bounces 0 (the default): paths continue only
  through non-diffuse lobes (diffuse light is direct light), so no ray is spawned by a diffuse lobe.
- Is Volume Scatter Ray and Portal Depth (Blender 5): DRT has no volumes and no portals.

Emission evaluated by light sampling and the world (seen by a ray or sampled) are evaluated as
Cycles evaluates them, with its emission flag: one bounce further (Ray Depth + 1); a light
sample has no ray kind, and the world's Ray Length is ``BACKGROUND_LENGTH``. Without a
``RayPath`` (the environment's importance table, the emissive triangles' power estimate) a
point is shaded as the light sample of a camera hit, ``ESTIMATE_LENGTH`` away.

Light Falloff reads the same Ray Length: a surface hit's distance, a light-sampled emitter's
distance from the shaded point, the world's FLT_MAX (where Cycles passes Strength through).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

REFLECT, TRANSMIT, GLOSSY, SINGULAR, DIFFUSE = 1, 2, 4, 8, 16
"""Bits of the ``KIND`` column: the lobe that spawned the ray (Cycles' PATH_RAY_* of the same names)."""
KIND, DEPTH, GLOSSY_DEPTH, TRANSMISSION_DEPTH, TRANSPARENT_DEPTH, DIFFUSE_DEPTH = range(6)
COLUMNS = 6
BACKGROUND_LENGTH = float(np.finfo(np.float32).max)
"""Ray Length at the world: Cycles' FLT_MAX (shader_setup_from_background; measured with Blender
5.0's Cycles, for the camera's rays)."""

OUTPUTS = ("Is Camera Ray", "Is Shadow Ray", "Is Diffuse Ray", "Is Glossy Ray", "Is Singular Ray",
           "Is Reflection Ray", "Is Transmission Ray", "Is Volume Scatter Ray", "Ray Length", "Ray Depth",
           "Diffuse Depth", "Glossy Depth", "Transparent Depth", "Transmission Depth", "Portal Depth")
"""The node's outputs, in the order the program's ``light_path`` operation returns them."""
FALLOFF = ("Quadratic", "Linear", "Constant")
"""Light Falloff's outputs, in the order the program's ``light_falloff`` operation returns them."""
ESTIMATE_LENGTH = 1.0
"""Ray Length where no ray is known (the emissive triangles' power estimate): a unit distance, so
that emission growing with distance (Light Falloff's Linear and Constant) keeps its light samples."""


def camera_bounces(n: int) -> np.ndarray:
    """The kind and depths of ``n`` camera rays: all 0."""
    return np.zeros((n, COLUMNS), np.int32)


@dataclass
class RayPath:
    """The rays that reached a batch of points: ``camera`` (N,) bool, ``bounces`` (N, COLUMNS)
    int, ``length`` (N,), whether the points are evaluated as emission (a light sample or
    the world: Cycles' PATH_RAY_EMISSION) and whether shadow rays reached them."""

    camera: np.ndarray
    bounces: np.ndarray
    length: np.ndarray
    emission: bool = False
    shadow: bool = False

    def take(self, rows) -> "RayPath":
        return RayPath(self.camera[rows], self.bounces[rows], self.length[rows], self.emission, self.shadow)

    @classmethod
    def light_samples(cls, bounces: np.ndarray, length: np.ndarray) -> "RayPath":
        """Emission or world sampled from points whose paths have ``bounces``: no ray kind."""
        kindless = bounces.copy()
        kindless[:, KIND] = 0
        return cls(np.zeros(len(bounces), bool), kindless, length, emission=True)


def outputs(path: RayPath | None, n: int) -> tuple:
    """The node's outputs (``OUTPUTS``) at ``n`` points reached by ``path`` (None: light samples of
    camera hits, see the module's docstring)."""
    path = _known(path, n)
    b = path.bounces
    kind = b[:, KIND]  # 0 for camera rays: transparent surfaces keep a ray's kind
    zero = np.zeros(n)

    def bit(mask):
        return ((kind & mask) != 0).astype(float)

    depth = b[:, DEPTH] + (1 if path.emission else 0)
    shadow = np.full(n, 1.0 if path.shadow else 0.0)
    return (path.camera.astype(float), shadow, bit(DIFFUSE), bit(GLOSSY), bit(SINGULAR), bit(REFLECT), bit(TRANSMIT),
            zero, np.asarray(path.length, float), depth.astype(float), b[:, DIFFUSE_DEPTH].astype(float),
            b[:, GLOSSY_DEPTH].astype(float), b[:, TRANSPARENT_DEPTH].astype(float),
            b[:, TRANSMISSION_DEPTH].astype(float), zero)


def falloff(strength, smooth, path: RayPath | None, n: int) -> tuple:
    """Light Falloff's outputs (``FALLOFF``) at ``n`` points reached by ``path``, as Cycles 5's
    svm_node_light_falloff: Strength times 1, the Ray Length or its square, smoothed near the
    light by length² / (Smooth + length²) where Smooth > 0; at the world (FLT_MAX) Strength as is."""
    length = np.asarray(_known(path, n).length, float)
    strength = np.broadcast_to(np.asarray(strength, float), (n,))
    smooth = np.broadcast_to(np.asarray(smooth, float), (n,))
    squared = length * length
    soft = np.where(smooth > 0.0, squared / np.where(smooth > 0.0, smooth + squared, 1.0), 1.0)
    world = length == BACKGROUND_LENGTH
    return tuple(np.where(world, strength, strength * scale * soft) for scale in (1.0, length, squared))


def _known(path: RayPath | None, n: int) -> RayPath:
    """``path``, or for None the light samples of camera hits ``ESTIMATE_LENGTH`` away."""
    return RayPath.light_samples(camera_bounces(n), np.full(n, ESTIMATE_LENGTH)) if path is None else path


def reads_light_path(program) -> bool:
    """Whether a shader program (or None) reads the ray's path: has a Light Path or a Light Falloff node."""
    return program is not None and any(node.op in ("light_path", "light_falloff") for node in program.nodes)
