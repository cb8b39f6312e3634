"""Render the in-memory scene with DRT or with Cycles through ``bpy.ops.render.render`` and read
the written EXR back as float arrays, so DRT and Cycles are compared like for like.

Cycles is set up the way DRT traces light (distribution ray tracing): no indirect diffuse
light, glossy and transmission chains as long as ``scene.drt.max_depth``, no glossy
blur, no clamping, no denoising, no adaptive sampling, CPU, and DRT's pixel filter.
Nothing here saves the .blend: settings change only the scene in memory.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np
import OpenImageIO as oiio

ROOT = Path(__file__).resolve().parents[2]

PASS_TOGGLES = {
    "Depth": ("use_pass_z", "Z"),
    "Normal": ("use_pass_normal", "XYZ"),
    "DiffCol": ("use_pass_diffuse_color", "RGB"),
    "GlossCol": ("use_pass_glossy_color", "RGB"),
    "DiffDir": ("use_pass_diffuse_direct", "RGB"),
    "DiffInd": ("use_pass_diffuse_indirect", "RGB"),
    "GlossDir": ("use_pass_glossy_direct", "RGB"),
    "GlossInd": ("use_pass_glossy_indirect", "RGB"),
    "TransDir": ("use_pass_transmission_direct", "RGB"),
    "TransInd": ("use_pass_transmission_indirect", "RGB"),
    "TransCol": ("use_pass_transmission_color", "RGB"),
    "Emit": ("use_pass_emit", "RGB"),
    "Env": ("use_pass_environment", "RGB"),
    "Mist": ("use_pass_mist", "Z"),
    "IndexOB": ("use_pass_object_index", "X"),
    "IndexMA": ("use_pass_material_index", "X"),
    "Vector": ("use_pass_vector", "XYZW"),
}
"""Passes both renderers write, by Blender's view-layer toggle and channel ids."""

BLENDER5_NAMES = {"DiffCol": "Diffuse Color", "GlossCol": "Glossy Color", "Emit": "Emission", "Env": "Environment",
                  "IndexOB": "Object Index", "IndexMA": "Material Index", "DiffDir": "Diffuse Direct",
                  "DiffInd": "Diffuse Indirect", "GlossDir": "Glossy Direct", "GlossInd": "Glossy Indirect",
                  "TransDir": "Transmission Direct", "TransInd": "Transmission Indirect",
                  "TransCol": "Transmission Color"}
"""Names Cycles in Blender 5.0 writes for the passes Blender 4 (and DRT) call by their short names."""


@dataclass
class Render:
    """One render: ``passes`` name -> (h, w, C) float32, top row first; wall time in seconds."""

    passes: dict
    seconds: float
    samples: int

    @property
    def rgb(self) -> np.ndarray:
        return self.passes["Combined"][..., :3]


def open_scene(path) -> bpy.types.Scene:
    """Load a .blend into this bpy session (the file on disk is never written)."""
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    return bpy.context.scene


def set_resolution(scene, width: int, height: int) -> None:
    render = scene.render
    render.resolution_x, render.resolution_y = width, height
    render.resolution_percentage = 100
    render.use_border = False


def configure_cycles(scene, samples: int, seed: int, threshold: float | None = None) -> None:
    """Cycles as a distribution ray tracer with DRT's Light Paths (Total, diffuse, glossy and
    transmission bounces), filter and no noise tricks; with a ``threshold``, its adaptive sampling
    at that noise threshold and automatic min samples (the benchmark's "Cycles adaptive")."""
    cycles = scene.cycles
    depth = scene.drt.max_depth
    cycles.device = "CPU"
    cycles.samples = samples
    cycles.seed = seed
    cycles.use_animated_seed = False
    cycles.use_adaptive_sampling = threshold is not None
    if threshold is not None:
        cycles.adaptive_threshold = threshold
        cycles.adaptive_min_samples = 0
    cycles.time_limit = 0.0
    cycles.use_denoising = False
    cycles.diffuse_bounces = scene.drt.diffuse_bounces
    cycles.min_light_bounces = scene.drt.min_light_bounces
    cycles.min_transparent_bounces = scene.drt.min_transparent_bounces
    cycles.glossy_bounces = scene.drt.glossy_bounces
    cycles.transmission_bounces = scene.drt.transmission_bounces
    cycles.transparent_max_bounces = scene.drt.max_transparent_bounces
    cycles.volume_bounces = 0
    cycles.max_bounces = depth
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    cycles.blur_glossy = scene.drt.filter_glossy
    cycles.sample_clamp_direct = scene.drt.sample_clamp_direct
    cycles.sample_clamp_indirect = scene.drt.sample_clamp_indirect
    cycles.pixel_filter_type = scene.drt.filter_type
    cycles.filter_width = scene.render.filter_size


