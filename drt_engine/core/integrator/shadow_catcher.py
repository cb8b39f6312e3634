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
(core.film.shadow_catcher).

The light passes and light groups keep what a path brought before its split and nothing after, as
Cycles' film writes none for a path flagged PATH_RAY_SHADOW_CATCHER_HIT (the split path and the one
split off; light_passes.h, "for easier compositing back together of the combined pass"): each
path's share of them is kept at its split and put back at the wave's end. So a scene's groups, its
every emitter in one, sum to the matte with the world it sees (Combined with an opaque film and the
Shadow Catcher pass), whatever the film."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..film.shadow_catcher import BACKGROUND, MATTE, PATHS, SPLITS

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


SEEN = ("Emit", "Env")
"""The passes the split-off paths write too, as Cycles' (what their camera ray sees: a catcher's own
emission, the world through a transparent one), so those count twice there, as in Cycles."""


def catcher_settings(settings):
    """The settings the catcher paths are traced with: Combined (and of ``SEEN`` those asked for),
    Monte Carlo direct light."""
    return replace(settings, passes=("Combined",) + tuple(name for name in SEEN if name in settings.passes), aovs=(),
                   shadow_estimator="MONTE_CARLO", use_denoising=False, use_adaptive_sampling=False)


@dataclass
class CatcherWave:
    """One wave's record of its splits: per path whether it split, its throughput and its matte
    (RGB, alpha) there, and the world its camera ray sees (with ``background``); ``counted`` the
    wave's per-path light pass and light group sums, ``kept`` each one's rows as they were at the
    paths' splits."""

    split: np.ndarray
    throughput: np.ndarray
    matte: np.ndarray
    background: np.ndarray | None
    counted: tuple = ()
    kept: tuple = ()


class Catchers:
    """The scene's shadow catchers: ``objects`` per instance, ``held`` (per instance) the object
    holdouts that do not split, and the integrator of the catchers alone (``paths``); ``background``
    whether the Background sum is kept, ``env`` whether the Env pass is that sum (the world the camera
    sees and behind the catchers: Cycles' split-off path shades its Background pass, Env, there over an
    opaque film)."""

    def __init__(self, objects: np.ndarray, held: np.ndarray, geometry, paths, background: bool, env: bool = False):
        self.objects = objects & ~held
        self.geometry = geometry
        self.paths = paths
        self.background = background
        self.env = env

    def new(self, n: int, counted: tuple = ()) -> CatcherWave:
        """A wave of ``n`` paths; ``counted`` its per-path arrays no split path adds to after its split."""
        return CatcherWave(np.zeros(n, bool), np.zeros((n, 3)), np.zeros((n, 4)),
                           np.zeros((n, 3)) if self.background or self.env else None, counted,
                           tuple(np.zeros_like(sums) for sums in counted))

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
        for sums, kept in zip(wave.counted, wave.kept):
            kept[path] = sums[path]
        if wave.background is not None:
            wave.background[path] += throughput * world(rows)

    def write(self, wave: CatcherWave, samples, sampler, radiance, alpha, aux: dict):
        """The wave's catcher sums into ``aux``: the matte (the paths that never split keep all they
        brought), the splits, and the catcher paths traced from the samples that split; the split
        paths' light passes and groups back to what they were at their splits."""
        split = wave.split
        for sums, kept in zip(wave.counted, wave.kept):
            sums[split] = kept[split]
        radiance = np.where(np.isfinite(radiance), radiance, 0.0)
        aux[MATTE] = np.where(split[:, None], wave.matte, np.concatenate([radiance, alpha[:, None]], axis=1))
        aux[MATTE][:, 3] = np.clip(aux[MATTE][:, 3], 0.0, 1.0)
        aux[SPLITS] = split[:, None].astype(float)
        aux[PATHS] = np.zeros((len(split), 3))
        rows = np.flatnonzero(split)
        traced = self.paths.trace(samples.take(rows), sampler) if len(rows) else {}
        if len(rows):
            aux[PATHS][rows] = wave.throughput[rows] * traced["Combined"][:, :3]
        if self.background:
            aux[BACKGROUND] = wave.background
        if self.env:  # Cycles' Background pass is its Env
            aux["Env"][:] = wave.background
        for name in SEEN:
            if name in traced:
                aux[name][rows] += wave.throughput[rows] * traced[name]
