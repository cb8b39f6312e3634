"""The distribution ray tracing integrator: one wave of camera samples, stage after stage.

Each depth step intersects all live rays at once, adds what they see (emission, lights,
world, each weighted by multiple importance sampling against light sampling), estimates
direct light at every hit with one shadow ray per light strategy, and continues each path
through one non-diffuse lobe (mirror, glossy, glass, transparent) chosen by its albedo, or, with
diffuse bounces (Cycles' Light Paths), through any lobe while the path has diffuse bounces left.
Stages pass named records (core.integrator.records); every random number comes from the sampler the
caller hands to ``trace``, at the dimensions core.sampling.dims lays out.

A depth step is a few kernel calls over the wave's arrays: the closest hits (Embree from the
kernel), the surface hits (integrator.hits), the step's sample values (two calls), every light
strategy's samples (lights.strategies), and per material the direct light with its shadow rays
traced in place (integrator.direct) and the continuation (integrator.continuation); between
them only what shader programs compute (NumPy, per material) and the emission rays find.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass, replace

import numpy as np

from ..base import vectors as vec
from ..base.vectors import Frame
from ..bsdf.blur import blur_roughness
from ..bsdf.bump_shadowing import model_code
from ..bsdf.shader import see_through
from ..bsdf.specular_normal import valid_specular_reflection
from ..film.cryptomatte import SceneIds, slot_count, write_hits
from ..film.denoising import Features
from ..film.film import PixelFilter
from ..film.mist import Mist
from ..film.ratio_sums import RATIO
from ..film.shadow_catcher import BACKGROUND as CATCHER_BACKGROUND
from ..geometry import camera as camera_rays
from ..geometry.motion_vectors import MotionVectors
from ..lights.strategies import LightSamples
from ..sampling import dims as D
from ..settings import AOV_CHANNELS, CRYPTOMATTE_PASSES, LIGHTGROUP_PREFIX
from ..shading.lightpath import BACKGROUND_LENGTH, KIND, RayPath, camera_bounces, reads_light_path
from ..shading.bevel import bevels
from ..shading.occlusion import OcclusionRays, traces
from ..shading.surface import SurfaceContext
from .aovs import ShaderAOVs, reach_scale
from .bounces import binding, ended
from .clamp import limits as clamp_limits, row_limits
from .continuation import continue_paths
from .direct import direct_light
from .hits import surface_records
from .holdout import Holdouts
from .lightgroups import NO_GROUPS, light_groups
from .lightpasses import NO_BOUNCES, NO_SPLIT, NO_WEIGHTS, WaveSplit, asked
from .masks import ray_masks
from .mis import add_emitted
from .ratio import RatioEstimator
from .records import PathState, Samples, ShadowRays, SurfaceHits
from .shadow_catcher import Catchers, CatcherWave
from .shadows import TransparentShadows, limits, new_queue, stopped
from .world_lobes import COSINE, draws_from, world_from_lobes

_MISS_DEPTH = 1e10  # Blender's depth for the background
_NO_BOUNCES = camera_bounces(0)  # the kernels' bounces when paths carry none
_NO_ROULETTE = np.full(2, -1, np.int64)
_NOTHING_CLEAR, _NO_LIMITS = np.zeros(0, bool), np.zeros(0, np.int64)  # the kernels' transparent shadows when off
_NO_BUMP = np.zeros((0, 4))  # the kernels' smooth normals where no bump replaced the shading normal
_AUX = (("Depth", "Z"), ("Normal", "XYZ"), ("Position", "XYZ"), ("DiffCol", "RGB"), ("GlossCol", "RGB"),
        ("Emit", "RGB"), ("Env", "RGB"), ("Denoising Albedo", "RGB"), ("Denoising Normal", "XYZ"), ("Mist", "Z"),
        ("IndexOB", "X"), ("IndexMA", "X"), ("DiffDir", "RGB"), ("DiffInd", "RGB"), ("GlossDir", "RGB"),
        ("GlossInd", "RGB"), ("TransDir", "RGB"), ("TransInd", "RGB"), ("TransCol", "RGB"))


@dataclass
class StepSamples:
    """The sample values the hits of one depth step use, one row per hit: ``light`` (N, S, 2, 2),
    per light strategy k the point on the light ``[:, k, 0]`` and the choice of light or
    triangle ``[:, k, 1, 0]``, valid where the material casts shadow rays; ``path`` (N, 2, 2),
    the lobe direction ``[:, 0]``, the lobe choice ``[:, 1, 0]`` and Russian roulette's
    ``[:, 1, 1]`` (with diffuse bounces; core.sampling.dims), valid where the path continues."""

    light: np.ndarray
    path: np.ndarray

    @property
    def lobe(self) -> np.ndarray:
        return self.path[:, 0]

    @property
    def lobe_choice(self) -> np.ndarray:
        return self.path[:, 1, 0]

    @property
    def roulette(self) -> np.ndarray:
        return self.path[:, 1, 1]

    def take(self, rows) -> "StepSamples":
        return StepSamples(self.light[rows], self.path[rows])


@dataclass
class WaveOutput:
    """The per-sample values of every pass a wave computes: the wave's accumulator, which the
    stages add their contributions to (Combined RGB, alpha, the auxiliary passes, and the
    ratio estimator with its N, D, U when it is used, core.integrator.ratio)."""

    radiance: np.ndarray
    alpha: np.ndarray
    aux: dict
    features: Features | None = None  # the denoising features' walks, when those passes are on
    # per path: its index passes and shader AOVs are final (an opaque enough hit was seen)
    indexed: np.ndarray | None = None
    # per path, with shader AOVs: the share of Cycles' samples that reach its next hit over its
    # throughput's (core.integrator.aovs)
    aov_reach: np.ndarray | None = None
    ratio: RatioEstimator | None = None
    # per path, with light groups: each group's share of the radiance (core.integrator.lightgroups)
    grouped: np.ndarray | None = None
    group_names: tuple = ()
    # with light passes: their per-path split and the paths' weights (core.integrator.lightpasses)
    split: WaveSplit | None = None
    # with shadow catchers: the wave's splits (core.integrator.shadow_catcher)
    catcher: CatcherWave | None = None

    def values(self) -> dict:
        radiance, ratio = self.radiance, None if self.ratio is None else self.ratio.ndu
        finite = np.isfinite(radiance)
        if ratio is not None:
            out_ratio = np.where((finite.all(axis=1) & np.isfinite(ratio).all(axis=1))[:, None], ratio, 0.0)
        radiance = np.where(finite, radiance, 0.0)
        for column, name in enumerate(self.group_names):  # a path Combined drops, its groups drop too
            self.aux[name] = np.where(finite, self.grouped[:, column], 0.0)
        if self.split is not None:  # so do its light passes
            self.split.split[~finite.all(axis=1)] = 0.0
            self.split.passes(self.aux)
        out = {"Combined": np.concatenate([radiance, np.clip(self.alpha, 0.0, 1.0)[:, None]], axis=1)}
        if ratio is not None:
            out[RATIO] = out_ratio
        out.update(self.aux)
        return out


class Integrator:
    """Traces waves of one scene's camera over its prepared scene (core.render.prepared) with one settings."""

    def __init__(self, prepared, scene, settings, plan):
        self.prepared = prepared
        self.geometry, self.lights = prepared.geometry, prepared.lights
        self.camera, self.settings, self.plan = scene.camera, settings, plan
        self.film_transparent = scene.film_transparent
        self.timed = plan.time
        self.filter = PixelFilter(settings.filter_type, settings.filter_size)
        self.pixel_spread = camera_rays.pixel_spread(self.camera)
        self.light_dims = D.LightDims(D.strategy_keys(self.lights), settings.max_depth)
        self.ratio = frozenset(plan.ratio)
        self.light_path = reads_light_path(scene.world.program) or any(
            reads_light_path(m.material.program) for m in prepared.shading) or any(
            reads_light_path(light.program) for light in self.lights.lights)
        # the Ambient Occlusion and Bevel nodes' rays, from the surfaces paths hit (core.shading.occlusion)
        self.occlusion = any(traces(m.material.program) for m in prepared.shading)
        self.mist = Mist(scene.camera, scene.world) if "Mist" in settings.passes else None
        indexed = {"IndexOB", "IndexMA"} & set(settings.passes)
        self.object_index = np.array([float(i.pass_index) for i in scene.instances]) if indexed else None
        self.material_index = np.array([float(m.pass_index) for m in scene.materials]) if indexed else None
        self.motion_vectors = MotionVectors(scene.camera, scene.instances, scene.meshes) \
            if "Vector" in settings.passes else None
        self.cryptomatte = [name for name in CRYPTOMATTE_PASSES if name in settings.passes]
        self.cryptomatte_ids = SceneIds(scene).ids if self.cryptomatte else None
        aovs = ShaderAOVs(prepared.shading, scene.world, scene.film_transparent, settings.aovs) if settings.aovs \
            else None
        self.aovs = aovs if aovs is not None and aovs.writes_any() else None  # AOVs no material writes stay 0
        self.diffuse = settings.diffuse_bounces if plan.rays.get("diffuse") else 0
        self.clamp = clamp_limits(settings)  # Clamp Direct and Indirect (core.integrator.clamp)
        self.clamping = bool(np.isfinite(self.clamp).any())
        # Filter Glossy (core.bsdf.blur): paths carry their least bounce density only when it is on and
        # some material has lobes it blurs
        self.filter_glossy = settings.filter_glossy if any(sh.blurs for sh in prepared.shaders) else 0.0
        # the Bevel node (core.shading.bevel) also reads that density: Cycles bevels no blurry path
        self.min_pdf = self.filter_glossy > 0 or any(bevels(m.material.program) for m in prepared.shading)
        # transparent shadows when some material lets shadow rays through (the plan lists them)
        self.shadows = None
        if plan.see_through:
            clear = self.geometry.of_triangles(np.array([see_through(m) for m in scene.materials]))
            self.shadows = TransparentShadows(self.geometry, clear, self.prepared.raises, self._bind_materials, self._count,
                                              self.clamp)
        # the glossy and transmission limits, where they can end paths before the Total does
        self.limited = binding(settings) and (plan.rays["reflection"] or plan.rays["refraction"]
                                              or plan.rays["diffuse"])
        # paths carry their ray kind and depths only for a scene whose shader programs read them,
        # with diffuse bounces, with transparent shadows (which count them), with objects hidden
        # from some kind of ray (whose masks they give), with a glossy or transmission limit or
        # with Translucent rays and an emitter hidden from diffuse rays
        self.carried = (self.light_path or self.diffuse > 0 or self.shadows is not None or self.geometry.masked
                        or self.limited or (plan.rays["diffuse"] and self.lights.hidden_from_diffuse))
        # Russian roulette after the minimum bounces, as Cycles, only with diffuse bounces (the
        # classic paths, bounded by the depth alone, stay as they were)
        self.roulette = (np.array([settings.min_light_bounces, settings.min_transparent_bounces], np.int64)
                         if self.diffuse else _NO_ROULETTE)
        # per material (and none): its hits draw lobe samples; with diffuse bounces, every lit one
        self.continues = prepared.continues | prepared.lit if self.diffuse else prepared.continues
        # a uniform world's sample is drawn again from the lobes of the hits that have a sheen, toon
        # or translucent lobe (core.integrator.world_lobes): its lobe choice, its own sample
        # dimension, and the density paths record for it, only in a scene with one
        self.world_drawn = self.lights.uniform_world and any(draws_from(sh) for sh in prepared.shaders)
        held = np.array([i.holdout for i in scene.instances], bool)
        self.holdouts = Holdouts(held, self.geometry) if held.any() or any(
            m.shader.holds_out for m in prepared.shading) else None
        self.groups = light_groups(scene, self.lights, settings.passes)  # None: no group to fill
        self.light_passes = asked(settings.passes)  # Diffuse / Glossy / Transmission Direct and Indirect
        self.group_passes = [name for name in settings.passes if name.startswith(LIGHTGROUP_PREFIX)
                             and name not in dict(settings.aovs)]
        self.catchers = None  # core.integrator.shadow_catcher.Catchers, when the renderer gives one (``catch``)
        self.rays = {"camera": 0, "shadow": 0, "reflection": 0, "refraction": 0, "transparent": 0, "diffuse": 0,
                     "occlusion": 0}
        self._rays_lock = threading.Lock()

    def catch(self, scene, paths):
        """Split camera paths at the scene's shadow catchers, ``paths`` the integrator of the catchers
        alone (core.integrator.shadow_catcher); it counts its rays with this one's."""
        paths.rays, paths._rays_lock = self.rays, self._rays_lock
        held = np.array([i.holdout for i in scene.instances], bool)
        self.catchers = Catchers(np.array([i.shadow_catcher for i in scene.instances], bool), held, self.geometry,
                                 paths, CATCHER_BACKGROUND in self.settings.passes,
                                 "Env" in self.settings.passes and not scene.film_transparent)

    def _count(self, kind, n):
        with self._rays_lock:
            self.rays[kind] += int(n)

    # -- one wave ---------------------------------------------------------------------
    def trace(self, samples: Samples, sampler) -> dict:
        """Per-sample values of every pass for the camera samples of one wave."""
        s = self.settings
        state, cam = self._camera_rays(samples, sampler)
        times = self.geometry.ray_times(state.time)  # each camera sample's shutter time, down its path
        n = len(state)
        aux = {name: np.zeros((n, len(ch))) for name, ch in _AUX if name in s.passes}
        aux.update((name, np.zeros((n, len(AOV_CHANNELS[kind])))) for name, kind in s.aovs)
        aux.update((name, np.zeros((n, 3))) for name in self.group_passes)
        if self.motion_vectors is not None:
            aux["Vector"] = np.zeros((n, 5))  # the vector and its weight (core.film.film WEIGHTED_PASSES)
        slots = 2 * slot_count(s.cryptomatte_levels)
        aux.update((name, np.zeros((n, slots))) for name in self.cryptomatte)  # per path (id, weight) slots
        out = WaveOutput(np.zeros((n, 3)), np.ones(n), aux,
                         ratio=RatioEstimator(self.lights.table, self.ratio, n) if self.ratio else None)
        if self.groups is not None:
            out.grouped, out.group_names = self.groups.new(n), tuple(self.groups.names)
        if self.light_passes:
            out.split = WaveSplit(n)
        if self.catchers is not None:  # the light passes and groups a split path stops adding to
            counted = (out.grouped, None if out.split is None else out.split.split)
            out.catcher = self.catchers.new(n, tuple(sums for sums in counted if sums is not None))
        if "Depth" in out.aux:
            out.aux["Depth"][:] = _MISS_DEPTH
        if "Mist" in out.aux:
            out.aux["Mist"][:] = 1.0  # Cycles' background: nothing subtracted
        if "IndexOB" in out.aux or "IndexMA" in out.aux or self.aovs is not None or self.motion_vectors is not None:
            out.indexed = np.zeros(n, bool)
        if self.aovs is not None:
            out.aov_reach = np.ones(n)
        if "Denoising Albedo" in out.aux or "Denoising Normal" in out.aux:
            out.features = Features(n, self.camera, out.aux, s.weighted_denoising_normal)
        if not cam.valid.all():  # no ray outside a fisheye's circle: black and opaque, as Cycles leaves it
            state = state.take(np.flatnonzero(cam.valid))
        for depth in range(s.max_depth + 1):
            if len(state) == 0:
                break
            ray_times = times[state.path]
            masks = None if not self.geometry.masked else ray_masks(
                state.straight, state.bounces[:, KIND].copy(), state.dirs, state.prev_normal)
            hits = self.geometry.intersect(state.origins, state.dirs, state.tmax, ray_times, masks)
            light_t, light_id, light_le = self.lights.intersect(state.origins, state.dirs,
                                                                np.minimum(hits.t, state.tmax), state.time)
            # a light hidden from a kind of ray is not there for it: it goes on past the light
            light_id = self.lights.seen(light_id, state.straight, state.dirs, state.prev_normal, state.bounces)
            on_light = light_id >= 0
            self._lights_hit(state.take(np.flatnonzero(on_light)), light_t[on_light], light_id[on_light],
                             light_le[on_light], out)
            # a light is no surface: as in Cycles (integrate_light), rays go on past it
            self._escaped(state.take(np.flatnonzero(~hits.hit)), out)
            rows = np.flatnonzero(hits.hit)
            if len(rows) == 0:
                break
            mat = self.geometry.material_of(hits.prim[rows])
            if len(self.prepared.shaders) > 1:
                # hits ordered by material (stably): each material's hits are one slice, so its
                # arrays are views, and per path nothing changes (groups keep their order)
                order = np.argsort(mat, kind="stable")
                rows, mat = rows[order], mat[order]
            surf = self._surface(state, hits, rows, mat, ray_times)
            if out.catcher is not None:  # before the hits' light: from here on a split path's is not the matte's
                self.catchers.split(surf, out.catcher, out.radiance, out.alpha,
                                    lambda seen: self._world_seen(state.take(surf.row[seen])))
            occlusion = self._occlusion(surf, state, samples, sampler, depth)
            self._emission_seen(surf, state, hits, out, occlusion)
            if self.aovs is not None:
                self._shader_aovs(surf, hits, out, occlusion)
            if self.limited:  # paths past a glossy or transmission limit end here, with what they saw
                kept = np.flatnonzero(~ended(surf.bounces, s))
                surf, occlusion = surf.take(kept), None if occlusion is None else occlusion.take(kept)
                if len(surf) == 0:
                    break
            if state.continuation is not None:  # Russian roulette, as Cycles' integrate_surface_terminate:
                # after the emission the ray found, a path ends or its throughput is divided by its chance
                chance = state.continuation[surf.row]
                kept = np.flatnonzero(chance > 0)
                surf, occlusion = surf.take(kept), None if occlusion is None else occlusion.take(kept)
                surf.throughput = surf.throughput / chance[kept, None]
                if len(surf) == 0:
                    break
            u = self._draw(depth, samples.pixel[surf.path], samples.sample[surf.path], surf.mat, sampler,
                           depth < s.max_depth)
            bound = [(group, u.take(rows), self._blurred(shader, group, state))
                     for rows, group, shader in self._bind_materials(surf, hits, occlusion=occlusion)]
            if self.holdouts is not None:
                bound = self.holdouts.write(bound, out.alpha)
            lit = [(group, u_g) for group, u_g, shader in bound if shader.lobes] if self.lights.strategies else []
            light, start = self._sample_lights(lit) if lit else None, 0
            continued, queued = [], []
            for group, u_g, shader in bound:
                if depth == 0:  # after the holdouts, as Cycles' film_write_data_passes
                    self._first_hit_passes(group, cam, hits.t[group.row], out)
                    self._colors(group, shader, out)
                if out.features is not None:
                    out.features.surface(group, shader)
                if self.mist is not None or out.indexed is not None or self.cryptomatte:
                    self._data_passes(group, shader, out)
                if light is not None and shader.lobes:
                    # no ray leaves the last depth: its light is light sampling's alone
                    queue = self._direct(shader, group, hits, light.take(slice(start, start + len(group))), out,
                                         depth < s.max_depth, u_g.light)
                    if queue is not None:
                        queued.append(queue)
                    start += len(group)
                if (shader.can_continue or (self.diffuse and shader.lobes)) and depth < s.max_depth:
                    nxt = self._continue(shader, group, u_g, state, out.split)
                    if nxt is not None:
                        continued.append(nxt)
            if queued:
                self.shadows.resolve(ShadowRays.concat(queued), out.radiance,
                                     NO_GROUPS if out.grouped is None else out.grouped, self.timed)
            if not continued:
                break
            state = PathState.concat(continued)
        if out.catcher is not None:
            self.catchers.write(out.catcher, samples, sampler, out.radiance, out.alpha, out.aux)
        return out.values()

    # -- camera ---------------------------------------------------------------------
    def _camera_rays(self, samples: Samples, sampler):
        """The wave's camera rays as the first path state (path = row in the wave)."""
        n = len(samples.index)
        w = self.camera.window_size[0]
        x0, y0 = self.camera.window[:2]
        off = self.filter.offset(sampler.get2d(samples.pixel, samples.sample, D.PIXEL))
        px = (samples.index % w + x0) + 0.5 + off[:, 0]
        py = (samples.index // w + y0) + 0.5 + off[:, 1]
        lens = sampler.get2d(samples.pixel, samples.sample, D.LENS) if self.plan.lens else None
        # the shutter is a dimension only when something moves
        time = (camera_rays.shutter_time(self.camera, sampler.get(samples.pixel, samples.sample, D.TIME),
                                         samples.index // w + y0) if self.timed else np.zeros(n))
        cam = camera_rays.generate(self.camera, px, py, lens, time if self.timed else None)
        self._count("camera", n)
        state = PathState(path=np.arange(n), origins=cam.origins, dirs=cam.directions, tmax=cam.tmax,
                          throughput=np.ones((n, 3)), prev_pdf=np.full(n, np.inf), prev_normal=np.zeros((n, 3)),
                          prev_shading=np.zeros((n, 3)), straight=np.ones(n, bool), time=time,
                          bounces=camera_bounces(n) if self.carried else None,
                          mis_origin=cam.origins if self.shadows is not None else None,
                          min_pdf=np.full(n, np.inf) if self.min_pdf else None,
                          receiver=np.zeros(n, np.int64) if self.lights.linking else None,
                          world_pdf=np.full(n, COSINE) if self.world_drawn else None)
        return state, cam

    def _limits(self, straight: np.ndarray) -> np.ndarray:
        """The clamp limit of each contribution of paths ``straight`` or not (direct: before their
        first bounce; core.integrator.clamp.row_limits, ``UNCLAMPED`` when nothing is clamped)."""
        return row_limits(self.clamp, straight)

    def _group(self, group) -> np.ndarray | None:
        """The wave's light group columns of the emitters in the scene light groups ``group()``
        gives (None, and nothing asked of ``group``, without light groups)."""
        return None if self.groups is None else self.groups.column(group())

    # -- what rays see ----------------------------------------------------------------
    def _lights_hit(self, rays: PathState, t, light_id, le, out: WaveOutput):
        """Lights hit directly: always by reflected and refracted rays, by the camera if asked; the
        rays go on to what is behind, which alone decides the pixel's alpha."""
        if len(rays) and rays.receiver is not None:  # light linking: camera rays see every light
            keep = np.flatnonzero(rays.straight | self.lights.light_links(light_id, rays.receiver))
            rays, t, light_id, le = rays.take(keep), t[keep], light_id[keep], le[keep]
        if len(rays) and self.lights.shadow_linking:  # light sampling's alone (strategies.NO_MIS), but after a
            # delta lobe, which light sampling does not light
            keep = np.flatnonzero(rays.straight | np.isinf(rays.prev_pdf)
                                  | ~self.lights.shadow_linked(light_id=light_id))
            rays, t, light_id, le = rays.take(keep), t[keep], light_id[keep], le[keep]
        if len(rays) == 0:
            return
        le = self.lights.emitted(light_id, rays.origins, rays.dirs, t, le, rays.time, rays.bounces)

        def light_pdf(smooth):  # each ray's own light, in one call
            origins, dist = rays.mis_ray(smooth, t[smooth])
            return self.lights.pdf(light_id[smooth], origins, rays.dirs[smooth], dist, rays.time[smooth])

        e = add_emitted(out, rays.path, rays.throughput, le, rays.prev_pdf, light_pdf, self._limits(rays.straight),
                        self._group(lambda: self.lights.light_group[light_id]))
        if "Emit" in out.aux:  # lights the camera sees are in Cycles' Emit too
            out.aux["Emit"][rays.path[rays.straight]] += e[rays.straight]
        if out.split is not None:
            out.split.add_found(rays.path, e)

    def _escaped(self, rays: PathState, out: WaveOutput):
        """Escaped rays see the world (and, after a bounce, the suns); camera rays take its AOVs and,
        when the settings ask (Cycles 5.2), the background's Vector."""
        if len(rays) == 0:
            return
        lights = self.lights
        st = rays.straight
        world = self._world_seen(rays)
        if out.catcher is not None and out.catcher.background is not None:  # Cycles' Background pass
            out.catcher.background[rays.path[st]] += rays.throughput[st] * world[st]
        aovs = self.aovs is not None and self.aovs.world
        vectors = self.motion_vectors is not None and self.settings.vector_background
        if aovs or vectors:  # the camera rays whose data passes no surface took yet
            seen = np.flatnonzero(st & ~out.indexed[rays.path])
        if aovs:
            self.aovs.write_world(rays.path[seen], rays.throughput[seen], out.aux, out.aov_reach[rays.path[seen]])
        if vectors:
            out.aux["Vector"][rays.path[seen], :4] = self.motion_vectors.directions(rays.dirs[seen])
            out.aux["Vector"][rays.path[seen], 4] = 1.0
        if "Env" in out.aux:
            out.aux["Env"][rays.path[st]] += rays.throughput[st] * world[st]
        if self.film_transparent:
            out.alpha[rays.path[st]] -= rays.throughput[st].mean(axis=1)
            keep = np.flatnonzero(~st)
            rays, world = rays.take(keep), world[keep]
        if len(rays) and lights.world_seen:
            sampled = None if lights.world is None else (  # a world light sampling can find
                lambda smooth: self._world_pdf(rays, smooth))
            e = add_emitted(out, rays.path, rays.throughput, world, rays.prev_pdf, sampled,
                            self._limits(rays.straight), self._group(lambda: np.full(len(rays), lights.world_group)))
            if out.split is not None:
                out.split.add_found(rays.path, e)
        bounced = rays.take(np.flatnonzero(~rays.straight)) if len(rays) else rays
        if len(bounced):
            # with light groups, each group's suns apart (a sun's light goes to its group)
            for group in [None] if self.groups is None else np.unique(lights.light_group):
                sun, pdf_sun = lights.suns_seen(bounced.origins, bounced.dirs, bounced.time, group, bounced.receiver)
                e = add_emitted(out, bounced.path, bounced.throughput, sun, bounced.prev_pdf,
                                lambda smooth: pdf_sun[smooth], self._limits(bounced.straight),
                                None if group is None else self._group(lambda: np.full(len(bounced), group)))
                if out.split is not None:
                    out.split.add_found(bounced.path, e)

    def _world_pdf(self, rays: PathState, rows) -> np.ndarray:
        """The density light sampling has for the world along ``rays[rows]``: lights.world's, or,
        for a uniform world, the one the surface the ray left recorded (core.integrator.world_lobes)."""
        cosine = self.lights.pdf_world(rays.prev_shading[rows], rays.dirs[rows])
        if rays.world_pdf is None:
            return cosine
        recorded = rays.world_pdf[rows]
        return np.where(recorded == COSINE, cosine, recorded)

    def _world_seen(self, rays: PathState) -> np.ndarray:
        """The world's radiance along ``rays`` as they see it (its ray visibility)."""
        path = None if rays.bounces is None else RayPath(rays.straight, rays.bounces,
                                                         np.full(len(rays), BACKGROUND_LENGTH), emission=True)
        return self.lights.world_radiance(rays.dirs, rays.straight, rays.prev_normal, path)

    def _surface(self, state: PathState, hits, rows, mat, ray_times) -> SurfaceHits:
        """The surface hits ``rows`` of this depth (materials ``mat``): position, normals and a frame
        facing the ray (core.integrator.hits)."""
        return surface_records(self.geometry, hits.prim, hits.u, hits.v, ray_times, rows, state.dirs,
                               self.prepared.raises, path=state.path[rows], mat=mat,
                               throughput=state.throughput[rows],
                               straight=state.straight[rows], time=state.time[rows],
                               bounces=None if state.bounces is None else state.bounces[rows])

    def _occlusion(self, surf: SurfaceHits, state: PathState, samples: Samples, sampler,
                   depth: int) -> OcclusionRays | None:
        """The Ambient Occlusion and Bevel nodes' rays from the hits ``surf`` of this depth (None when
        no material has either node)."""
        if not self.occlusion:
            return None
        return OcclusionRays(self.geometry, sampler, samples.pixel[surf.path], samples.sample[surf.path], depth,
                             surf.pos, surf.ng, surf.scale, surf.prim, surf.time if self.timed else None, surf.ns,
                             lambda n: self._count("occlusion", n),
                             None if state.min_pdf is None else state.min_pdf[surf.row])

    def _emission_seen(self, surf: SurfaceHits, state: PathState, hits, out: WaveOutput,
                       occlusion: OcclusionRays | None = None):
        """Emission seen on surfaces (two-sided), weighted against light sampling of emissive triangles;
        ``occlusion``: the Ambient Occlusion node's rays from ``surf``."""
        glows = self.lights.glows
        glowing = np.flatnonzero(glows[surf.mat]) if len(glows) else np.zeros(0, np.int64)
        if self.holdouts is not None and len(glowing):  # an object holdout the camera sees gives no light
            glowing = glowing[~self.holdouts.whole(surf.take(glowing))]
        if state.receiver is not None and len(glowing):  # light linking: camera rays see every emitter
            seen = self.lights.triangle_links(surf.prim[glowing], state.receiver[surf.row[glowing]])
            glowing = glowing[surf.straight[glowing] | seen]
        if self.lights.shadow_linking and len(glowing):  # light sampling's alone (strategies.NO_MIS)
            glowing = glowing[surf.straight[glowing] | np.isinf(state.prev_pdf[surf.row[glowing]])
                              | ~self.lights.shadow_linked(prim=surf.prim[glowing])]
        if len(glowing) == 0:
            return
        prim = surf.prim[glowing]
        hit = surf.row[glowing]
        emission = self.lights.emission_seen(prim, hits.u[hit], hits.v[hit], surf.normal[glowing],
                                             self._ray_path(surf, hits, glowing),
                                             None if occlusion is None else occlusion.take(glowing), state.dirs[hit])

        def emissive_pdf(smooth):
            rows = hit[smooth]
            origins, dist = state.mis_ray(rows, hits.t[rows])
            return self.lights.pdf_emissive(prim[smooth], origins, state.dirs[rows], dist)

        e = add_emitted(out, surf.path[glowing], surf.throughput[glowing], emission, state.prev_pdf[hit], emissive_pdf,
                        self._limits(surf.straight[glowing]), self._group(lambda: self.lights.group_of_triangles(prim)))
        if "Emit" in out.aux:
            first = surf.straight[glowing]
            out.aux["Emit"][surf.path[glowing[first]]] += e[first]
        if out.split is not None:
            out.split.add_found(surf.path[glowing], e)

    def _first_hit_passes(self, surf: SurfaceHits, cam, t, out: WaveOutput):
        aux = out.aux
        if "Depth" in aux:
            aux["Depth"][surf.path, 0] = (cam.t_start[surf.path] + t) * cam.depth_per_t[surf.path]
        if "Normal" in aux:
            aux["Normal"][surf.path] = surf.normal
        if "Position" in aux:
            aux["Position"][surf.path] = surf.pos

    def _data_passes(self, group: SurfaceHits, shader, out: WaveOutput):
        """Mist and the index passes at the hits the camera sees directly or through transparency,
        as Cycles' film_write_data_passes: each hit takes (1 - mist) of Mist, weighted by the path's
        throughput times the hit's opacity; an index is the last such hit's until one is at least
        as opaque as the view layer's alpha threshold (the film keeps the first sample's, core.film.film);
        that hit alone writes the Vector pass, with weight 1 (core.geometry.motion_vectors). Each hit
        writes its Cryptomatte ids with Mist's weight (core.film.cryptomatte)."""
        rows = np.flatnonzero(group.straight)
        if len(rows) == 0:
            return
        path = group.path[rows]
        opacity = np.clip(1.0 - shader.transparency(group.wo_l[rows, 2], rows), 0.0, 1.0)
        seen = (group.throughput[rows] * opacity).mean(axis=1)
        if self.mist is not None:
            out.aux["Mist"][path, 0] -= (1.0 - self.mist.amount(group.pos[rows])) * seen
        if self.cryptomatte:
            instance = self.geometry.source_of(group.prim[rows])[:, 0]
            for name in self.cryptomatte:
                owner = group.mat[rows] if name == "CryptoMaterial" else instance
                write_hits(out.aux[name], path, self.cryptomatte_ids[name][owner], seen)
        if out.indexed is not None:
            open_ = ~out.indexed[path]
            rows, path = rows[open_], path[open_]
            if "IndexOB" in out.aux:
                out.aux["IndexOB"][path, 0] = self.object_index[self.geometry.source_of(group.prim[rows])[:, 0]]
            if "IndexMA" in out.aux:
                out.aux["IndexMA"][path, 0] = self.material_index[group.mat[rows]]
            if out.aov_reach is not None:
                out.aov_reach[path] *= reach_scale(shader, group, rows)
            closed = opacity[open_].mean(axis=1) >= self.settings.pass_alpha_threshold
            out.indexed[path] = closed
            if self.motion_vectors is not None and closed.any():
                rows, path = rows[closed], path[closed]
                source = self.geometry.source_of(group.prim[rows])
                out.aux["Vector"][path, :4] = self.motion_vectors.vectors(group.pos[rows], source[:, 0], source[:, 1])
                out.aux["Vector"][path, 4] = 1.0

    def _shader_aovs(self, surf: SurfaceHits, hits, out: WaveOutput, occlusion: OcclusionRays | None = None):
        """The materials' AOV Output nodes at the hits the camera sees directly or through
        transparency, before the data passes close their paths (core.integrator.aovs)."""
        rows = np.flatnonzero(surf.straight & ~out.indexed[surf.path])
        seen = surf.take(rows)
        if len(seen) == 0:
            return
        occlusion = None if occlusion is None else occlusion.take(rows)
        for g in _material_slices(seen.mat):
            group = seen.take(g)
            rays = None if occlusion is None else occlusion.take(g)
            self.aovs.write(group, lambda: self._context(group, hits, occlusion=rays), out.aux,
                            out.aov_reach[group.path])

    def _colors(self, group: SurfaceHits, shader, out: WaveOutput):
        """The diffuse, glossy and transmission colour passes of the camera's own hits."""
        aux = out.aux
        if "TransCol" in aux:
            aux["TransCol"][group.path] = shader.transmission_color(group.wo_l[:, 2])
        if "DiffCol" in aux or "GlossCol" in aux:
            diff, gloss = shader.colors(group.wo_l[:, 2])
            if "DiffCol" in aux:
                aux["DiffCol"][group.path] = diff
            if "GlossCol" in aux:
                aux["GlossCol"][group.path] = gloss

    # -- sample values of one depth step ------------------------------------------------
    def _draw(self, depth, pixel, sample, mat, sampler, bounce) -> StepSamples:
        """Every sample value the hits of one depth step use, drawn in two calls for all materials
        and strategies at once (values are per (pixel, sample, dimension), so drawing them
        together gives the very numbers drawing per material would)."""
        n = len(pixel)
        lights = self.lights
        light = np.zeros((n, lights.strategies, 2, 2))
        lit = np.flatnonzero(self.prepared.lit[mat]) if lights.strategies else np.zeros(0, np.int64)
        if len(lit):
            emissive = lights.light_slots if len(lights.emissive) else -1
            dims = np.full((lights.strategies, 2), -1, np.int64)
            for k in range(lights.strategies):
                dims[k, 0] = self.light_dims.point(depth, k)
                # a uniform world drawn from the hits' lobes (the last strategy) picks the lobe
                if k == emissive or (lights.selecting and k < lights.light_slots) or \
                        (k == lights.strategies - 1 and self.world_drawn):
                    dims[k, 1] = self.light_dims.choice(depth, k)
            whole = len(lit) >= n - n // 8  # drawing for a few hits that do not need it beats listing them
            sampler.pairs(pixel, sample, dims, None if whole else lit, light.reshape(n, -1, 2))
        path = np.zeros((n, 2, 2))
        go = np.flatnonzero(self.continues[mat]) if bounce else np.zeros(0, np.int64)
        if len(go):
            sampler.pairs(pixel, sample, [D.lobe(depth), D.lobe_choice(depth)], go, path)
            if self.roulette[0] >= 0:  # its own dimension: not correlated with the lobe choice
                path[:, 1, 1] = sampler.pairs(pixel, sample, [D.roulette(depth)], go)[:, 0, 0]
        return StepSamples(light, path)

    def _bind_materials(self, surf: SurfaceHits, hits, shadow: bool = False, occlusion: OcclusionRays | None = None):
        """(rows of ``surf``, those hits, shader) per material: a slice of the hits (sorted by
        material) for a constant material, index arrays of hits sharing one bound shader for a
        material with varying inputs (see core.shading); a program's normal replaces the shading
        normal and frame of its hits in the records it yields (raised for all but the diffuse lobes
        where wo lies below it, as the mesh's, core.integrator.hits), an anisotropic material's
        tangent the frame's tangent. ``shadow``: shadow rays reached the hits (Light Path's Is Shadow Ray);
        ``occlusion``: the Ambient Occlusion node's rays from ``surf`` (None: AO 1, as Cycles' shadow rays)."""
        for g in _material_slices(surf.mat):
            group = surf.take(g)
            shading = self.prepared.shading[surf.mat[g.start]]
            if not shading.varying:
                yield g, group, shading.shader
                continue
            rays = None if occlusion is None else occlusion.take(g)
            groups, normal, tangent, smooth = shading.bind(self._context(group, hits, shadow, rays))
            if normal is not None or tangent is not None:
                n, kept, wo = group.frame.n, group.ns, group.wo
                if normal is not None:
                    kept = np.where((vec.dot(normal, group.ng) * vec.dot(wo, group.ng) > 0)[:, None], normal, kept)
                    n = _raised_above(kept, group.ng, wo, shading.material.bump_correction)
                frame = Frame.about(n) if tangent is None else Frame.along(n, tangent)
                if smooth is not None:
                    smooth = _smooth_rows(smooth, shading.material)
                group = replace(group, frame=frame, wo_l=frame.to_local(wo), ns=kept,
                                dn=_diffuse_normal(frame, n, kept), smooth=smooth)
            for sub, shader in groups:
                taken = group.take(sub)
                if shader.coat_normal:
                    shader = _coat_turned(shader, taken, shading.material.bump_correction)
                if shader.hair:
                    shader = _hair_turned(shader, taken)
                yield g.start + sub, taken, shader

    def _context(self, group: SurfaceHits, hits, shadow: bool = False,
                 occlusion: OcclusionRays | None = None) -> SurfaceContext:
        """The hits ``group`` as shader programs read them (core.shading.surface); ``shadow``:
        shadow rays reached them; ``occlusion``: their Ambient Occlusion rays."""
        hu, hv = hits.u[group.row], hits.v[group.row]
        bary = np.stack([1.0 - hu - hv, hu, hv], axis=1)
        width = self.pixel_spread[0] + self.pixel_spread[1] * hits.t[group.row]
        return SurfaceContext(self.prepared.attributes, group.prim, bary, group.pos, group.ns, width, -group.wo,
                              self._ray_path(group, hits, shadow=shadow), occlusion)

    @staticmethod
    def _ray_path(group: SurfaceHits, hits, rows=slice(None), shadow=False) -> RayPath | None:
        """The rays that reached hits ``rows`` of ``group``, for Light Path (None when no program reads it)."""
        if group.bounces is None:
            return None
        return RayPath(group.straight[rows], group.bounces[rows], hits.t[group.row[rows]], shadow=shadow)

    def _blurred(self, shader, group: SurfaceHits, state: PathState):
        """The shader of hits ``group`` with its glossy lobes blurred as Filter Glossy asks after their
        paths' bounces (core.bsdf.blur); itself where nothing is blurred."""
        if state.min_pdf is None or not shader.blurs:
            return shader
        roughness = blur_roughness(state.min_pdf[group.row], self.filter_glossy)
        return shader.blurred(roughness) if roughness.any() else shader

    # -- next-event estimation ----------------------------------------------------------
    def _sample_lights(self, lit) -> LightSamples:
        """Every light strategy sampled at the hits of one depth step that have lobes (``lit``:
        (hits, their samples) per shader), for all shaders at once and in their order; the
        world around each hit's shading normal (a normal program's where there is one)."""
        def joined(arrays):
            return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)

        hits = [group for group, _ in lit]
        out = self.lights.sample_all(joined([h.pos for h in hits]), joined([h.ns for h in hits]),
                                     joined([u.light for _, u in lit]),
                                     joined([h.time for h in hits]) if self.timed else None,
                                     joined([h.bounces for h in hits]) if self.light_path else None,
                                     groups=self.groups is not None,
                                     receivers=self.lights.receivers(joined([h.prim for h in hits]))
                                     if self.lights.linking else None)
        if self.groups is not None:
            out.group = self.groups.column(out.group)
        return out

    def _direct(self, shader, group: SurfaceHits, hits, light: LightSamples, wave: WaveOutput, continues: bool,
                u_light: np.ndarray):
        """Direct light at the hits of one shader, every strategy's shadow ray traced in the
        kernel (core.integrator.direct), weighed against the rays these hits may continue
        through (the diffuse lobes' within the diffuse bounces), where any ``continues``, a
        uniform world's sample drawn from their diffuse-type lobes there (``u_light``, their light
        sample values; core.integrator.world_lobes);
        what the wave's ratio estimator needs, when there is one, shown to it after
        (core.integrator.ratio). Returns the shadow rays stopped on see-through surfaces (None:
        none, core.integrator.shadows)."""
        n = len(group)
        keep = 0 if wave.ratio is None else n
        f_diff, visibility = np.zeros((light.strategies, keep, 3)), np.zeros((light.strategies, keep), np.int8)
        cuts = np.ones((light.strategies, keep if self.clamping else 0))  # the ratio estimator's, under a clamp
        # the terminator lift is for diffuse shading over coarse facets (measured on Ignis'
        # rough-glass cylinder, lifting glass as well doubled its highlights' noise)
        lifted = len(self.geometry.tables[3]) > 0 and any(lobe.diffuse for lobe in shader.lobes)
        geo = self.geometry
        shadows = self.shadows is not None
        qf, qi = new_queue(n * light.strategies, shadows)
        clear = self.shadows.clear if shadows else _NOTHING_CLEAR
        allowed = limits(group.bounces, self.settings.max_transparent_bounces) if shadows else _NO_LIMITS
        if continues and self.world_drawn and draws_from(shader):
            self._world_from_lobes(shader, group, light, u_light)
        traced, m = direct_light(
            shader.lp, shader.lt, shader.hp, shader.hit_rows(n), shader.mu, len(shader.sampled), _c(group.pos),
            _c(group.ng), _c(group.frame.m), _smooth(group), _c(group.dn), _c(group.wo_l), _c(group.inside),
            _c(group.scale),
            _c(group.throughput),
            _c(group.path), row_limits(self.clamp, group.straight),
            _NO_BOUNCES if group.bounces is None else _c(group.bounces),
            self.diffuse if continues else 0, continues, geo.tables,
            group.prim, hits.u[group.row], hits.v[group.row], lifted, *light.arrays(),
            geo.handle, geo.center, geo.shadow_mask, geo.time_values(group.time if self.timed else None),
            wave.radiance, NO_GROUPS if wave.grouped is None else wave.grouped,
            *((NO_SPLIT, NO_WEIGHTS, NO_BOUNCES) if wave.split is None else wave.split.arrays()),
            f_diff, visibility, cuts, clear, allowed, qf, qi)
        self._count("shadow", traced)
        if wave.ratio is not None:
            wave.ratio.direct(shader, group, light.value, f_diff, visibility, cuts)
        return stopped(qf, qi, m, group.bounces)

    def _world_from_lobes(self, shader, group: SurfaceHits, light: LightSamples, u_light: np.ndarray) -> None:
        """The uniform world's samples (the last strategy) of ``light`` drawn again from the hits'
        diffuse-type lobes (core.integrator.world_lobes), in place: the ratio estimator reads them
        too. The kernel takes contiguous copies, whatever views ``light`` holds (one specialization)."""
        k = light.strategies - 1
        wi, value, pdf = (np.ascontiguousarray(a[k]) for a in (light.wi, light.value, light.pdf))
        world_from_lobes(shader.lp, shader.lt, shader.hp, shader.hit_rows(len(group)), shader.mu, _c(group.frame.m),
                         _smooth(group), _c(group.dn), _c(group.wo_l), _c(group.inside), _c(u_light), k,
                         np.asarray(self.lights.world, np.float64), wi, value, pdf)
        light.wi[k], light.value[k], light.pdf[k] = wi, value, pdf

    # -- continuation through one lobe -------------------------------------------------
    def _continue(self, shader, hits: SurfaceHits, u: StepSamples, state: PathState,
                  split: WaveSplit | None = None) -> PathState | None:
        """The paths of these hits (rows ``hits.row`` of ``state``) continued through one sampled
        lobe (None if none goes on; core.integrator.continuation); with light passes (``split``),
        the paths' weights set at their first bounce and their bounces counted."""
        n = len(hits)
        go, passthrough, transmit, diffuse = np.empty(n, bool), np.empty(n, bool), np.empty(n, bool), np.empty(n, bool)
        origin, wi, weight, prev_pdf, chance = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty(n), \
            np.empty(n)
        bounces = _NO_BOUNCES if hits.bounces is None else _c(hits.bounces)
        next_bounces = np.empty_like(bounces)
        first = np.zeros(0, bool) if split is None else split.bounces[hits.path] == 0
        shares = np.empty((n if split is not None else 0, 6, 3))
        drawn = state.world_pdf is not None and draws_from(shader)  # else the cosine's, COSINE
        world_pdf = np.empty(n if drawn else 0)
        continue_paths(shader.lp, shader.lt, shader.hp, shader.hit_rows(n), shader.mu, len(shader.sampled),
                       _c(hits.frame.m), _smooth(hits), _c(hits.dn),
                       _c(hits.wo_l), _c(hits.inside), _c(u.lobe_choice), _c(u.lobe), _c(hits.throughput),
                       _c(hits.pos), _c(hits.ng), _c(hits.scale), bounces, self.diffuse, _c(u.roulette),
                       self.roulette, go, origin, wi, weight, prev_pdf, passthrough, transmit, next_bounces, diffuse,
                       first, shares, chance, world_pdf)
        sel = np.flatnonzero(go)
        if len(sel) == 0:
            return None
        passthrough, transmit, diffuse = passthrough[sel], transmit[sel], diffuse[sel]
        if split is not None:  # a bounce (not a pass-through) counts; the first sets the weights
            bounced = sel[~passthrough]
            set_now = bounced[first[bounced]]
            split.weights[hits.path[set_now]] = shares[set_now]
            split.bounces[hits.path[bounced]] += 1
        self._count("diffuse", diffuse.sum())
        self._count("refraction", (transmit & ~passthrough & ~diffuse).sum())
        self._count("reflection", (~transmit & ~diffuse).sum())
        self._count("transparent", passthrough.sum())
        prev_pdf, prev_normal, prev_shading, origin = prev_pdf[sel], hits.ng[sel], hits.ns[sel], origin[sel]
        world_pdf = None if state.world_pdf is None else world_pdf[sel] if drawn else np.full(len(sel), COSINE)
        mis_origin = None
        if state.mis_origin is not None:  # transparent shadows: a pass-through keeps the MIS state
            kept, rows = passthrough[:, None], hits.row[sel]
            prev_pdf = np.where(passthrough, state.prev_pdf[rows], prev_pdf)
            if world_pdf is not None:
                world_pdf = np.where(passthrough, state.world_pdf[rows], world_pdf)
            prev_normal = np.where(kept, state.prev_normal[rows], prev_normal)
            prev_shading = np.where(kept, state.prev_shading[rows], prev_shading)
            mis_origin = np.where(kept, state.mis_origin[rows], origin)
        receiver = None
        if state.receiver is not None:  # light linking: the object bounced off, kept through pass-throughs
            receiver = np.where(passthrough, state.receiver[hits.row[sel]], self.lights.receivers(hits.prim[sel]))
        min_pdf = None
        if state.min_pdf is not None:  # Cycles' min_ray_pdf: the least density of non-transparent bounces
            before = state.min_pdf[hits.row[sel]]
            min_pdf = np.where(passthrough, before, np.minimum(before, prev_pdf))
        return PathState(path=hits.path[sel], origins=origin, dirs=wi[sel], tmax=np.full(len(sel), np.inf),
                         throughput=weight[sel], prev_pdf=prev_pdf, prev_normal=prev_normal,
                         prev_shading=prev_shading, straight=hits.straight[sel] & passthrough, time=hits.time[sel],
                         bounces=None if hits.bounces is None else next_bounces[sel], mis_origin=mis_origin,
                         min_pdf=min_pdf, receiver=receiver,
                         continuation=chance[sel] if self.roulette[0] >= 0 else None, world_pdf=world_pdf)


def _material_slices(mat):
    """The slices of hits sorted by material (``mat``) that share one material."""
    starts = np.concatenate([[0], np.flatnonzero(np.diff(mat)) + 1])
    return [slice(int(a), int(b)) for a, b in zip(starts, np.append(starts[1:], len(mat)))]


def _c(a):
    return np.ascontiguousarray(a)


def _smooth_rows(smooth, material) -> np.ndarray:
    """The kernels' rows of a bumped material's hits: the smooth normal and its model's code."""
    code = model_code(material.bump_shadowing, material.bump_correction)
    return np.concatenate([smooth, np.full((len(smooth), 1), float(code))], axis=1)


def _smooth(hits) -> np.ndarray:
    """The smooth normals of ``hits`` whose shading normal a bump replaced, for the kernels."""
    return _NO_BUMP if hits.smooth is None else _c(hits.smooth)


def _raised_above(ns, ng, wo, raises: bool):
    """Program normals ``ns`` raised as Cycles raises a specular closure's where wo's mirror image
    would leave below the surface (ensure_valid_specular_reflection, about ``ng`` facing wo), the
    geometric normal where wo is still below: the frame's normal, for the glossy, glass and coat
    lobes (the diffuse lobes keep ``ns``: Cycles keeps a diffuse closure's bumped normal facing away
    from the viewer; raising it for them lit the rim of a bumped sphere 0.12 brighter than Cycles
    in its worst block). ``ns`` as it is where the material does not ``raise`` (its Bump Map
    Correction off: core.integrator.hits)."""
    if not raises:
        return ns
    ns = valid_specular_reflection(ng, wo, ns)
    return np.where((vec.dot(wo, ns) <= 1e-6)[:, None], ng, ns)


def _diffuse_normal(frame: Frame, n, kept) -> np.ndarray:
    """The diffuse lobes' normal ``kept`` in ``frame`` (about ``n``): (0, 0, 1) exactly where it is ``n``
    (core.bsdf.diffuse_normal)."""
    dn = np.zeros_like(kept)
    dn[:, 2] = 1.0
    own = np.flatnonzero(np.any(kept != n, axis=1))
    if len(own):
        dn[own] = frame[own].to_local(kept[own])
    return dn


def _hair_turned(shader, hits: SurfaceHits):
    """The bound shader with its hair lobes' frames at each hit (MaterialShader.turn_hair): the
    geometric normal turned toward wo, as Cycles' sd->Ng on a back face, and the mesh's shading normal."""
    ng = np.where((vec.dot(hits.wo, hits.ng) < 0)[:, None], -hits.ng, hits.ng)
    frame = hits.frame
    return shader.turn_hair(frame.to_local, frame.to_local(ng), frame.to_local(hits.ns), hits.wo_l)


def _coat_turned(shader, hits: SurfaceHits, raises: bool):
    """The bound shader with its coat normal (world, from the material's program) in each hit's
    shading frame: unit (Cycles' safe_normalize_fallback to the frame's normal) and, where the material
    ``raises`` (Bump Map Correction on), raised toward the geometric normal until wo's mirror image
    leaves above the surface (Cycles' coat takes its normal through maybe_ensure_valid_specular_reflection;
    it may start below the surface), the frame's normal where wo is still not above it. Unraised, the
    coat reflects nothing where wo is below its normal (core.bsdf.reflection.own_reflect_eval)."""
    n = hits.frame.n
    nc = shader.coat_normals()
    length = vec.norm(nc)
    nc = np.where((length > 1e-20)[:, None], nc / np.maximum(length, 1e-20)[:, None], n)
    if raises:
        ng = np.where((vec.dot(hits.wo, hits.ng) < 0)[:, None], -hits.ng, hits.ng)
        nc = valid_specular_reflection(ng, hits.wo, nc)
        nc = np.where((vec.dot(hits.wo, nc) <= 1e-6)[:, None], n, nc)
    return shader.turn_coat(hits.frame.to_local(nc), hits.wo_l)
