"""The DRT RenderEngine: export the depsgraph, trace it, hand the passes back to Blender.

Blender calls ``render`` once per view layer with that layer's depsgraph (stereo views
are not rendered separately yet). With border render on, Blender's render result covers only the border (it
pastes the result into the full frame itself when "Crop to Render Region" is off), so
the engine always writes the ``camera.window`` rectangle at (0, 0) of its result.
"""
import dataclasses
import json
import time
import traceback
import weakref

import bpy
import numpy as np

from ..core.base import jit
from ..core.errors import DRTError, RenderCancelled
from ..core.render import report
from . import part_files
from .properties import enabled_passes, pass_layout, settings_from_scene

DISPLAY_INTERVAL = 1.0
"""Seconds between refreshes of the image on screen while rendering."""

COMPILING = "Compiling DRT kernels (first run only)"
"""Status while the first render after an install compiles the kernels (later ones load them)."""

PREVIEW_SAMPLES = 8
PREVIEW_MAX_DEPTH = 4
"""Material and light previews (thumbnails, the Preview panel): few samples and short chains.
8 samples, not 16: the 128-pixel preview of a Cornell box material took 2.4 s at 16 (its
relMSE against 256 samples 3.6e-4, 8.9e-4 at 8), bench/preview_times.py."""

PREVIEW_LAYER = "<material preview>"
"""The ``persistent`` slot of previews: Blender renders a material's icon, then its large
preview, of the same preview scene, so the second reuses the first's prepared scene."""


def render_window(render, width: int, height: int) -> tuple[int, int, int, int]:
    """The pixel rectangle (x0, y0, x1, y1) Blender allocates for a render, rows from the bottom.

    ``width``, ``height`` are the full image after the resolution percentage
    (``RenderEngine.resolution_x/y``). Blender truncates border * size in single
    precision (render_init_from_main in pipeline.cc), so this does the same.
    """
    if not render.use_border:
        return 0, 0, width, height
    border = np.array([render.border_min_x, render.border_min_y, render.border_max_x, render.border_max_y],
                      np.float32)
    x0, y0, x1, y1 = (int(v) for v in border * np.array([width, height, width, height], np.float32))
    return x0, y0, x1, y1


last_reports: dict[str, dict] = {}
"""The report (core.render.report.report_dict) of the newest final render of each view layer, by name.

The CLI runs Blender's render operator in its own process; this is how it gets the
engine's settings, stats and error log back to write ``<OUT stem>.drt.json``.
"""

progress_listener = None
"""Called with every core ProgressUpdate of a final render when set: the CLI's live progress line."""


persistent: dict[str, tuple[str, object]] = {}
"""With Blender's Persistent Data on (Render Properties > Performance, as for Cycles): per view
layer, the content key (core.render.prepared.content_key) and prepared scene of its last final render,
so the next frame reuses the Embree scenes, lights and materials when only the camera changed."""


def prepared_for(scene_data, layer: str, keep: bool):
    """(scene data, prepared scene or None) for a final render: the kept prepared scene when the
    content is the same, else None (the Renderer prepares it), kept for the next frame if ``keep``."""
    from ..core.render.prepared import PreparedScene, content_key

    if not keep:
        persistent.pop(layer, None)
        return scene_data, None
    key = content_key(scene_data)
    kept = persistent.get(layer)
    if key is not None and kept is not None and kept[0] == key:
        return kept[1].adopt(scene_data), kept[1]
    persistent.pop(layer, None)  # free the old one before building the next
    prepared = PreparedScene(scene_data)
    if key is not None:
        persistent[layer] = (key, prepared)
    return scene_data, prepared


def write_passes(result, passes: dict) -> None:
    """Copy the core's (h, w, C) arrays, rows bottom-to-top like Blender's, into a render result."""
    layer_passes = result.layers[0].passes
    for name, pixels in passes.items():
        target = layer_passes.get(name)
        if target is not None:
            target.rect.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())


def preview_settings(settings):
    """Settings for a material or light preview: small and fast, Combined only."""
    return dataclasses.replace(settings, samples=min(settings.samples, PREVIEW_SAMPLES),
                               max_depth=min(settings.max_depth, PREVIEW_MAX_DEPTH), passes=("Combined",),
                               sample_start=0, sample_end=0)


def viewport_settings(settings, preview_samples: int):
    """Settings for Rendered shading: the viewport samples, Combined only, no stop rules."""
    return dataclasses.replace(settings, samples=preview_samples, passes=("Combined",),
                               use_adaptive_sampling=False, time_limit=0.0, target_error=0.0,
                               sample_start=0, sample_end=0)


