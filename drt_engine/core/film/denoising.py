"""The denoising features Blender's Denoise node (OpenImageDenoise) takes beside the image.

Defined as Cycles defines its "Denoising Albedo" and "Denoising Normal" passes
(intern/cycles/kernel/film/denoising_passes.h): a camera path walks through hits whose
lobes are mostly specular-like (GGX alpha at most 0.075: mirrors, clear glass, transparency),
multiplying a feature throughput by their specular albedo, and at the first hit that is not
(or has no lobes) writes that throughput times the hit's diffuse-like albedo, and its shading
normal in Cycles' camera space (x right, y up, z away from the viewer), which Cycles from
Blender 5.2 on scales by the walk's mean feature throughput (``weighted``). Emission and the
world seen while the walk is still open add to the albedo, as in Cycles. The film averages
both over the pixel's samples.
"""
from __future__ import annotations

import dataclasses

import numpy as np

ALBEDO, NORMAL = "Denoising Albedo", "Denoising Normal"
PASSES = (ALBEDO, NORMAL)


def world_to_camera(camera) -> np.ndarray:
    """3x3 rotation from world directions to Cycles' camera space, whose z is Blender's -z."""
    rotation = np.asarray(camera.matrix, np.float64)[:3, :3]
    rotation = rotation / np.maximum(np.linalg.norm(rotation, axis=0), 1e-30)
    return np.diag([1.0, 1.0, -1.0]) @ rotation.T


class Features:
    """The open feature walks of one wave: each camera sample's feature throughput and
    whether its features are still to be written; writes into the wave's passes ``aux``."""

    def __init__(self, n: int, camera, aux: dict, weighted: bool = False):
        self.throughput = np.ones((n, 3))
        self.weighted = weighted
        self.open = np.ones(n, bool)
        self.to_camera = world_to_camera(camera)
        self.albedo = aux.get(ALBEDO)
        self.normal = aux.get(NORMAL)

    def emitted(self, path: np.ndarray, radiance: np.ndarray) -> None:
        """Light the paths ``path`` see (emission, lights, world): part of the albedo while open."""
        if self.albedo is None or len(path) == 0:
            return
        keep = self.open[path]
        self.albedo[path[keep]] += self.throughput[path[keep]] * radiance[keep]

    def surface(self, hits, shader) -> None:
        """The hits of one shader: close the walks of diffuse-like hits, go on through the others."""
        keep = np.flatnonzero(self.open[hits.path])
        if len(keep) == 0:
            return
        path = hits.path[keep]
        rows = keep if shader.bound else None
        diffuse, specular, take = shader.denoising_albedos(hits.wo_l[keep, 2], hits.inside[keep], rows)
        done, going = path[take], path[~take]
        if self.albedo is not None:
            self.albedo[done] += self.throughput[done] * diffuse[take]
        if self.normal is not None:
            # a hit without lobes (pure emission, holdout) has no normal to give: zero, as Cycles
            normal = hits.ns[keep[take]] @ self.to_camera.T if shader.lobes else 0.0
            if self.weighted:
                normal = normal * self.throughput[done].mean(axis=1)[:, None]
            self.normal[done] = normal
        self.open[done] = False
        self.throughput[going] *= specular[~take]


def with_features(settings):
    """``settings`` (core.settings.RenderSettings) with the features a denoiser reads traced too:
    OpenImageDenoise is guided by them even where the user asked for no such passes."""
    return dataclasses.replace(settings, passes=tuple(settings.passes) + tuple(
        name for name in PASSES if name not in settings.passes))
