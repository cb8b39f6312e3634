"""Blender driven from a script: what the headless CLI asks of the bpy module in its own process.

Open a .blend with DRT registered, change its settings in memory, run Blender's render
operator and save its result. The CLI sits above this layer and never imports bpy itself;
this module knows nothing of the CLI (its options, messages or exit codes): it raises
BatchError with Blender's own message and the caller says what it was doing.
"""
from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import bpy

from . import oidn, register
from .engine import DRTRenderEngine
from .hooks import render_hooks


class BatchError(Exception):
    """An operator of Blender's failed: the message is Blender's, on one line."""


def _blender_message(error: Exception) -> str:
    """Blender's operator errors read 'Error: message\\n...': keep the message."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    text = lines[0] if lines else type(error).__name__
    return re.sub(r"^(Error|Warning):\s*", "", text)


def open_scene(blend: Path, frame: int | None = None):
    """Open ``blend`` with DRT registered and return its active scene at ``frame`` (None: the file's)."""
    if not DRTRenderEngine.is_registered:  # once per process (a test may have done it)
        register()
    try:
        bpy.ops.wm.open_mainfile(filepath=str(blend), load_ui=False)
    except RuntimeError as error:
        raise BatchError(_blender_message(error)) from None
    scene = bpy.context.scene
    if frame is not None:
        scene.frame_set(frame)
    return scene


def use_drt(scene, resolution: tuple[int, int] | None = None) -> None:
    """Render ``scene`` with DRT, at ``resolution`` (100%) when given. In memory only, as every change
    here: the file is never saved."""
    render = scene.render
    render.engine = "DRT"
    if resolution:
        render.resolution_x, render.resolution_y = resolution
        render.resolution_percentage = 100


def denoising_unavailable() -> str | None:
    """Why this Blender cannot denoise (it ships no OpenImageDenoise), or None when it can."""
    return oidn.unavailable_reason()


def set_settings(scene, **settings) -> None:
    """Each ``scene.drt`` setting given that is not None, in the order given."""
    for name, value in settings.items():
        if value is not None:
            setattr(scene.drt, name, value)


def render(scene, progress=None, collect_parts: bool = False) -> tuple[dict[str, dict], dict[str, object]]:
    """Run Blender's render operator on ``scene``: (report of each view layer, part of each view layer).

    ``progress`` is called with every core ProgressUpdate; ``collect_parts`` keeps the parts
    (core.film.parts.Part) instead of writing part files, else the parts returned are empty.
    """
    if collect_parts:
        render_hooks.collect_parts = True
        render_hooks.last_parts.clear()
    render_hooks.last_reports.clear()
    render_hooks.progress_listener = progress
    try:
        bpy.ops.render.render(write_still=False, scene=scene.name)
    except RuntimeError as error:
        raise BatchError(_blender_message(error)) from None
    finally:
        render_hooks.progress_listener = None
    return dict(render_hooks.last_reports), dict(render_hooks.last_parts) if collect_parts else {}


def _set_output_format(image_settings, exr: bool) -> None:
    has_media_type = hasattr(image_settings, "media_type")  # Blender 5.0+
    if exr:
        if has_media_type:
            image_settings.media_type = "MULTI_LAYER_IMAGE"
        image_settings.file_format = "OPEN_EXR_MULTILAYER"
        image_settings.color_depth = "32"
    else:
        if has_media_type:
            image_settings.media_type = "IMAGE"
        image_settings.file_format = "PNG"


def save_render(scene, output: Path) -> None:
    """Save the render result to ``output``: a multilayer EXR of every pass (.exr), else a PNG through
    the scene's view transform."""
    _set_output_format(scene.render.image_settings, output.suffix.lower() == ".exr")
    try:
        bpy.data.images["Render Result"].save_render(filepath=str(output), scene=scene)
    except RuntimeError as error:
        raise BatchError(_blender_message(error)) from None


def output_size(scene) -> tuple[int, int]:
    """The rendered image's width and height in pixels (the resolution at its percentage)."""
    render = scene.render
    return tuple(side * render.resolution_percentage // 100 for side in (render.resolution_x, render.resolution_y))


def remove_session_folder() -> None:
    """Remove Blender's session temp folder, which the bpy module removes only in a teardown a script
    may skip (os._exit)."""
    if os.path.basename(os.path.normpath(bpy.app.tempdir)).startswith("blender_"):
        shutil.rmtree(bpy.app.tempdir, ignore_errors=True)