def stats_line(samples_done: int, samples_total: int, relmse: float, elapsed: float) -> str:
    """The live stats line: 'Sample 12/64 | est. error 0.8% | 12.3 s'."""
    return (f"Sample {samples_done}/{samples_total} | est. error {report.relative_error_text(relmse)} "
            f"| {elapsed:.1f} s")


def done_line(stats: dict, cancelled: bool) -> str:
    """The last stats line: samples, estimated error, time, what stopped the render, the render plan."""
    error = report.relative_error_text(stats.get("relmse"))
    state = "Cancelled" if cancelled else "Done"
    samples = f"{stats['samples']} samples"
    if stats.get("adaptive_threshold") is not None:
        samples += f" (mean {stats['samples_mean']:.1f})"
    stopped = "" if cancelled else f" | stopped by {report.STOP_REASONS[stats['stopped_by']]}"
    plan = f" | {stats['plan_summary']}" if stats.get("plan_summary") else ""
    return f"{state} | {samples} | est. error {error} | {stats['elapsed']:.2f} s{stopped}{plan}"


def stamp_report(engine, view_layer: str, outcome) -> None:
    """The stop reason, estimated error and the whole error log as the render's metadata.

    Fields go on the engine's whole result (as Cycles stamps ``cycles.<layer>.samples``;
    a result from begin_result drops them when it is merged), named ``drt.<layer>.*``,
    and Blender writes them into EXR headers and PNG text with its other metadata.
    """
    result = engine.get_result()
    if result is None or not hasattr(result, "stamp_data_add_field"):
        return
    stats = outcome.stats
    fields = {
        "stopped_by": stats["stopped_by"],
        "samples": str(stats["samples"]),
        "elapsed": f"{stats['elapsed']:.3f}",
        "est_relmse": "" if stats.get("relmse") is None else f"{stats['relmse']:.6g}",
        "error_log": json.dumps(report.json_safe(outcome.log), separators=(",", ":")),
    }
    for name, value in fields.items():
        result.stamp_data_add_field(f"drt.{view_layer}.{name}", value)


def _one_line(text: str) -> str:
    return " ".join(text.split())


class DRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "DRT"
    bl_label = "DRT"
    bl_use_shading_nodes_custom = False
    bl_use_preview = True
    bl_use_postprocess = True
    bl_use_eevee_viewport = True

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._viewport = None  # ViewportRender, made at the first view_update
        self._view_scene = None  # SceneData of the last view_update, camera replaced per view
        self._view_settings = None
        self._view_key = None  # region size and matrices the running viewport render is for
        self._view_texture = None
        self._view_meshes = None  # export.geometry.MeshCache: meshes kept between viewport exports

    def render(self, depsgraph):
        try:
            self._render(depsgraph)
        except RenderCancelled:
            pass
        except DRTError as error:
            self.report({"ERROR"}, _one_line(str(error)))
        except Exception as error:  # a bug of ours: one line for the user, details in the console
            print(f"DRT: unexpected error while rendering\n{traceback.format_exc()}")
            self.report({"ERROR"}, _one_line(f"DRT internal error: {type(error).__name__}: {error}"))

    def _render(self, depsgraph):
        from ..core.render.render import Renderer
        from .export import export_scene

        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        self.update_stats("", "Exporting scene")
        scene_data = export_scene(depsgraph, camera_object=self.camera_override, cancel=self.test_break,
                                  frame_set=None if self.is_preview else self.frame_set)
        self._warn(scene_data.warnings)
        if self.test_break():
            return
        self._check_window(scene_data.camera, scene.render)

        settings = settings_from_scene(scene, view_layer)
        if self.is_preview:
            settings = preview_settings(settings)
        if jit.first_run():
            self.update_stats("", COMPILING)
            print(f"DRT: {COMPILING}", flush=True)  # the console, and the CLI's output
        else:
            self.update_stats("", "Preparing the render")
        if self.is_preview:
            scene_data, prepared = prepared_for(scene_data, PREVIEW_LAYER, True)
        else:
            scene_data, prepared = prepared_for(scene_data, view_layer.name, scene.render.use_persistent_data)
        renderer = Renderer(scene_data, settings, prepared)
        if self.test_break():
            return

        width, height = scene_data.camera.window_size
        result = self.begin_result(0, 0, width, height, layer=view_layer.name)
        try:
            outcome = renderer.render(progress=self._progress_callback(result))
            write_passes(result, outcome.passes)
            if not self.is_preview:
                summary = report.report_dict(settings, outcome.stats, outcome.log,
                                             report.scene_summary(scene_data))
                summary["view_layer"] = view_layer.name
                last_reports[view_layer.name] = summary
                if not outcome.cancelled:
                    part_files.keep(scene, view_layer, scene_data, renderer.film, settings, summary)
        finally:
            self.end_result(result)
        if not self.is_preview:
            stamp_report(self, view_layer.name, outcome)
        self._warn([w for w in getattr(outcome, "warnings", ()) if w not in scene_data.warnings])
        if not outcome.cancelled:
            self.update_progress(1.0)
        stats = outcome.stats
        self.update_stats("", done_line(stats, outcome.cancelled))
        if not self.is_preview:  # the console (and the CLI's output) shows what the scene left out
            rays = ", ".join(f"{k} {v}" for k, v in stats.get("rays", {}).items())
            print(f"DRT: {stats.get('plan_summary', '')}\nDRT: rays traced: {rays}", flush=True)

    def _warn(self, warnings):
        if not self.is_preview:  # material thumbnails would repeat the same warnings endlessly
            for warning in warnings:
                self.report({"WARNING"}, _one_line(warning))

    def _progress_callback(self, result):
        """The core's progress callback: progress bar, stats, progressive image, cancel."""
        last_display = time.monotonic()

        def progress(update) -> bool:
            nonlocal last_display
            if progress_listener is not None and not self.is_preview:
                progress_listener(update)
            self.update_progress(min(max(update.fraction, 0.0), 1.0))
            self.update_stats("", stats_line(update.samples_done, update.samples_total, update.error,
                                             update.elapsed))
            now = time.monotonic()
            if now - last_display >= DISPLAY_INTERVAL:
                write_passes(result, {"Combined": update.passes()["Combined"]})
                self.update_result(result)
                last_display = now
            return not self.test_break()

        return progress

    def _check_window(self, camera, render):
        """The export's pixel rectangle must be the one Blender allocated for the result."""
        expected = render_window(render, self.resolution_x, self.resolution_y)
        if tuple(camera.resolution) != (self.resolution_x, self.resolution_y) or tuple(camera.window) != expected:
            raise DRTError(
                f"DRT internal error: exported image {camera.resolution} window {camera.window} "
                f"differs from Blender's {(self.resolution_x, self.resolution_y)} window {expected}"
            )

    def view_update(self, context, depsgraph):
        """The scene changed (or the viewport opened): export what changed and restart the
        viewport render, whose worker updates the prepared scene for the edit."""
        from .export import export_scene
        from .export.geometry import MeshCache
        from .export.viewport import edited_geometry
        from .viewport import ViewportRender, weak_redraw

        if self._viewport is None:
            self._viewport = ViewportRender(weak_redraw(self))
            self._view_meshes = MeshCache()
            weakref.finalize(self, self._viewport.stop)  # Blender frees the engine: stop the worker
        self._view_meshes.forget(edited_geometry(depsgraph.updates))
        try:
            scene_data = export_scene(depsgraph, meshes=self._view_meshes)
        except Exception as error:
            if not isinstance(error, DRTError):  # a bug of ours: details in the console
                print(f"DRT: unexpected error while exporting for the viewport\n{traceback.format_exc()}")
            self._viewport.stop(timeout=0.0)
            self._view_scene = None
            self.update_stats("", _one_line(str(error)))
            return
        self._view_scene = scene_data
        self._view_settings = viewport_settings(settings_from_scene(depsgraph.scene, depsgraph.view_layer),
                                                depsgraph.scene.drt.preview_samples)
        self._view_key = None  # view_draw restarts the render with the region's camera

    def view_draw(self, context, depsgraph):
        """Draw the newest viewport image; restart the render first if the view changed."""
        import gpu

        from .export.viewport import level_cameras, viewport_camera
        from .viewport import ViewportTexture

        region, region_data = context.region, context.region_data
        if self._view_scene is not None:
            key = (region.width, region.height, tuple(map(tuple, region_data.view_matrix)),
                   tuple(map(tuple, region_data.window_matrix)))
            if key != self._view_key:
                cameras = level_cameras(viewport_camera(region, region_data))
                self._viewport.start(self._view_scene, cameras, self._view_settings)
                self._view_key = key
        if self._viewport is None:
            return
        version, image = self._viewport.latest()
        if self._viewport.status:
            self.update_stats("", self._viewport.status)
        if image is None:
            return
        if self._view_texture is None:
            self._view_texture = ViewportTexture()
        self._view_texture.update(version, image)
        gpu.state.blend_set("ALPHA_PREMULT")
        self.bind_display_space_shader(depsgraph.scene)
        self._view_texture.draw(region.width, region.height)
        self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")

    def update_render_passes(self, scene=None, renderlayer=None):
        for name in enabled_passes(renderlayer):
            self.register_pass(scene, renderlayer, name, *pass_layout(name))


classes = (DRTRenderEngine,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
