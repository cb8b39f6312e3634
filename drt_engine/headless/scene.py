"""The .blend a render command names: its paths checked before Blender loads, then opened with the
command's overrides (through drt_engine.blender.batch) and checked for what the command needs."""
from __future__ import annotations

import os
from pathlib import Path

from .errors import CLIError

BLEND_MAGIC = (b"BLENDER", b"\x1f\x8b", b"\x28\xb5\x2f\xfd")  # plain, gzip, zstd


def check_paths(blend: Path, output: Path) -> None:
    if not blend.is_file():
        raise CLIError(f"no such file: {blend}")
    with open(blend, "rb") as f:
        head = f.read(7)
    if not head.startswith(BLEND_MAGIC):
        raise CLIError(f"not a .blend file: {blend}")
    if output.suffix.lower() not in (".exr", ".png"):
        raise CLIError(f"output must end in .exr or .png: {output}")
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise CLIError(f"cannot create output folder {output.parent}: {error.strerror or error}") from None
    if output.is_dir():
        raise CLIError(f"output is a folder: {output}")
    if not os.access(output.parent, os.W_OK):
        raise CLIError(f"output folder is not writable: {output.parent}")


def open_scene(args, blend: Path):
    """Open ``blend`` in this process's bpy with DRT registered and the overrides applied."""
    from ..blender import batch  # loads Blender: not before the checks that need none

    try:
        scene = batch.open_scene(blend, args.frame)
    except batch.BatchError as error:
        raise CLIError(f"cannot open {blend}: {error}") from None
    if scene.camera is None:
        raise CLIError(f"scene {scene.name!r} in {blend.name} has no camera")
    adaptive = (args.adaptive_threshold, args.adaptive_min_samples, args.adaptive_mode)
    if args.denoise and batch.denoising_unavailable():
        raise CLIError(f"--denoise: {batch.denoising_unavailable()}")
    batch.use_drt(scene, args.resolution)
    batch.set_settings(scene, samples=args.samples, seed=args.seed, threads=args.engine_threads,
                       time_limit=args.time_limit, target_error=args.target_error,
                       use_adaptive_sampling=True if any(v is not None for v in adaptive) else None,
                       adaptive_threshold=args.adaptive_threshold, adaptive_min_samples=args.adaptive_min_samples,
                       adaptive_mode=args.adaptive_mode, shadow_estimator=args.shadow_estimator,
                       use_denoising=True if args.denoise else None)
    return scene


def check_splittable(scene, blend: Path) -> None:
    """A render split into parts needs a fixed sample count and one view layer (a part holds one)."""
    drt = scene.drt
    if drt.use_adaptive_sampling or drt.time_limit > 0 or drt.target_error > 0:
        raise CLIError(f"{blend.name}: a render split into parts needs a fixed sample count: turn off adaptive "
                       "sampling, the time limit and the target error")
    layers = [layer.name for layer in scene.view_layers if layer.use]
    if len(layers) != 1:
        raise CLIError(f"{blend.name}: a render split into parts needs exactly one view layer used for "
                       f"rendering, the scene has {len(layers)}")
