"""Rendered shading in the 3D viewport: a progressive render on a worker thread.

Blender calls the engine's ``view_update`` and ``view_draw`` on its main thread, which
must never wait for the tracer. The scene is exported there (reading Blender data is
only safe on the main thread), then a worker thread prepares it (core.render.prepared: Embree
scenes, lights, materials) and traces; ``view_draw`` only uploads the newest image and
draws it. Each view renders progressively: one sample at 1/8, 1/4 and 1/2 of the region's
resolution (drawn stretched), then the full resolution accumulating the viewport samples,
published after every round and at most every PUBLISH_INTERVAL within one. A new scene or
a new view stops the running worker (it notices at its next progress call, after its
current wave) and starts another one; a new view of the same scene (orbit, zoom) reuses
its prepared scene, an edited scene updates it (only the meshes, materials or lights the
edit touched are rebuilt). The worker never holds the engine: it asks for redraws through
a weak reference, so Blender can free the engine whenever it wants, and a
``weakref.finalize`` on the engine stops the worker first. ViewportSession is what the
engine keeps between its ``view_update`` and ``view_draw`` calls.
"""
from __future__ import annotations

import dataclasses
import os
import sys
import threading
import time
import traceback
import weakref
from collections.abc import Callable

import numpy as np

from ..core.errors import DRTError
from ..core.film.denoising import PASSES as FEATURE_PASSES, with_features
from .oidn import oidn_library
from .properties import settings_from_scene
from .status import done_line, one_line, stats_line

PUBLISH_INTERVAL = 1.0
"""Seconds between two images of the full-resolution render within a round of samples (every
round's end publishes too: 1, 2, 4, ... samples)."""

WORKER_NICE = 5
"""How much nicer (Linux scheduling priority) the viewport's worker runs than Blender, with the
render threads it starts (threads inherit it): Blender's UI thread and its OpenGL driver come
first when the cores are busy. Seen in the GUI test (Mesa's software OpenGL, 2 cores): an image
waits for the next window redraw, about 0.5 s apart while the tracer held both cores."""

STOP_TIMEOUT = 5.0
"""Seconds the engine waits, when Blender frees it, for the worker to reach its next progress call."""


def viewport_settings(settings, preview_samples: int):
    """Settings for Rendered shading: the viewport samples, Combined only, no stop rules, no final-render
    denoising (``use_denoising``; the viewport denoises its own images through ViewDenoise)."""
    return dataclasses.replace(settings, samples=preview_samples, passes=("Combined",), aovs=(),
                               use_adaptive_sampling=False, time_limit=0.0, target_error=0.0,
                               sample_start=0, sample_end=0, use_denoising=False)


@dataclasses.dataclass
class ViewDenoise:
    """Denoising of the viewport's full-resolution images from ``start_sample`` samples on, on the
    worker thread (Blender's UI thread never waits for it), with the scene's viewport prefilter and
    quality (view_denoise)."""
    denoiser: object  # core.film.denoiser.Denoiser
    start_sample: int
    prefilter: str
    quality: str

    def settings(self, settings):
        """The viewport's settings with the features the denoiser needs traced."""
        return with_features(settings)

    def image(self, passes: dict, samples: int, filters) -> tuple[np.ndarray, bool]:
        """(RGBA image to show, whether it is denoised) of a render's passes with ``samples`` in
        every pixel, denoised on ``filters`` (the worker's: core.film.denoiser.Filters)."""
        combined = passes["Combined"]
        if samples < self.start_sample:
            return combined, False
        out = combined.copy()
        out[..., :3] = filters.denoise(combined, passes.get(FEATURE_PASSES[0]), passes.get(FEATURE_PASSES[1]),
                                       prefilter=self.prefilter, quality=self.quality)
        return out, True


def view_denoise(scene) -> ViewDenoise | None:
    """The viewport's denoising of ``scene``: None when off, where Blender has no OpenImageDenoise, or
    when its library fails to load (one line in the console: the viewport goes on, noisy)."""
    path = oidn_library()
    if not scene.drt.use_preview_denoising or path is None:
        return None
    from ..core.film.denoiser import load

    try:
        drt = scene.drt
        return ViewDenoise(load(path), drt.preview_denoising_start_sample, drt.preview_denoising_prefilter,
                           drt.preview_denoising_quality)
    except DRTError as error:
        print(f"DRT: the viewport is not denoised: {one_line(str(error))}")
        return None


