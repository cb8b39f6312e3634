"""Shadow catchers, as Cycles' integrator_split_shadow_catcher: where a camera path (a camera ray,
or one gone straight on through transparent surfaces) first meets a shadow catcher object that is
not a holdout, it splits. The path itself goes on through the whole scene (Combined: the catcher
with the other objects' shadows and reflections); from there on it adds nothing to the matte, which
keeps what the path brought before and takes its throughput as transparency. The split-off path
sees the catchers alone (Cycles' SHADOW_CATCHER_VISIBILITY: the other objects and their emission
are not there for its rays and shadow rays; lights and the world, shadow catchers by default in
Blender's sync, are) and sums the catcher's light as if the other objects were not there.

That second path starts on the same camera ray with the same sample values (Cycles copies the
state, random numbers included), so it is traced as a render of the catchers alone over the
samples that split (``Catchers``, a second integrator the renderer builds), weighted by the
throughput at the split. The film reads Combined and the Shadow Catcher pass from these sums
(core.film.shadow_catcher)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..film.shadow_catcher import BACKGROUND, MATTE, PATHS, SPLITS

LEFT_OUT = ("shadow catcher: the light passes and light groups still count the catchers' light with the "
            "other objects (Cycles leaves the paths that met a catcher out of them)")
"""The warning with shadow catchers and light passes or light groups."""
RATIO_LEFT_OUT = ("shadow catcher: the catcher paths estimate lights' direct light by Monte Carlo, and the "
                  "matte leaves out the ratio estimator's share of what paths bring before a catcher")
"""The warning with shadow catchers and the ratio shadow estimator."""
NOT_DENOISED = ("shadow catcher: the image is not denoised (DRT denoises the whole scene's Combined, not the "
                "catchers' matte Cycles' Combined is with them)")
"""The warning with shadow catchers and Denoise on (the render, and a farm's merge, leave it undenoised)."""


def catchers_only(scene):
    """The scene of the shadow catchers alone, or None when no object is one."""
    kept = [instance for instance in scene.instances if instance.shadow_catcher]
    return replace(scene, instances=kept) if kept else None


def catcher_settings(settings):
    """The settings the catcher paths are traced with: Combined alone, Monte Carlo direct light."""
    return replace(settings, passes=("Combined",), aovs=(), shadow_estimator="MONTE_CARLO",
                   use_denoising=False, use_adaptive_sampling=False)


@dataclass
class CatcherWave:
    """One wave's record of its splits: per path whether it split, its throughput and its matte
    (RGB, alpha) there, and the world its camera ray sees (with ``background``)."""

    split: np.ndarray
    throughput: np.ndarray
    matte: np.ndarray
    background: np.ndarray | None


class Catchers:
    """The scene's shadow catchers: ``objects`` per instance, ``held`` (per instance) the object
    holdouts that do not split, and the integrator of the catchers alone (``paths``)."""

    def __init__(self, objects: np.ndarray, held: np.ndarray, geometry, paths, background: bool):
        self.objects = objects & ~held
        self.geometry = geometry
        self.paths = paths
        self.background = background

    def new(self, n: int) -> CatcherWave:
        return CatcherWave(np.zeros(n, bool), np.zeros((n, 3)), np.zeros((n, 4)),
                           np.zeros((n, 3)) if self.background else None)

    def split(self, surf, wave: CatcherWave, radiance: np.ndarray, alpha: np.ndarray, world=None):
        """Split the paths of ``surf`` that meet a catcher straight for the first time: their matte
        is what they brought so far, less their throughput's share of alpha; ``world(rows)`` the
        world seen along those hits' rays (for the background)."""
        rows = np.flatnonzero(surf.straight & self.objects[self.geometry.source_of(surf.prim)[:, 0]])
        rows = rows[~wave.split[surf.path[rows]]]
        if len(rows) == 0:
            return
        path, throughput = surf.path[rows], surf.throughput[rows]
        wave.split[path] = True
        wave.throughput[path] = throughput
        wave.matte[path, :3] = radiance[path]
        wave.matte[path, 3] = alpha[path] - throughput.mean(axis=1)
        if wave.background is not None:
            wave.background[path] += throughput * world(rows)

    def write(self, wave: CatcherWave, samples, sampler, radiance, alpha, aux: dict):
        """The wave's catcher sums into ``aux``: the matte (the paths that never split keep all they
        brought), the splits, and the catcher paths traced from the samples that split."""
        split = wave.split
        radiance = np.where(np.isfinite(radiance), radiance, 0.0)
        aux[MATTE] = np.where(split[:, None], wave.matte, np.concatenate([radiance, alpha[:, None]], axis=1))
        aux[MATTE][:, 3] = np.clip(aux[MATTE][:, 3], 0.0, 1.0)
        aux[SPLITS] = split[:, None].astype(float)
        aux[PATHS] = np.zeros((len(split), 3))
        rows = np.flatnonzero(split)
        if len(rows):
            light = self.paths.trace(samples.take(rows), sampler)["Combined"][:, :3]
            aux[PATHS][rows] = wave.throughput[rows] * light
        if wave.background is not None:
            aux[BACKGROUND] = wave.background
