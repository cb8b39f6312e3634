"""A render of one SceneData with one RenderSettings: the prepared scene, the progressive
driver and the integrator put together, and the waves split over the render's threads.

Every random number is drawn from the sampler handed to the integrator with the camera
sample's own (pixel, sample id): sample k of a pixel comes from replicate k % 2 (see
adaptive.replicate_samplers), so the film's two halves are independent estimates.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np

from ..base import jit
from ..errors import SceneError, SettingsError
from ..film.denoising import PASSES as FEATURE_PASSES, with_features
from ..film.film import Film
from ..film.shadow_catcher import hidden_sums
from ..integrator.aovs import AOV_TRANSPARENCY
from ..integrator.bounces import LIMIT_TRANSPARENCY
from ..integrator.integrator import Integrator
from ..integrator.lightpasses import RATIO_LEFT_OUT, SHADOWS_LEFT_OUT
from ..integrator.plan import make_plan
from ..integrator.records import Samples
from ..integrator.shadow_catcher import NOT_DENOISED as CATCHER_NOT_DENOISED, \
    RATIO_LEFT_OUT as CATCHER_RATIO_LEFT_OUT, catcher_settings, catchers_only
from ..sampling.sampler import Sampler
from ..scene import SceneData
from ..settings import RenderSettings, pass_of, read_over
from ..validate import validate_camera
from . import adaptive
from .denoise import Schedule, denoise_film, denoised_passes, figures
from .driver import TARGET_MIN_SAMPLES, WAVE, ProgressUpdate, drive
from .prepared import PreparedScene

__all__ = ["WAVE", "ProgressUpdate", "RenderResult", "Renderer", "PreparedScene"]

_MIN_PIECE = 1 << 12  # fewest camera samples in one thread's piece of a wave (smaller waves stay whole)


@dataclass
class RenderResult:
    passes: dict
    stats: dict
    cancelled: bool = False
    warnings: list = field(default_factory=list)
    log: list = field(default_factory=list)  # report.ErrorLog entries, one per step


class Renderer:
    """Renders one SceneData with one RenderSettings.

    ``prepared`` (core.render.prepared.PreparedScene) reuses the Embree scenes, lights and materials
    built for the same scene with another camera; without it they are built here. ``denoiser``
    (core.film.denoiser.Denoiser) is the OpenImageDenoise that ``use_denoising`` runs; the caller
    finds the library (the core never looks for one).
    """

    def __init__(self, scene: SceneData, settings: RenderSettings, prepared: PreparedScene | None = None,
                 denoiser=None):
        if scene.camera is None:
            raise SceneError("the scene has no camera")
        if prepared is None:
            prepared = PreparedScene(scene)
        elif not prepared.serves(scene):
            raise ValueError("the prepared scene was made for another scene")
        else:
            validate_camera(scene.camera)
        self.prepared = prepared
        self.scene, self.settings, self.camera = scene, settings, scene.camera
        self.denoiser = denoiser
        catchers = catchers_only(scene)  # the scene of its shadow catchers alone, if it has any
        # a denoised Combined would be the whole scene's, not the catchers' matte: not denoised, and said so
        self.denoising = settings.use_denoising and not settings.partial and catchers is None
        self._denoised = None  # (samples in the film, core.render.denoise.Denoised) of the newest denoising
        self._denoise_seconds = 0.0
        self._filters = None  # core.film.denoiser.Filters while a denoising render runs
        self._schedule = None  # core.render.denoise.Schedule while one runs under a target error
        if self.denoising and denoiser is None:
            raise SettingsError("denoising is on but no OpenImageDenoise library was found")
        if settings.use_denoising:  # the features guide the denoiser (a part's, the merge's): traced even
            settings = with_features(settings)  # when not asked for as passes
        self._read_over = read_over(settings.passes)  # light passes' colours, summed (parts keep them), not returned
        if catchers is not None:  # the sums Combined and the Shadow Catcher pass are read from
            self._read_over += hidden_sums(settings.passes, scene.film_transparent)
        if self._read_over:
            settings = replace(settings, passes=tuple(settings.passes) + self._read_over)
        self.threads = settings.threads if settings.threads > 0 else (os.cpu_count() or 1)
        self.geometry, self.lights, self.shaders = prepared.geometry, prepared.lights, prepared.shaders
        self.sampler = Sampler(settings.sampling_pattern, settings.samples, settings.seed)
        self.plan = make_plan(scene, settings, self.geometry, self.lights, self.shaders)
        self.timed = self.plan.time
        self.integrator = Integrator(prepared, scene, settings, self.plan)
        if catchers is not None:
            only, only_settings = prepared.catchers, catcher_settings(settings)
            plan = make_plan(catchers, only_settings, only.geometry, only.lights, only.shaders)
            self.integrator.catch(scene, Integrator(only, catchers, only_settings, plan))
        w, h = self.camera.window_size
        contrast = settings.use_adaptive_sampling and settings.adaptive_mode == "CONTRAST"
        self.film = Film(w, h, settings.passes, track_range=contrast, ratio=bool(self.plan.ratio),
                         halved=FEATURE_PASSES if settings.use_denoising else (), aovs=settings.aovs,
                         cryptomatte_levels=settings.cryptomatte_levels)

    @property
    def rays(self) -> dict:
        return self.integrator.rays

    @property
    def warnings(self) -> list:
        return self.prepared.warnings + self._setting_warnings()

    def _setting_warnings(self) -> list[str]:
        """What these settings make DRT approximate in this scene: shader AOVs behind transparency
        (core.integrator.aovs), paths a bounce limit ends before transparency (core.integrator.bounces),
        light passes without transparent shadows' or the ratio estimator's share (core.integrator.lightpasses)."""
        transparent = any(c.kind == "TRANSPARENT" for m in self.scene.materials for c in m.closures)
        warnings = []
        if self.integrator.aovs is not None and transparent:
            warnings.append(AOV_TRANSPARENCY)
        if self.integrator.limited and transparent:
            warnings.append(LIMIT_TRANSPARENCY)
        if self.integrator.light_passes and self.integrator.shadows is not None:
            warnings.append(SHADOWS_LEFT_OUT)
        if self.integrator.light_passes and self.integrator.ratio:
            warnings.append(RATIO_LEFT_OUT)
        if self.integrator.catchers is not None:
            if self.integrator.ratio:
                warnings.append(CATCHER_RATIO_LEFT_OUT)
            if self.settings.use_denoising:
                warnings.append(CATCHER_NOT_DENOISED)
        return warnings

    def render(self, progress=None) -> RenderResult:
        """Render progressively (core.render.driver) and return the passes, stats and error log."""
        s = self.settings
        first_id, end_id = s.sample_range()
        cap = end_id - first_id  # samples a pixel takes here: ids first_id.. of the full set
        replicas = adaptive.replicate_samplers(s.sampling_pattern, self.sampler.samples, s.seed)
        pool = ThreadPoolExecutor(self.threads, thread_name_prefix="DRT") if self.threads > 1 else None

        def trace(pixel, sample):
            sample = sample + first_id
            samples = Samples(pixel, self._seed_pixels(pixel), sample)
            if replicas is None:
                self._trace(samples, self.sampler, None, pool)
                return
            for r, sampler in enumerate(replicas):
                sel = np.flatnonzero((sample & 1) == r)
                if len(sel):
                    half = samples.take(sel)
                    self._trace(Samples(half.index, half.pixel, half.sample >> 1), sampler, r, pool)

        # with a target error, the steps that could meet it are denoised to know whether the denoised
        # image is there yet (Schedule); without one, only the finished image is denoised
        stepwise = self.denoising and s.target_error > 0
        self._schedule = Schedule(s.target_error) if stepwise else None
        self._filters = self.denoiser.filters() if self.denoising else None
        try:
            try:
                outcome = drive(s, self.film, cap, trace, self.rays, progress,
                                denoised=self._step_figures if stepwise else None)
            finally:
                if pool is not None:
                    pool.shutdown(wait=True)
            if outcome.stopped != "cancelled":
                jit.mark_compiled()  # also when warm: the stamp's time is the folder's last use
            return self._result(outcome)
        finally:
            if self._filters is not None:
                self._filters.close()
                self._filters = None

    def _seed_pixels(self, index):
        """Ids in the whole image of the window's pixels ``index``: they seed the samples, so a
        border render draws the numbers the full render does."""
        w = self.camera.window_size[0]
        x0, y0 = self.camera.window[:2]
        return ((index % w + x0) + (index // w + y0) * self.camera.resolution[0]).astype(np.uint32)

    def _trace(self, samples: Samples, sampler, replicate, pool):
        """Trace a wave, split into one interleaved piece per thread, and add it to the film.

        Piece i takes every ``pieces``-th sample from i: a wave holds the image in pixel order,
        and contiguous pieces gave one thread the image's top and the other its bottom, whose
        costs differ (one thread idle while the other finished). Every path depends only on its
        own (pixel, sample) and Embree answers each ray alone, so the pieces give the values one
        piece would, and the film receives them in the wave's order in one call: the image is
        bit-identical for any thread count. Each piece runs the whole loop (kernels, NumPy's
        array loops and Embree release the GIL).
        """
        n = len(samples)
        pieces = min(self.threads, max(1, n // _MIN_PIECE))
        if pieces == 1:
            values = self.integrator.trace(samples, sampler)
        else:
            rows = [np.arange(i, n, pieces) for i in range(pieces)]
            jobs = [pool.submit(self.integrator.trace, samples.take(r), sampler) for r in rows]
            parts = [job.result() for job in jobs]
            values = {name: _interleaved(rows, [part[name] for part in parts]) for name in parts[0]}
        self.film.add(samples.index, values, samples.sample, replicate=replicate)

    def _result(self, outcome) -> RenderResult:
        s, film = self.settings, self.film
        n_pix = film.n
        last = outcome.log.last or {}
        stats = {"samples": int(film.count.max()) if n_pix else 0, "samples_requested": self.sampler.samples,
                 "samples_mean": float(film.count.mean()) if n_pix else 0.0,
                 "elapsed": outcome.elapsed, "cpu": outcome.log.cpu(), "rays": dict(self.rays),
                 "threads": self.threads, "triangles": self.geometry.triangle_count,
                 "light_strategies": self.lights.strategies, "stopped_by": outcome.stopped,
                 "rmse": last.get("rmse"), "relmse": last.get("relmse"),
                 "adaptive_threshold": outcome.threshold if s.use_adaptive_sampling else None,
                 "adaptive_first_test": outcome.first if s.use_adaptive_sampling else None,
                 "plan": self.plan.as_dict(), "plan_summary": self.plan.summary()}
        passes = {name: image for name, image in film.images().items() if name not in self._read_over}
        warnings = list(self.warnings)
        if s.use_denoising and s.partial:  # the part's film keeps the features for the merge
            passes = {name: image for name, image in passes.items() if pass_of(name) in s.passes}
            warnings.append("this render is one range of the samples (a farm part): it is not denoised here; "
                            "merging the parts denoises the merged image")
        if self.denoising and outcome.stopped != "cancelled":
            passes = self._denoise(passes, stats, outcome.log.last)
        return RenderResult(passes, stats, outcome.stopped == "cancelled", warnings, outcome.log.entries)

    def _denoise_film(self):
        """The film's image denoised (core.render.denoise) on the render's filters, once per sample
        total: the step that ends a render and the result share one denoising."""
        s, samples = self.settings, float(self.film.count.sum())
        if self._denoised is None or self._denoised[0] != samples:
            denoised = denoise_film(self.film, self._filters, s.denoising_prefilter, s.denoising_quality)
            self._denoised = samples, denoised
            self._denoise_seconds += denoised.seconds
        return self._denoised[1]

    def _step_figures(self, entry: dict) -> dict:
        """A step's denoised figures under a target error, when the target may stop it and the
        schedule says the denoised image could be under it; else none."""
        if self.film.count.min() < TARGET_MIN_SAMPLES or not self._schedule.due(entry["relmse"]):
            return {}
        found = figures(self._denoise_film())
        self._schedule.measured(entry["relmse"], found["relmse_denoised"])
        return found

    def _denoise(self, passes: dict, stats: dict, last: dict | None) -> dict:
        """Combined denoised, the rendered one kept as Noisy Image (core.render.denoise.denoised_passes);
        the denoised image's estimated error in ``stats`` and the log's last entry, beside the noisy
        image's. Under a target error the steps that could meet it have it too (driver.drive)."""
        s = self.settings
        found = figures(self._denoise_film())
        stats.update(found, denoising={"prefilter": s.denoising_prefilter, "quality": s.denoising_quality,
                                       "seconds": self._denoise_seconds})
        if last is not None:
            last.update(found)
        return denoised_passes(passes, self._denoised[1], s.passes)


def _interleaved(rows: list, parts: list) -> np.ndarray:
    """One array of the pieces' rows put back where ``rows`` took them from."""
    out = np.empty((sum(len(p) for p in parts),) + parts[0].shape[1:], parts[0].dtype)
    for r, part in zip(rows, parts):
        out[r] = part
    return out
