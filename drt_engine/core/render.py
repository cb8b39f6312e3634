"""The distribution ray tracing loop over wavefronts.

A wave is a batch of camera samples (pixel, sample id). Each depth step intersects
all live rays at once, adds what they see (emission, lights, world, each weighted
by multiple importance sampling against light sampling), estimates direct light at
every hit with one shadow ray per light strategy, and continues each path through
one non-diffuse lobe (mirror, glossy, glass, transparent) chosen by its albedo.
Every random number is drawn from ``Sampler`` with the camera sample's own id.
"""
from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from . import adaptive
from . import camera as camera_rays
from . import microfacet as mf
from .accel import Geometry, spawn
from .errors import SceneError
from .film import Film, PixelFilter
from .lights import Lights
from .plan import make_plan
from .report import ErrorLog
from .sampling import Sampler
from .scene import SceneData
from .settings import RenderSettings
from .shading import MaterialShading, SurfaceAttributes, SurfaceContext, load_textures
from .validate import validate_scene

WAVE = 1 << 16  # camera samples per wave: bounds memory whatever the resolution
_MIN_PIECE = 1 << 12  # fewest camera samples in one thread's piece of a wave (smaller waves stay whole)
_FIRST_TIMED_WAVE = 1 << 12  # under a time limit, the wave that measures the rate
_TINY = 1e-30
_MISS_DEPTH = 1e10  # Blender's depth for the background


@dataclass
class RenderResult:
    passes: dict
    stats: dict
    cancelled: bool = False
    warnings: list = field(default_factory=list)
    log: list = field(default_factory=list)  # report.ErrorLog entries, one per step


@dataclass
class ProgressUpdate:
    fraction: float
    samples_done: int
    samples_total: int
    elapsed: float
    _film: Film
    error: float = float("inf")  # latest estimated relMSE of the image (inf until known)
    entry: dict | None = None  # the log entry when a step just ended, else None

    def passes(self) -> dict:
        return self._film.images()


