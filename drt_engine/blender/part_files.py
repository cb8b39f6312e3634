"""The part a render of a sample range leaves behind, for a render farm's merge.

A `blender -b` job with ``scene.drt.sample_offset`` / ``sample_count`` set writes its part
beside the frame's output (``<frame path without extension>.samples-START-END.exr``, the
view layer's name added when the scene renders several); `python -m drt_engine merge`
adds the parts into the image of all the samples. The CLI instead sets the hooks'
``collect_parts`` and takes the parts from their ``last_parts`` to write them where it is told.
"""
from __future__ import annotations

import os

import bpy

from ..core.errors import DRTError
from ..core.film import cryptomatte, parts
from .hooks import render_hooks


def keep_part(scene, view_layer, scene_data, film, settings, summary: dict) -> None:
    """Keep or write the part of a final render, if it is one (``settings.partial``) or the hooks collect parts."""
    collect = render_hooks.collect_parts
    if not (settings.partial or collect):
        return
    header = {"blend": bpy.data.filepath, "frame": scene.frame_current, "view_layer": view_layer.name,
              "fingerprint": parts.fingerprint(scene_data), "report": summary,
              "metadata": cryptomatte.scene_metadata(view_layer.name, scene_data, settings.passes)}
    part = parts.from_film(film, settings, header)
    if collect:
        render_hooks.last_parts[view_layer.name] = part
        return
    path = part_path(scene, view_layer, settings)
    try:
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        parts.write(path, part)
    except OSError as error:
        raise DRTError(f"cannot write the part {path}: {error.strerror or error}") from None
    print(f"DRT: wrote the part {path}", flush=True)


def part_path(scene, view_layer, settings) -> str:
    frame_path = bpy.path.abspath(scene.render.frame_path(frame=scene.frame_current))
    base, _ = os.path.splitext(frame_path)
    start, end = settings.sample_range()
    layer = f".{view_layer.name}" if sum(layer.use for layer in scene.view_layers) > 1 else ""
    return f"{base}{layer}.samples-{start}-{end}.exr"