def configure_drt(scene, samples: int, seed: int) -> None:
    drt = scene.drt
    drt.samples = samples
    drt.seed = seed
    drt.use_adaptive_sampling = False
    drt.time_limit = 0.0
    drt.target_error = 0.0


def render(scene, engine: str, samples: int, seed: int, out_dir, passes=(), name="render") -> Render:
    """Render ``scene`` with ``engine`` ('DRT' or 'CYCLES') to a multilayer EXR and read it back, with
    the view layer's shader AOVs and light groups (by name, channels as Cycles registers them)."""
    if engine == "CYCLES":
        configure_cycles(scene, samples, seed)
    else:
        configure_drt(scene, samples, seed)
    scene.render.engine = engine
    view_layer = scene.view_layers[0]
    for layer in scene.view_layers:
        layer.use = layer == view_layer
    for pass_name, (toggle, _) in PASS_TOGGLES.items():
        setattr(view_layer, toggle, pass_name in passes)
    path = set_exr_output(scene, Path(out_dir) / f"{name}-{engine.lower()}-{seed}.exr")
    start = time.perf_counter()
    result = bpy.ops.render.render(write_still=True, scene=scene.name)
    seconds = time.perf_counter() - start
    assert result == {"FINISHED"} and path.exists(), f"{engine} did not write {path}"
    channels = read_channels(path)
    images = {"Combined": _pass(channels, view_layer.name, "Combined", "RGBA")}
    for pass_name in passes:
        images[pass_name] = _pass(channels, view_layer.name, pass_name, PASS_TOGGLES[pass_name][1])
    for aov in view_layer.aovs:
        images[aov.name] = _pass(channels, view_layer.name, aov.name, "RGBA" if aov.type == "COLOR" else "X")
    for group in view_layer.lightgroups:  # Cycles' light group passes, Combined_<group> (RGB)
        name = f"Combined_{group.name}"
        images[name] = _pass(channels, view_layer.name, name, "RGB")
    return Render(images, seconds, samples)


def set_exr_output(scene, path: Path) -> Path:
    """Write renders of ``scene`` to ``path`` as a 32-bit multilayer EXR (in memory only)."""
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # Blender 5.0+
        settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    return path


def read_channels(path) -> dict:
    """Every channel of an EXR, all parts (Blender 5 writes one part per pass): name -> (h, w)."""
    image = oiio.ImageInput.open(str(path))
    assert image is not None, oiio.geterror()
    channels = {}
    try:
        index = 0
        while image.seek_subimage(index, 0):
            spec = image.spec()
            pixels = image.read_image(format="float").reshape(spec.height, spec.width, spec.nchannels)
            for c, channel in enumerate(spec.channelnames):
                channels[channel] = pixels[..., c]
            index += 1
    finally:
        image.close()
    return channels


def _pass(channels: dict, layer: str, name: str, ids: str) -> np.ndarray:
    if f"{layer}.{name}.{ids[0]}" not in channels and name in BLENDER5_NAMES:
        name = BLENDER5_NAMES[name]
    keys = [f"{layer}.{name}.{c}" for c in ids]
    missing = [k for k in keys if k not in channels]
    assert not missing, f"channels {missing} not in the file: {sorted(channels)}"
    return np.stack([channels[k] for k in keys], axis=-1)


COMPARE_DIR = ROOT / "out" / "compare"
"""Side-by-side images of the comparisons (the repository's out/ is git-ignored)."""


def save_side_by_side(name: str, left: np.ndarray, right: np.ndarray, folder=COMPARE_DIR) -> Path:
    """PNG of ``left | right | |left - right| x 10`` (RGB, top row first), for looking at by eye.

    One exposure for all three panels: the right image's 99th percentile maps to white, then
    the sRGB transfer curve; 2-pixel grey gaps separate the panels.
    """
    scale = 1.0 / max(float(np.percentile(right, 99)), 1e-6)
    diff = 10.0 * np.abs(left - right)
    gap = np.full((left.shape[0], 2, 3), 0.5)
    panels = [np.clip(image * scale, 0.0, 1.0) for image in (left, right, diff)]
    linear = np.concatenate([panels[0], gap, panels[1], gap, panels[2]], axis=1)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.png"
    pixels = np.ascontiguousarray((srgb * 255 + 0.5).astype(np.uint8))
    output = oiio.ImageOutput.create(str(path))
    assert output is not None, oiio.geterror()
    output.open(str(path), oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, "uint8"))
    output.write_image(pixels)
    output.close()
    return path


def environment_texture(world, path: str, rotation_z: float, strength: float, interpolation="Linear"):
    """Feed ``world``'s Background from an Environment Texture of the image at ``path``, through
    a Mapping turned by ``rotation_z`` (radians) about Z, at ``strength``."""
    tree = world.node_tree
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(path)
    env.interpolation = interpolation
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    background = tree.nodes["Background"]
    background.inputs["Strength"].default_value = strength
    tree.links.new(env.outputs["Color"], background.inputs["Color"])