def _wave_size(time_limit: float, elapsed: float, traced: int) -> int:
    """Samples in the next wave: WAVE, or under a time limit what fits in the time left.

    The rate so far (every cost included) predicts the time a wave takes, so the render
    ends close to the limit instead of up to a whole wave after it.
    """
    if time_limit <= 0:
        return WAVE
    if traced == 0 or elapsed <= 0:
        return _FIRST_TIMED_WAVE
    fits = int(traced / elapsed * (time_limit - elapsed))
    return min(WAVE, max(_FIRST_TIMED_WAVE // 4, fits))


def _power(a, b):
    """Power heuristic weight of strategy a against b (densities per solid angle)."""
    a2 = np.where(np.isinf(a), 1.0, a * a)
    b2 = np.where(np.isinf(a), 0.0, b * b)
    return a2 / np.maximum(a2 + b2, _TINY)


class _Dims:
    """Sample dimensions of a path: pixel, lens, shutter time, then a stride per depth step."""

    PIXEL, LENS, TIME = 0, 2, 4
    _FIRST = 6

    def __init__(self, strategies: int):
        self.stride = 4 + 4 * strategies

    def lobe(self, depth):
        return self._FIRST + depth * self.stride

    def pick(self, depth):
        return self._FIRST + depth * self.stride + 2

    def light(self, depth, k):
        return self._FIRST + depth * self.stride + 4 + 4 * k

    def choice(self, depth, k):
        """Which light strategy k picks, when lights are chosen by contribution."""
        return self.light(depth, k) + 2


class Renderer:
    """Renders one SceneData with one RenderSettings."""

    def __init__(self, scene: SceneData, settings: RenderSettings):
        if scene.camera is None:
            raise SceneError("the scene has no camera")
        validate_scene(scene)
        self.scene = scene
        self.settings = settings
        threads = settings.threads if settings.threads > 0 else (os.cpu_count() or 1)
        self.threads = threads
        self.pool = ThreadPoolExecutor(threads) if threads > 1 else None
        self.camera = scene.camera
        self.geometry = Geometry(scene, self.camera.matrix[:3, 3])
        for i, mesh in enumerate(scene.meshes):
            if len(mesh.material_indices) and (mesh.material_indices.max() >= len(scene.materials)
                                               or mesh.material_indices.min() < 0):
                raise SceneError(f"mesh {mesh.name!r} refers to a material that does not exist")
        self.warnings = list(scene.warnings) + self.geometry.warnings
        textures = load_textures(scene, self.warnings)
        self.shading = [MaterialShading(m, textures, self.warnings) for m in scene.materials]
        self.shaders = [sh.shader for sh in self.shading]
        # casts shadow rays, continues (a material with varying inputs may, whatever its fallback)
        self._lit = np.array([bool(sh.lobes) or m.varying for sh, m in zip(self.shaders, self.shading)] + [False])
        self._continues = np.array([sh.can_continue or m.varying for sh, m in zip(self.shaders, self.shading)]
                                   + [False])
        self.attributes = SurfaceAttributes(scene, self.geometry) if any(s.varying for s in self.shading) else None
        self.pixel_spread = camera_rays.pixel_spread(self.camera)
        self.lights = Lights(scene, self.geometry, self.shading, textures)
        self.sampler = Sampler(settings.sampling_pattern, settings.samples, settings.seed)
        self.filter = PixelFilter(settings.filter_type, settings.filter_size)
        self.dims = _Dims(self.lights.strategies)
        # per triangle: emission seen when hit (constant, or from a texture)
        self._glows = (mf.max3(self.lights.tri_emission) > 0) | np.isin(self.geometry.material, self.lights.textured)
        self.plan = make_plan(scene, settings, self.geometry, self.lights, self.shaders)
        self.timed = self.plan.time
        w, h = self.camera.window_size
        contrast = settings.use_adaptive_sampling and settings.adaptive_mode == "CONTRAST"
        self.film = Film(w, h, settings.passes, track_range=contrast)
        self.rays = {"camera": 0, "shadow": 0, "reflection": 0, "refraction": 0, "transparent": 0}
        self._rays_lock = threading.Lock()

    # -- driver ---------------------------------------------------------------------
    def render(self, progress=None) -> RenderResult:
        """Trace rounds of samples up to each checkpoint, then log, test and apply the stop rules.

        Sample k of a pixel comes from replicate k % 2 (see adaptive.replicate_samplers),
        so the film's two halves are independent estimates and its error estimate holds.

        Only active pixels are traced: a round gives every active pixel the samples it
        lacks to reach the next checkpoint (after NOISE's first test: its share of a round
        that grows with the render, adaptive.allocate), sample after sample over the
        active pixels (so a round cut short leaves an even image), in waves of at most WAVE. Each
        pixel draws sample ids 0, 1, 2, ... in order, so its sequence stays stratified.
        """
        start = time.perf_counter()
        log = ErrorLog()
        s = self.settings
        w, h = self.camera.window_size
        x0, y0, _, _ = self.camera.window
        n_pix = w * h
        cap = self.sampler.samples
        threshold = adaptive.effective_threshold(s.adaptive_threshold, cap)
        first = adaptive.first_test(adaptive.min_samples(s.adaptive_min_samples, cap))
        points = adaptive.checkpoints(cap, first if s.use_adaptive_sampling else cap)
        replicas = adaptive.replicate_samplers(s.sampling_pattern, cap, s.seed)
        main_sampler = self.sampler
        active = np.arange(n_pix)
        planned = float(n_pix) * cap
        traced = 0
        stopped = None

        def trace(pixel, sample):
            if replicas is None:
                self._trace(pixel, sample, x0, y0, w)
                return
            for r, sampler in enumerate(replicas):
                sel = (sample & 1) == r
                if sel.any():
                    self.sampler, self.film.replicate = sampler, r
                    self._trace(pixel[sel], sample[sel] >> 1, x0, y0, w)
            self.sampler, self.film.replicate = main_sampler, None

        def notify(done, entry=None) -> bool:
            elapsed = time.perf_counter() - start
            fraction = traced / planned if planned else 1.0
            if s.time_limit > 0:
                fraction = max(fraction, elapsed / s.time_limit)
            last = log.last
            error = last["relmse"] if last else float("inf")
            update = ProgressUpdate(min(fraction, 1.0), done, cap, elapsed, self.film, error, entry)
            return progress is None or progress(update) is not False

        target = 0
        allocating = False
        unconverged = 1.0  # fraction of the pixels the last test left unconverged
        try:
            while True:
                base = _counts(self.film.count, active)
                if allocating:
                    budget = max(adaptive.MIN_ROUND, int(adaptive.ROUND_GROWTH * traced))
                    need = adaptive.allocate(self.film, active, budget, cap)
                    target = int((base + need).max())
                else:
                    target = adaptive.next_checkpoint(points, target, len(active), first)
                    need = target - base
                keep = need > 0
                pix, base, need = (active, base, need) if keep.all() else (active[keep], base[keep], need[keep])
                left = int(need.sum(dtype=np.int64))
                for wave_pix, wave_sample in _waves(pix, base, need):
                    a = 0
                    while a < len(wave_pix):  # one piece, or under a time limit what fits in the time left
                        size = _wave_size(s.time_limit, time.perf_counter() - start, traced)
                        trace(wave_pix[a:a + size], wave_sample[a:a + size])
                        count = len(wave_pix[a:a + size])
                        a, traced, left = a + size, traced + count, left - count
                        if s.time_limit > 0 and time.perf_counter() - start >= s.time_limit:
                            stopped = "time_limit"
                            break
                        if left > 0 and not notify(target - 1):
                            stopped = "cancelled"
                            break
                    if stopped:
                        break
                if stopped:
                    break
                if s.use_adaptive_sampling and target >= first and (allocating or target < cap):
                    mask = adaptive.still_active(self.film, s.adaptive_mode, threshold)
                    unconverged = float(mask.mean())
                    active = np.flatnonzero(mask & (self.film.count < cap))
                    allocating = s.adaptive_mode == "NOISE"
                entry = log.record(time.perf_counter() - start, self.film, self.rays, unconverged)
                if self.film.count.min() >= cap if allocating else target == cap:
                    stopped = "samples"
                elif len(active) == 0:
                    stopped = "threshold"
                elif s.target_error > 0 and self.film.count.min() >= 4 and entry["relmse"] < s.target_error:
                    stopped = "target_error"
                elif s.time_limit > 0 and entry["elapsed"] >= s.time_limit:
                    stopped = "time_limit"
                if not notify(target, entry) and not stopped:
                    stopped = "cancelled"
                if stopped:
                    entry["stopped"] = stopped
                    break
            if stopped in ("time_limit", "cancelled") and (not log.last or "stopped" not in log.last):
                log.record(time.perf_counter() - start, self.film, self.rays, unconverged, stopped)
        finally:
            if self.pool is not None:
                self.pool.shutdown(wait=True)
        elapsed = time.perf_counter() - start
        last = log.last or {}
        stats = {"samples": int(self.film.count.max()) if n_pix else 0, "samples_requested": cap,
                 "samples_mean": float(self.film.count.mean()) if n_pix else 0.0,
                 "elapsed": elapsed, "cpu": log.cpu(), "rays": dict(self.rays), "threads": self.threads,
                 "triangles": self.geometry.triangle_count, "light_strategies": self.lights.strategies,
                 "stopped_by": stopped or "samples", "rmse": last.get("rmse"), "relmse": last.get("relmse"),
                 "adaptive_threshold": threshold if s.use_adaptive_sampling else None,
                 "adaptive_first_test": first if s.use_adaptive_sampling else None,
                 "plan": self.plan.as_dict(), "plan_summary": self.plan.summary()}
        return RenderResult(self.film.images(), stats, stopped == "cancelled", self.warnings, log.entries)

    # -- one wave of camera samples ---------------------------------------------------
    def _trace(self, pixel, sample, x0, y0, w):
        """Trace a wave, split into one contiguous piece per thread, and add it to the film.

        Every path depends only on its own (pixel, sample) and Embree answers each ray alone,
        so the pieces give the values one piece would, and the film receives them in the
        same order in one call: the image is bit-identical for any thread count. Each piece
        runs the whole loop (NumPy releases the GIL in its array loops, Embree in its calls).
        """
        n = len(pixel)
        pieces = min(self.threads, max(1, n // _MIN_PIECE))
        if pieces == 1:
            values = self._shade(pixel, sample, x0, y0, w)
        else:
            bounds = np.linspace(0, n, pieces + 1).astype(np.int64)
            jobs = [self.pool.submit(self._shade, pixel[a:b], sample[a:b], x0, y0, w)
                    for a, b in zip(bounds[:-1], bounds[1:])]
            parts = [job.result() for job in jobs]
            values = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
        self.film.add(pixel, values, sample)

    def _count(self, kind, n):
        with self._rays_lock:
            self.rays[kind] += int(n)

    def _shade(self, pixel, sample, x0, y0, w):
        """Per-sample values of every pass for camera samples (pixel, sample)."""
        s = self.settings
        passes = set(s.passes)
        n = len(pixel)
        seed_pixel = (pixel % w + x0) + (pixel // w + y0) * self.camera.resolution[0]  # stable across windows
        seed_pixel = seed_pixel.astype(np.uint32)
        off = self.filter.offset(self.sampler.get2d(seed_pixel, sample, _Dims.PIXEL))
        px = (pixel % w + x0) + 0.5 + off[:, 0]
        py = (pixel // w + y0) + 0.5 + off[:, 1]
        lens = self.sampler.get2d(seed_pixel, sample, _Dims.LENS) if self.plan.lens else None
        # the shutter is a dimension only when something moves
        time = self.sampler.get(seed_pixel, sample, _Dims.TIME) if self.timed else np.zeros(n)
        cam = camera_rays.generate(self.camera, px, py, lens, time if self.timed else None)
        times = self.geometry.ray_times(time)  # moving parts' transforms, once per camera sample
        self._count("camera", n)

        radiance = np.zeros((n, 3))
        alpha = np.ones(n)
        aux = {name: np.zeros((n, len(ch))) for name, ch in
               (("Depth", "Z"), ("Normal", "XYZ"), ("Position", "XYZ"), ("DiffCol", "RGB"),
                ("GlossCol", "RGB"), ("Emit", "RGB"), ("Env", "RGB")) if name in passes}
        if "Depth" in aux:
            aux["Depth"][:] = _MISS_DEPTH

        # live path state, indexed by path id
        path = np.arange(n)
        origins, dirs, tmax = cam.origins, cam.directions, cam.tmax
        throughput = np.ones((n, 3))
        prev_pdf = np.full(n, np.inf)  # solid-angle pdf of the last continuation (inf: delta/camera)
        prev_normal = np.zeros((n, 3))
        straight = np.ones(n, bool)  # seen only through transparent surfaces from the camera

        for depth in range(s.max_depth + 1):
            if len(path) == 0:
                break
            ray_time = time[path]
            ray_times = times[path]
            hits = self.geometry.intersect(origins, dirs, tmax, ray_times)
            light_t, light_id, light_le = self.lights.intersect(origins, dirs, np.minimum(hits.t, tmax), ray_time)
            # a light hidden from the camera is not there for camera rays: they go on past it
            hidden = straight[path] & ~self.lights.camera_visible[np.maximum(light_id, 0)]
            light_id = np.where(hidden, -1, light_id)
            on_light = light_id >= 0
            on_surface = hits.hit & ~on_light
            escaped = ~hits.hit & ~on_light

            # lights hit directly: always by reflected and refracted rays, by the camera if asked
            idx = np.flatnonzero(on_light)
            if len(idx):
                contrib = light_le[idx].copy()
                smooth = ~np.isinf(prev_pdf[idx])
                if smooth.any():
                    k = idx[smooth]
                    pl = np.zeros(len(k))
                    for li in np.unique(light_id[k]):
                        sel = light_id[k] == li
                        pl[sel] = self.lights.pdf(li, origins[k[sel]], dirs[k[sel]], light_t[k[sel]],
                                                  ray_time[k[sel]])
                    contrib[smooth] *= _power(prev_pdf[k], pl)[:, None]
                radiance[path[idx]] += throughput[idx] * contrib
                if self.scene.film_transparent:
                    direct = straight[path[idx]]
                    alpha[path[idx[direct]]] -= throughput[idx[direct]].mean(axis=1)

            # escaped rays see the world
            idx = np.flatnonzero(escaped)
            if len(idx):
                st = straight[path[idx]]
                world = self.lights.world_radiance(dirs[idx], st, prev_normal[idx])
                if "Env" in aux:
                    aux["Env"][path[idx[st]]] += throughput[idx[st]] * world[st]
                if self.scene.film_transparent:
                    alpha[path[idx[st]]] -= throughput[idx[st]].mean(axis=1)
                    idx, world = idx[~st], world[~st]
                if len(idx) and self.lights.world_seen:
                    weight = np.ones(len(idx))
                    smooth = ~np.isinf(prev_pdf[idx])
                    if smooth.any() and self.lights.world is not None:
                        k = idx[smooth]
                        weight[smooth] = _power(prev_pdf[k], self.lights.pdf_world(prev_normal[k], dirs[k]))
                    radiance[path[idx]] += throughput[idx] * world * weight[:, None]
                bounced = idx[~straight[path[idx]]] if len(idx) else idx
                if len(bounced):
                    sun, pdf_sun = self.lights.suns_seen(origins[bounced], dirs[bounced], ray_time[bounced])
                    weight = np.where(np.isinf(prev_pdf[bounced]), 1.0, _power(prev_pdf[bounced], pdf_sun))
                    radiance[path[bounced]] += throughput[bounced] * sun * weight[:, None]

            surf = np.flatnonzero(on_surface)
            if len(surf) == 0:
                break
            if len(self.shaders) > 1:
                # hits ordered by material (stably): each material's hits are one slice, so its
                # arrays are views, and per path nothing changes (groups keep their order)
                surf = surf[np.argsort(self.geometry.material[hits.prim[surf]], kind="stable")]
            p_ids = path[surf]
            pos, ng, ns = self.geometry.surface(hits, surf, ray_times)
            prim = hits.prim[surf]
            mat = self.geometry.material[prim]
            wo = -dirs[surf]

            # emission seen (two-sided), weighted against light sampling of emissive triangles
            glowing = np.flatnonzero(self._glows[prim]) if len(self._glows) else np.zeros(0, np.int64)
            if len(glowing):
                emission = self.lights.emission_seen(prim[glowing], hits.u[surf[glowing]], hits.v[surf[glowing]])
                weight = np.ones(len(glowing))
                k = surf[glowing]
                smooth = ~np.isinf(prev_pdf[k])
                if smooth.any():
                    pl = self.lights.pdf_emissive(prim[glowing[smooth]], dirs[k[smooth]], hits.t[k[smooth]])
                    weight[smooth] = _power(prev_pdf[k[smooth]], pl)
                e = throughput[k] * emission * weight[:, None]
                radiance[p_ids[glowing]] += e
                if "Emit" in aux:
                    first = straight[p_ids[glowing]]
                    aux["Emit"][p_ids[glowing[first]]] += e[first]

            # orient the frame toward the incoming ray
            inside = mf.dot(wo, ng) < 0
            flip = np.where(inside, -1.0, 1.0)[:, None]
            ng_o = ng * flip
            ns_o = ns * flip
            bad = mf.dot(wo, ns_o) <= 1e-6
            ns_o[bad] = ng_o[bad]
            tangent, bitangent = _frame(ns_o)
            wo_l = _to_local(wo, tangent, bitangent, ns_o)

            first_hit = np.full(len(surf), depth == 0)
            if depth == 0:
                if "Depth" in aux:
                    aux["Depth"][p_ids, 0] = (cam.t_start[p_ids] + hits.t[surf]) * cam.depth_per_t[p_ids]
                if "Normal" in aux:
                    aux["Normal"][p_ids] = ns
                if "Position" in aux:
                    aux["Position"][p_ids] = pos

            scale = self.geometry.offset_scale(prim, pos)
            u = self._draw(depth, seed_pixel[p_ids], sample[p_ids], mat, depth < s.max_depth)
            thr_s, straight_s = throughput[surf], straight[p_ids]

            def lift(g):  # the terminator lift of hits g, worked out only for materials that use it
                return self.geometry.smooth_offset(hits, surf[g], ray_times)

            next_state = []
            shadow = []
            for g, shader in self._bind_materials(mat, prim, hits, surf, pos, ng_o, ns_o, tangent, bitangent,
                                                  wo_l, wo, dirs[surf]):
                if ("DiffCol" in aux or "GlossCol" in aux) and first_hit[g].any():
                    fg = _at(g, np.flatnonzero(first_hit[g]))
                    diff, gloss = shader.colors(wo_l[fg, 2])
                    if "DiffCol" in aux:
                        aux["DiffCol"][p_ids[fg]] = diff
                    if "GlossCol" in aux:
                        aux["GlossCol"][p_ids[fg]] = gloss
                shadow.append(self._direct(shader, g, u, p_ids, pos, ng_o, ns_o,
                                           tangent, bitangent, wo_l, inside, scale, thr_s, time, lift))
                if shader.can_continue and depth < s.max_depth:
                    next_state.append(self._continue(shader, g, u, p_ids, pos, ng_o,
                                                     ns_o, tangent, bitangent, wo_l, inside, scale,
                                                     thr_s, straight_s))
            self._resolve_shadows(shadow, radiance, times)

            if not next_state:
                break
            path = np.concatenate([st[0] for st in next_state])
            origins = np.concatenate([st[1] for st in next_state])
            dirs = np.concatenate([st[2] for st in next_state])
            throughput = np.concatenate([st[3] for st in next_state])
            prev_pdf = np.concatenate([st[4] for st in next_state])
            prev_normal = np.concatenate([st[5] for st in next_state])
            straight = np.zeros(n, bool)
            straight[path] = np.concatenate([st[6] for st in next_state])
            tmax = np.full(len(path), np.inf)

        if s.clamp > 0:
            peak = mf.max3(radiance)
            radiance *= np.where(peak > s.clamp, s.clamp / np.maximum(peak, _TINY), 1.0)[:, None]
        radiance = np.where(np.isfinite(radiance), radiance, 0.0)
        values = {"Combined": np.concatenate([radiance, np.clip(alpha, 0.0, 1.0)[:, None]], axis=1)}
        values.update(aux)
        return values

    # -- sample values of one depth step ------------------------------------------------
    def _draw(self, depth, sp, sm, mat, bounce):
        """Every sample value the hits of one depth step use, drawn in one call per dimension
        for all materials at once (values are per (pixel, sample, dimension), so drawing them
        together gives the very numbers drawing per material would).

        Keys: "pick" (N, 2) lobe choice and emissive-triangle pick; "light" [k] (N, 2) and
        "choice" [k] (N,) per light strategy, valid where the material has lobes; "lobe" (N, 2), valid
        where the material continues.
        """
        n = len(sp)
        u = {"pick": self.sampler.get2d(sp, sm, self.dims.pick(depth))}
        lit = np.flatnonzero(self._lit[mat]) if self.lights.strategies else np.zeros(0, np.int64)
        whole = len(lit) >= n - n // 8  # drawing for a few hits that do not need it beats gathering

        def subset(get, dim, shape):
            if whole:
                return get(sp, sm, dim)
            out = np.zeros(shape)
            out[lit] = get(sp[lit], sm[lit], dim)
            return out

        u["light"] = [subset(self.sampler.get2d, self.dims.light(depth, k), (n, 2))
                      for k in range(self.lights.strategies)] if len(lit) else []
        u["choice"] = [subset(self.sampler.get, self.dims.choice(depth, k), n)
                       for k in range(self.lights.strategies)] if len(lit) and self.lights.selecting else None
        go = np.flatnonzero(self._continues[mat]) if bounce else np.zeros(0, np.int64)
        u["lobe"] = np.zeros((n, 2))
        if len(go):
            u["lobe"][go] = self.sampler.get2d(sp[go], sm[go], self.dims.lobe(depth))
        return u

    def _bind_materials(self, mat, prim, hits, surf, pos, ng, ns, tangent, bitangent, wo_l, wo, dirs):
        """(hits, shader) per material: a slice of the hits (sorted by material) for a constant
        material, index arrays of hits sharing one bound shader for a material with varying
        inputs (see core.shading); a program's normal replaces the shading normal and frame of
        its hits in place."""
        starts = np.concatenate([[0], np.flatnonzero(np.diff(mat)) + 1])
        for a, b in zip(starts, np.append(starts[1:], len(mat))):
            g = slice(int(a), int(b))  # the hits of material mat[a]
            shading = self.shading[mat[a]]
            if not shading.varying:
                yield g, shading.shader
                continue
            u, v = hits.u[surf[g]], hits.v[surf[g]]
            bary = np.stack([1.0 - u - v, u, v], axis=1)
            width = self.pixel_spread[0] + self.pixel_spread[1] * hits.t[surf[g]]
            ctx = SurfaceContext(self.attributes, prim[g], bary, pos[g], ns[g], width, dirs[g])
            groups, normal = shading.bind(ctx)
            if normal is not None:
                n = np.where((mf.dot(normal, ng[g]) * mf.dot(wo[g], ng[g]) > 0)[:, None], normal, ns[g])
                n = np.where((mf.dot(wo[g], n) <= 1e-6)[:, None], ng[g], n)
                ns[g] = n
                tangent[g], bitangent[g] = _frame(n)
                wo_l[g] = _to_local(wo[g], tangent[g], bitangent[g], n)
            for rows, shader in groups:
                yield rows + int(a), shader

    # -- next-event estimation ----------------------------------------------------------
    def _direct(self, shader, g, u, p_ids, pos, ng, ns, t, b, wo_l, inside, scale, thr, time, lift):
        """Shadow rays (not yet traced) for the hits g (a slice) of one material, one per light strategy."""
        lights = self.lights
        out = []
        if lights.strategies == 0 or not shader.lobes:
            return out
        pid = p_ids[g]
        u_pick = u["pick"][g, 1]
        # the material's hits: views, as g is a slice
        pos_g, ng_g, t_g, b_g, ns_g, wo_g, in_g, thr_g, scale_g = (
            a[g] for a in (pos, ng, t, b, ns, wo_l, inside, thr, scale))
        time_g = time[pid] if self.timed else None
        sel_g = shader.selection(wo_g[:, 2]) if shader.sampled else None
        # the terminator lift is for diffuse shading over coarse facets (measured on Ignis'
        # rough-glass cylinder, lifting glass as well doubled the noise of its highlights)
        lift_g = lift(g) if any(lobe.kind == "diffuse" for lobe in shader.lobes) else np.zeros_like(pos_g)
        for k in range(lights.strategies):
            u_k = u["light"][k][g]
            u_light = u["choice"][k][g] if lights.selecting else None
            ls = lights.sample(k, pos_g, ng_g, u_k, u_pick, u_light, time_g)
            ok = mf.max3(ls.value) > 0
            if not ok.any():
                continue
            wi_l = _to_local(ls.wi, t_g, b_g, ns_g)
            above = wi_l[:, 2] > 0  # the shading hemisphere decides, as in Cycles, not the facet
            f_diff, f_nd, pdf_b = shader.evaluate(wo_g, wi_l, above, in_g, sel_g)
            f_diff, f_nd = ls.restrict(f_diff, f_nd, above)
            w_l = _power(ls.pdf, pdf_b)
            contrib = thr_g * ls.value * (f_diff + f_nd * w_l[:, None])
            ok &= mf.max3(contrib) > 0
            sel = np.flatnonzero(ok)
            if len(sel) == 0:
                continue
            origin = _shadow_origin(pos_g[sel], ng_g[sel], ls.wi[sel], wi_l[sel, 2], lift_g[sel], scale_g[sel])
            dist = ls.dist[sel]
            stop = 0.0 if ls.tmax_scale is None else ls.tmax_scale[sel]
            tmax = np.where(np.isinf(dist), np.inf, dist * (1.0 - 1e-6) - stop - scale_g[sel])
            out.append((pid[sel], origin, ls.wi[sel], np.maximum(tmax, 0.0), contrib[sel]))
        return out

    def _resolve_shadows(self, shadow, radiance, times):
        parts = [item for group in shadow for item in group]
        if not parts:
            return
        pid = np.concatenate([p[0] for p in parts])
        origins = np.concatenate([p[1] for p in parts])
        dirs = np.concatenate([p[2] for p in parts])
        tmax = np.concatenate([p[3] for p in parts])
        contrib = np.concatenate([p[4] for p in parts])
        self._count("shadow", len(pid))
        blocked = self.geometry.occluded(origins, dirs, tmax, times[pid])
        # area lights are not geometry: a nearer area light also blocks (lights cast shadows
        # of each other's bodies in Cycles only when they are meshes, so it does not here)
        visible = ~blocked
        for c in range(3):
            radiance[:, c] += np.bincount(pid[visible], weights=contrib[visible, c], minlength=len(radiance))

    # -- continuation through a non-diffuse lobe ------------------------------------
    def _continue(self, shader, g, u, p_ids, pos, ng, ns, t, b, wo_l, inside, scale, thr, straight):
        pid = p_ids[g]
        u2 = u["lobe"][g]
        u_sel = u["pick"][g, 0]
        wi_l, weight, pdf, delta, valid, passthrough = shader.sample(wo_l[g], u_sel, u2, inside[g])
        new_thr = thr[g] * weight
        valid &= mf.max3(new_thr) > 0
        sel = np.flatnonzero(valid)
        gi = _at(g, sel)
        wi = _to_world(wi_l[sel], t[gi], b[gi], ns[gi])
        # a sampled direction on the wrong side of the geometric surface would leak light
        transmit = wi_l[sel, 2] < 0
        geo_ok = (mf.dot(wi, ng[gi]) < 0) == transmit
        sel, gi, wi, transmit = sel[geo_ok], gi[geo_ok], wi[geo_ok], transmit[geo_ok]
        passthrough = passthrough[sel]
        origin = spawn(pos[gi], ng[gi], wi, scale[gi])
        self._count("refraction", (transmit & ~passthrough).sum())
        self._count("reflection", (~transmit).sum())
        self._count("transparent", passthrough.sum())
        prev_pdf = np.where(delta[sel], np.inf, pdf[sel])
        return pid[sel], origin, wi, new_thr[sel], prev_pdf, ng[gi], straight[g][sel] & passthrough


_BLOCK = 1 << 20  # pixels of a round gathered at a time (bounds the driver's memory on large images)


def _counts(count, pixels):
    """Samples so far of ``pixels`` as int32, gathered a block at a time (no float64 copy)."""
    out = np.empty(len(pixels), np.int32)
    for a in range(0, len(pixels), _BLOCK):
        out[a:a + _BLOCK] = count[pixels[a:a + _BLOCK]]
    return out


def _waves(pix, base, need):
    """Waves of at most WAVE (pixel, sample ids) in sample-major order: every pixel's next
    sample before any pixel's one after. Made step by step, a block of pixels at a time, as
    they are traced, so memory is bounded by the block and the wave, not by the samples of
    a round or the image (an 8K round held 4.6 GB at its peak with whole-image steps)."""
    pend_pix, pend_sample, size = [], [], 0
    for step in range(int(need.max()) if len(need) else 0):
        for b in range(0, len(pix), _BLOCK):
            live = need[b:b + _BLOCK] > step
            pend_pix.append(pix[b:b + _BLOCK][live])
            pend_sample.append(base[b:b + _BLOCK][live].astype(np.int64) + step)
            size += len(pend_pix[-1])
            if size >= WAVE:
                p, smp = np.concatenate(pend_pix), np.concatenate(pend_sample)
                full = size - size % WAVE
                for a in range(0, full, WAVE):
                    yield p[a:a + WAVE], smp[a:a + WAVE]
                pend_pix, pend_sample, size = [p[full:]], [smp[full:]], size - full
    if size:
        yield np.concatenate(pend_pix), np.concatenate(pend_sample)


TERMINATOR_CUTOFF = 0.1
"""Cosine below which shadow rays leave from the smooth surface (Cycles' default shadow
terminator geometry offset)."""


def _shadow_origin(pos, ng, wi, cos_shading, lift, scale):
    """Shadow-ray origin: on the side of the surface the shading normal puts wi, lifted by
    ``lift`` toward the smooth surface near the terminator (Cycles' rule, faded in by the
    cosines) so that light the shading normal sees is not cut off by the flat facet."""
    cos_geo = mf.dot(ng, wi)
    c = TERMINATOR_CUTOFF
    amount = np.where(cos_shading < c, np.clip(2.0 - (cos_geo + cos_shading) / c, 0.0, 1.0),
                      np.clip(1.0 - cos_geo / c, 0.0, 1.0))
    amount = np.where(cos_shading > 0, amount, 0.0)
    side = np.where(cos_shading > 0, 1.0, -1.0)[:, None] * ng
    return spawn(pos + lift * amount[:, None], ng, side, scale)


_frame = mf.orthonormal_basis


def _at(g, sel):
    """Hit indices of the positions ``sel`` within the group ``g`` (a slice or an index array)."""
    return sel + g.start if isinstance(g, slice) else g[sel]


def _to_local(v, t, b, n):
    return np.stack([mf.dot(v, t), mf.dot(v, b), mf.dot(v, n)], axis=1)


def _to_world(v, t, b, n):
    return v[:, :1] * t + v[:, 1:2] * b + v[:, 2:] * n