class ViewportSession:
    """One engine's Rendered shading: its worker, the scene of the last ``view_update`` (the camera
    replaced per view) and the view its render is for, the texture on screen, the meshes kept
    between exports. Made at the engine's first ``view_update``."""

    def __init__(self, engine):
        from .export.geometry import MeshCache

        self.worker = ViewportRender(weak_redraw(engine))
        self.meshes = MeshCache()
        self.scene = None  # SceneData of the last view_update
        self.settings = None
        self.denoise = None  # ViewDenoise, or None: the viewport is not denoised
        self.key = None  # region size and matrices the running render is for
        self.texture = None
        weakref.finalize(engine, self.worker.close)  # Blender frees the engine: stop the worker

    def update(self, engine, depsgraph) -> None:
        """The scene changed (or the viewport opened): export what changed; the next ``draw``
        restarts the render, whose worker updates the prepared scene for the edit."""
        from .export import export_scene
        from .export.viewport import edited_geometry

        self.meshes.forget(edited_geometry(depsgraph.updates))
        try:
            scene_data = export_scene(depsgraph, meshes=self.meshes)
        except Exception as error:
            if not isinstance(error, DRTError):  # a bug of ours: details in the console
                print(f"DRT: unexpected error while exporting for the viewport\n{traceback.format_exc()}")
            self.worker.stop(timeout=0.0)
            self.scene = None
            engine.update_stats("", one_line(str(error)))
            return
        self.scene = scene_data
        self.settings = viewport_settings(settings_from_scene(depsgraph.scene, depsgraph.view_layer),
                                          depsgraph.scene.drt.preview_samples)
        self.denoise = view_denoise(depsgraph.scene)
        self.key = None  # draw restarts the render with the region's camera

    def draw(self, engine, context, depsgraph) -> None:
        """Draw the newest image; restart the render first if the view changed."""
        import gpu

        from .export.viewport import level_cameras, viewport_camera

        region, region_data = context.region, context.region_data
        if self.scene is not None:
            key = (region.width, region.height, tuple(map(tuple, region_data.view_matrix)),
                   tuple(map(tuple, region_data.window_matrix)))
            if key != self.key:
                cameras = level_cameras(viewport_camera(region, region_data))
                self.worker.start(self.scene, cameras, self.settings, self.denoise)
                self.key = key
        version, image = self.worker.latest()
        if self.worker.status:
            engine.update_stats("", self.worker.status)
        if image is None:
            return
        if self.texture is None:
            self.texture = ViewportTexture()
        self.texture.update(version, image)
        gpu.state.blend_set("ALPHA_PREMULT")
        engine.bind_display_space_shader(depsgraph.scene)
        self.texture.draw(region.width, region.height)
        engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")


