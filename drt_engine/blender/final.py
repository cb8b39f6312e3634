"""A render through the engine's ``render``: F12, ``blender -b``, the headless CLI, and the previews.

Export the depsgraph, trace it, hand the passes back to Blender. Blender calls ``render``
once per view layer with that layer's depsgraph (stereo views are not rendered separately
yet). With border render on, Blender's render result covers only the border (it pastes the
result into the full frame itself when "Crop to Render Region" is off), so the engine always
writes the ``camera.window`` rectangle at (0, 0) of its result.
"""
import dataclasses
import json
import time
import traceback

import numpy as np

from ..core.base import jit
from ..core.errors import DRTError, RenderCancelled
from ..core.film import cryptomatte
from ..core.render import report
from .hooks import render_hooks
from .oidn import UNAVAILABLE, oidn_library
from .part_files import keep_part
from .preview import PREVIEW_LAYER, preview_settings
from .properties import result_pass_name, settings_from_scene
from .status import COMPILING, done_line, one_line, stats_line

DISPLAY_INTERVAL = 1.0
"""Seconds between refreshes of the image on screen while rendering."""


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


def prepared_for(scene_data, layer: str, keep: bool):
    """(scene data, prepared scene or None) for a final render: the kept prepared scene when the
    content is the same, else None (the Renderer prepares it), kept for the next frame if ``keep``."""
    from ..core.render.prepared import PreparedScene, content_key

    persistent = render_hooks.persistent
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
        target = layer_passes.get(result_pass_name(name))
        if target is not None:
            target.rect.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())


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
        "est_relmse_denoised": "" if stats.get("relmse_denoised") is None else f"{stats['relmse_denoised']:.6g}",
        "error_log": json.dumps(report.json_safe(outcome.log), separators=(",", ":")),
    }
    for name, value in fields.items():
        result.stamp_data_add_field(f"drt.{view_layer}.{name}", value)


def stamp_cryptomatte(engine, view_layer: str, scene_data, settings) -> None:
    """Each Cryptomatte pass's name, hash, conversion and manifest as the render's metadata, as Cycles
    stamps them (``cryptomatte/<7 hex digits>/...``): the compositor's Cryptomatte node reads them."""
    fields = cryptomatte.scene_metadata(view_layer, scene_data, settings.passes)
    result = engine.get_result() if fields else None
    if result is None or not hasattr(result, "stamp_data_add_field"):
        return
    for key, value in fields.items():
        result.stamp_data_add_field(key, value)


def render(engine, depsgraph) -> None:
    """The engine's ``render``: errors end as one report, a bug's details go to the console."""
    try:
        _render(engine, depsgraph)
    except RenderCancelled:
        pass
    except DRTError as error:
        engine.report({"ERROR"}, one_line(str(error)))
    except Exception as error:  # a bug of ours: one line for the user, details in the console
        print(f"DRT: unexpected error while rendering\n{traceback.format_exc()}")
        engine.report({"ERROR"}, one_line(f"DRT internal error: {type(error).__name__}: {error}"))


def _render(engine, depsgraph):
    from ..core.render.render import Renderer
    from .export import export_scene

    scene = depsgraph.scene
    view_layer = depsgraph.view_layer
    engine.update_stats("", "Exporting scene")
    scene_data = export_scene(depsgraph, camera_object=engine.camera_override, cancel=engine.test_break,
                              frame_set=None if engine.is_preview else engine.frame_set)
    _warn(engine, scene_data.warnings)
    if engine.test_break():
        return
    _check_window(engine, scene_data.camera, scene.render)

    settings = settings_from_scene(scene, view_layer)
    if engine.is_preview:
        settings = preview_settings(settings)
    settings, denoiser = denoiser_for(engine, settings)
    if jit.first_run():
        engine.update_stats("", COMPILING)
        print(f"DRT: {COMPILING}", flush=True)  # the console, and the CLI's output
    else:
        engine.update_stats("", "Preparing the render")
    if engine.is_preview:
        scene_data, prepared = prepared_for(scene_data, PREVIEW_LAYER, True)
    else:
        scene_data, prepared = prepared_for(scene_data, view_layer.name, scene.render.use_persistent_data)
    renderer = Renderer(scene_data, settings, prepared, denoiser=denoiser)
    if engine.test_break():
        return

    width, height = scene_data.camera.window_size
    result = engine.begin_result(0, 0, width, height, layer=view_layer.name)
    try:
        outcome = renderer.render(progress=progress_callback(engine, result))
        write_passes(result, outcome.passes)
        if not engine.is_preview:
            summary = report.report_dict(settings, outcome.stats, outcome.log,
                                         report.scene_summary(scene_data))
            summary["view_layer"] = view_layer.name
            render_hooks.last_reports[view_layer.name] = summary
            if not outcome.cancelled:
                keep_part(scene, view_layer, scene_data, renderer.film, settings, summary)
    finally:
        engine.end_result(result)
    if not engine.is_preview:
        stamp_report(engine, view_layer.name, outcome)
        stamp_cryptomatte(engine, view_layer.name, scene_data, settings)
    _warn(engine, [w for w in getattr(outcome, "warnings", ()) if w not in scene_data.warnings])
    if not outcome.cancelled:
        engine.update_progress(1.0)
    stats = outcome.stats
    engine.update_stats("", done_line(stats, outcome.cancelled))
    if not engine.is_preview:  # the console (and the CLI's output) shows what the scene left out
        rays = ", ".join(f"{k} {v}" for k, v in stats.get("rays", {}).items())
        print(f"DRT: {stats.get('plan_summary', '')}\nDRT: rays traced: {rays}", flush=True)


def denoiser_for(engine, settings):
    """(settings, core.film.denoiser.Denoiser or None): Blender's own OpenImageDenoise when the
    settings ask for denoising; where this Blender has none, a warning and a render not denoised.
    A library that is there but fails to load is a DenoiserError (one line, the render ends)."""
    if not settings.use_denoising or settings.partial:
        return settings, None
    path = oidn_library()
    if path is None:
        _warn(engine, [f"{UNAVAILABLE}; the image is not denoised"])
        return dataclasses.replace(settings, use_denoising=False), None
    from ..core.film.denoiser import load

    return settings, load(path)


def _warn(engine, warnings):
    if not engine.is_preview:  # material thumbnails would repeat the same warnings endlessly
        for warning in warnings:
            engine.report({"WARNING"}, one_line(warning))


def progress_callback(engine, result):
    """The core's progress callback: progress bar, stats, progressive image, cancel."""
    last_display = time.monotonic()

    def progress(update) -> bool:
        nonlocal last_display
        listener = render_hooks.progress_listener
        if listener is not None and not engine.is_preview:
            listener(update)
        engine.update_progress(min(max(update.fraction, 0.0), 1.0))
        engine.update_stats("", stats_line(update.samples_done, update.samples_total, update.error,
                                           update.elapsed))
        now = time.monotonic()
        if now - last_display >= DISPLAY_INTERVAL:
            write_passes(result, {"Combined": update.passes()["Combined"]})
            engine.update_result(result)
            last_display = now
        return not engine.test_break()

    return progress


def _check_window(engine, camera, render):
    """The export's pixel rectangle must be the one Blender allocated for the result."""
    expected = render_window(render, engine.resolution_x, engine.resolution_y)
    if tuple(camera.resolution) != (engine.resolution_x, engine.resolution_y) or tuple(camera.window) != expected:
        raise DRTError(
            f"DRT internal error: exported image {camera.resolution} window {camera.window} "
            f"differs from Blender's {(engine.resolution_x, engine.resolution_y)} window {expected}"
        )