class ViewportRender:
    """One worker at a time rendering the viewport; the newest image, shared under a lock."""

    def __init__(self, redraw: Callable[[], None]):
        self._redraw = redraw
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.image: np.ndarray | None = None
        """(h, w, 4) float32 RGBA, rows bottom-to-top, or None before the first round."""
        self.version = 0
        self.status = ""
        self._prepared = None  # (SceneData, PreparedScene) of the newest scene prepared
        self._prepare_lock = threading.Lock()
        self._filters = None  # core.film.denoiser.Filters the views share (set up once per size)
        self._filters_lock = threading.Lock()

    def start(self, scene_data, cameras, settings, denoise: ViewDenoise | None = None) -> None:
        """Stop the running worker (without waiting for it) and render ``scene_data`` seen by
        ``cameras``: coarse to fine, the same view at growing resolutions, one sample each but
        the last, which takes ``settings.samples`` (denoised by ``denoise`` from its start sample)."""
        self._stop.set()
        stop = threading.Event()
        self._stop = stop
        self._thread = threading.Thread(target=self._run, args=(scene_data, cameras, settings, stop, denoise),
                                        name="DRT viewport", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = STOP_TIMEOUT) -> None:
        """Stop the worker and wait for it, so nothing calls back into a freed engine."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    def close(self) -> None:
        """Stop the worker and release the denoiser's filters (a worker still running then fails
        with a DenoiserError instead of setting filters up again)."""
        self.stop()
        with self._filters_lock:
            if self._filters is not None:
                self._filters.close()

    def filters(self, denoiser):
        """The denoiser's filters, kept from view to view: setting one up for a 1280x720 image took
        0.2-0.3 s (bench/viewport_times.py's load), which every orbit step would pay again. Workers
        may overlap; the denoiser's lock serialises their runs."""
        with self._filters_lock:
            if self._filters is None or self._filters.denoiser is not denoiser:
                if self._filters is not None:
                    self._filters.close()
                self._filters = denoiser.filters()
            return self._filters

    def latest(self) -> tuple[int, np.ndarray | None]:
        with self._lock:
            return self.version, self.image

    def _publish(self, image: np.ndarray, stop: threading.Event, status: str) -> None:
        with self._lock:
            if stop.is_set():
                return
            self.image = np.ascontiguousarray(image, dtype=np.float32)
            self.version += 1
            self.status = status
        self._redraw()

    def prepared(self, scene_data):
        """The prepared scene of ``scene_data``: the one made for it before, else the previous
        scene's updated for the edit (core.render.prepared.PreparedScene.update rebuilds only what
        changed), else a new one (under a lock: a stale worker and a new one never prepare the
        same scene twice)."""
        from ..core.render.prepared import PreparedScene

        with self._prepare_lock:
            if self._prepared is None:
                self._prepared = (scene_data, PreparedScene(scene_data))
            elif self._prepared[0] is not scene_data:
                self._prepared = (scene_data, self._prepared[1].update(scene_data))
            return self._prepared[1]

    def _run(self, scene_data, cameras, settings, stop: threading.Event, denoise=None) -> None:
        from ..core.render.render import Renderer

        try:
            _nicer(WORKER_NICE)
            prepared = self.prepared(scene_data)
            if stop.is_set():  # the view changed while the scene was being prepared
                return
            coarse = dataclasses.replace(settings, samples=1)
            for camera in cameras[:-1]:  # one sample each, a new view on screen at once
                renderer = Renderer(dataclasses.replace(scene_data, camera=camera), coarse, prepared)
                result = renderer.render(progress=lambda _: not stop.is_set())
                if result.cancelled or stop.is_set():
                    return
                width, height = camera.resolution
                self._publish(result.passes["Combined"], stop, f"Preview {width} x {height}")
            full = denoise.settings(settings) if denoise is not None else settings
            renderer = Renderer(dataclasses.replace(scene_data, camera=cameras[-1]), full, prepared)
            last = [0.0]

            def shown(passes, samples):
                if denoise is None:
                    return passes["Combined"], ""
                image, denoised = denoise.image(passes, samples, self.filters(denoise.denoiser))
                return image, " | Denoised" if denoised else ""

            def progress(update) -> bool:
                if stop.is_set():
                    return False
                now = time.monotonic()
                if update.entry is not None or (now - last[0] >= PUBLISH_INTERVAL and update.samples_everywhere):
                    image, note = shown(update.passes(), update.samples_everywhere)
                    last[0] = time.monotonic()  # the next image waits a whole interval after this one
                    self._publish(image, stop, stats_line(update.samples_done, update.samples_total, update.error,
                                                          update.elapsed) + note)
                return not stop.is_set()

            result = renderer.render(progress=progress)
            if not result.cancelled:
                image, note = shown(result.passes, result.stats["samples"])  # no adaptive sampling here
                self._publish(image, stop, done_line(result.stats, False) + note)
        except DRTError as error:
            self._fail(" ".join(str(error).split()), stop)
        except Exception as error:  # a bug of ours: keep the UI alive, details in the console
            print(f"DRT: unexpected error in the viewport render\n{traceback.format_exc()}")
            self._fail(f"DRT internal error: {type(error).__name__}: {error}", stop)

    def _fail(self, message: str, stop: threading.Event) -> None:
        with self._lock:
            if stop.is_set():
                return
            self.status = message
        self._redraw()


def _nicer(step: int) -> None:
    """Lower the calling thread's priority by ``step`` (Linux: niceness is per thread, and
    threads it starts inherit it); elsewhere, or when refused, leave it."""
    if not sys.platform.startswith("linux"):
        return
    thread = threading.get_native_id()
    try:
        os.setpriority(os.PRIO_PROCESS, thread, min(19, os.getpriority(os.PRIO_PROCESS, thread) + step))
    except OSError:
        pass


def weak_redraw(engine) -> Callable[[], None]:
    """``engine.tag_redraw`` through a weak reference: a no-op once the engine is gone.

    Blender may free the engine between the dereference and the call; the Python object
    then raises ReferenceError instead of touching freed memory.
    """
    ref = weakref.ref(engine)

    def redraw():
        alive = ref()
        if alive is not None:
            try:
                alive.tag_redraw()
            except ReferenceError:
                pass

    return redraw


class ViewportTexture:
    """The newest viewport image on the GPU, drawn stretched over the whole region.

    Drawn with Blender's built-in IMAGE shader on a two-triangle strip; gpu_extras'
    draw_texture_2d uses a triangle fan, which Blender 4.3 reports as deprecated on every
    draw (a DeprecationWarning from its own module)."""

    CORNERS = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0))

    def __init__(self):
        self.version = -1
        self.texture = None
        self._batch = None
        self._shader = None

    def update(self, version: int, image: np.ndarray) -> None:
        """Upload ``image`` if its version is new; an unchanged one keeps the texture. The
        Buffer wraps the worker's contiguous float32 array through the buffer protocol without
        a copy (bpy_gpu_buffer's Buffer.__new__), so the upload is the only pass over it."""
        import gpu

        if version == self.version:
            return
        height, width, _ = image.shape
        pixels = gpu.types.Buffer("FLOAT", width * height * 4, image.ravel())
        self.texture = gpu.types.GPUTexture((width, height), format="RGBA16F", data=pixels)
        self.version = version

    def draw(self, width: int, height: int) -> None:
        import gpu
        from gpu_extras.batch import batch_for_shader

        if self.texture is None:
            return
        if self._batch is None:
            self._shader = gpu.shader.from_builtin("IMAGE")
            self._batch = batch_for_shader(self._shader, "TRI_STRIP", {"pos": self.CORNERS, "texCoord": self.CORNERS})
        with gpu.matrix.push_pop():
            gpu.matrix.scale((width, height))
            self._shader.uniform_sampler("image", self.texture)
            self._batch.draw(self._shader)
