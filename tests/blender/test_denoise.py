"""Blender's compositor Denoise node takes DRT's Image, Denoising Albedo and Denoising Normal as
it takes Cycles': the passes hold what Cycles writes there, and denoising a 16-sample render
brings it closer to a 1024-sample one (OpenImageDenoise is in the bpy 5.0 wheel's compositor;
Debian's Blender 4.3 has none, so this runs here)."""
import json
import math

import bpy
import numpy as np
import pytest

from tests.support.datablocks import new_compositor, new_material
from tests.support.render_helpers import ROOT, read_channels, save_side_by_side, set_exr_output, set_resolution

LAYER = "ViewLayer"
COLOUR = (0.2, 0.4, 0.6)
TINT = (0.9, 0.5, 0.7)
NOISY_SPP, REFERENCE_SPP, RESOLUTION = 16, 1024, 96
UI_DIR = ROOT / "out" / "ui"


def _plane(name, half, z, material, x=0.0, facing_down=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = (x, 0.0, z)
    if facing_down:
        obj.rotation_euler = (math.pi, 0.0, 0.0)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _bsdf_material(name, node_type, color, roughness=None):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new(node_type)
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    if roughness is not None:
        bsdf.inputs["Roughness"].default_value = roughness
    tree.links.new(bsdf.outputs[0], tree.nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    return mat


def mirror_and_paint_scene():
    """Camera 2 m above a floor: left half a tinted mirror, right half diffuse paint; 3 m up a
    diffuse ceiling facing down, which the mirror shows. Tilted about x so normals are not axes."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    set_resolution(scene, 16, 8)
    paint = _bsdf_material("Paint", "ShaderNodeBsdfDiffuse", COLOUR)
    _plane("Mirror", 2.0, 0.0, _bsdf_material("Mirror", "ShaderNodeBsdfGlossy", TINT, roughness=0.0), x=-2.0)
    _plane("Paint", 2.0, 0.0, paint, x=2.0)
    _plane("Ceiling", 20.0, 3.0, _bsdf_material("Ceiling", "ShaderNodeBsdfDiffuse", (0.8, 0.6, 0.4)),
           facing_down=True)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, 0.0, 2.0)
    camera.rotation_euler = (0.1, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def denoising_passes(scene, engine, tmp_path):
    """(albedo, normal) of a render of ``scene`` by ``engine`` with its denoising data on."""
    scene.render.engine = engine
    view_layer = scene.view_layers[LAYER]
    if engine == "CYCLES":
        scene.cycles.device, scene.cycles.samples, scene.cycles.use_denoising = "CPU", 4, False
        view_layer.cycles.denoising_store_passes = True
    else:
        scene.drt.samples = 4
        view_layer.drt.use_pass_denoising_data = True
    path = set_exr_output(scene, tmp_path / f"{engine}.exr")
    assert bpy.ops.render.render(write_still=True, scene=scene.name) == {"FINISHED"}
    channels = read_channels(path)
    return tuple(np.stack([channels[f"{LAYER}.{name}.{c}"] for c in ids], axis=-1)
                 for name, ids in (("Denoising Albedo", "RGB"), ("Denoising Normal", "XYZ")))


def test_denoising_passes_match_cycles(drt, tmp_path):
    """Diffuse paint: its colour and its normal in Cycles' camera space; the mirror: its tint
    times the ceiling's colour, the ceiling's normal. Columns next to the seam mix both."""
    scene = mirror_and_paint_scene()
    drt_albedo, drt_normal = denoising_passes(scene, "DRT", tmp_path)
    cycles_albedo, cycles_normal = denoising_passes(scene, "CYCLES", tmp_path)
    inner = np.r_[0:6, 10:16]
    np.testing.assert_allclose(drt_albedo[:, 10:], np.broadcast_to(COLOUR, (8, 6, 3)), atol=1e-4)
    np.testing.assert_allclose(drt_albedo[:, :6], np.broadcast_to(np.multiply(TINT, (0.8, 0.6, 0.4)), (8, 6, 3)),
                               atol=0.02)
    np.testing.assert_allclose(drt_albedo[:, inner], cycles_albedo[:, inner], atol=0.02)
    np.testing.assert_allclose(drt_normal[:, inner], cycles_normal[:, inner], atol=1e-3)
    assert abs(drt_normal[0, 12, 1]) > 0.05  # the tilt shows: not a normal along an axis


def test_the_toggle_adds_both_sockets_to_render_layers(drt):
    scene = mirror_and_paint_scene()
    scene.render.engine = "DRT"
    node = new_compositor(scene).nodes.new("CompositorNodeRLayers")
    node.scene, node.layer = scene, LAYER
    names = {"Denoising Albedo", "Denoising Normal"}
    assert not names & {s.name for s in node.outputs if s.enabled}
    scene.view_layers[LAYER].drt.use_pass_denoising_data = True
    assert names <= {s.name for s in node.outputs if s.enabled}


def _denoise_compositor(scene):
    """Render Layers (Image, Denoising Albedo, Denoising Normal) -> Denoise -> the composite
    output (Composite node in 4.x, the group output in 5.0), as Cycles users wire it."""
    tree = new_compositor(scene)
    layers = tree.nodes.new("CompositorNodeRLayers")
    layers.scene, layers.layer = scene, LAYER
    denoise = tree.nodes.new("CompositorNodeDenoise")
    for output, socket in (("Image", "Image"), ("Denoising Albedo", "Albedo"), ("Denoising Normal", "Normal")):
        tree.links.new(layers.outputs[output], denoise.inputs[socket])
    if hasattr(scene, "compositing_node_group"):
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        tree.links.new(denoise.outputs["Image"], tree.nodes.new("NodeGroupOutput").inputs[0])
    else:
        tree.links.new(denoise.outputs["Image"], tree.nodes.new("CompositorNodeComposite").inputs["Image"])


def relmse(image, reference):
    """Mean relative squared error over pixels and channels, (x - ref)^2 / (ref^2 + 0.01)."""
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 1e-2)))


def test_denoise_node_brings_16_samples_closer_to_1024(drt, sample_scene, tmp_path):
    bpy.ops.wm.open_mainfile(filepath=str(sample_scene("cornell_box")), load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    set_resolution(scene, RESOLUTION, RESOLUTION)
    drt = scene.drt
    drt.use_adaptive_sampling, drt.time_limit, drt.target_error, drt.seed = False, 0.0, 0.0, 1
    scene.view_layers[LAYER].drt.use_pass_denoising_data = True
    _denoise_compositor(scene)
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):
        settings.media_type = "IMAGE"
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    scene.render.use_file_extension = False

    def render(name, samples, composite):
        drt.samples = samples
        scene.render.use_compositing = composite
        scene.render.filepath = str(tmp_path / f"{name}.exr")
        assert bpy.ops.render.render(write_still=True, scene=scene.name) == {"FINISHED"}
        channels = read_channels(scene.render.filepath)
        return np.stack([channels[c] for c in "RGB"], axis=-1)

    denoised = render("denoised", NOISY_SPP, True)
    noisy = render("noisy", NOISY_SPP, False)  # the same samples (fixed seed), not composited
    reference = render("reference", REFERENCE_SPP, False)
    assert not np.array_equal(denoised, noisy), "the Denoise node did not change the image"
    noisy_error, denoised_error = relmse(noisy, reference), relmse(denoised, reference)
    UI_DIR.mkdir(parents=True, exist_ok=True)
    save_side_by_side("denoise_noisy_16spp", noisy, reference, folder=UI_DIR)
    save_side_by_side("denoise_denoised_16spp", denoised, reference, folder=UI_DIR)
    (UI_DIR / "denoise.json").write_text(json.dumps({
        "scene": "cornell_box", "resolution": RESOLUTION, "samples": NOISY_SPP, "reference_samples": REFERENCE_SPP,
        "blender": bpy.app.version_string, "relmse_noisy": noisy_error, "relmse_denoised": denoised_error,
        "ratio": noisy_error / denoised_error}, indent=2) + "\n")
    print(f"relMSE 16 spp noisy {noisy_error:.3g}, denoised {denoised_error:.3g}, "
          f"ratio {noisy_error / denoised_error:.2f}")
    assert denoised_error < noisy_error


def test_the_cli_exr_carries_the_passes(bl, tmp_path):
    """An emitter seen by the camera: its emission is the albedo (Cycles adds emission met while
    the features are open) and, without a BSDF, the normal is zero."""
    from test_cli import run_cli

    scene = bl.emission_scene(strength=0.5, samples=2)
    scene.view_layers[LAYER].drt.use_pass_denoising_data = True
    blend = tmp_path / "scene.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out = tmp_path / "out.exr"
    result = run_cli("render", blend, "-o", out)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    channels = bl.read_channels(out)
    assert {"Denoising Albedo", "Denoising Normal"} <= bl.passes_in(channels, LAYER)
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Denoising Albedo"), 0.5, rtol=1e-5)
    np.testing.assert_array_equal(bl.pass_pixels(channels, LAYER, "Denoising Normal"), 0.0)


# -- Denoising built in (scene.drt.use_denoising) ----------------------------------------------

class _Recorder:
    """Stands in for a UILayout: records what a panel's draw asks of it."""

    def __init__(self, log):
        self.log = log
        self.enabled = self.active = True

    def _child(self):
        child = _Recorder(self.log)
        self.log.append(child)
        return child

    row = column = lambda self, **kw: self._child()

    def prop(self, data, name, **kw):
        self.log.append(("prop", name, self))

    def label(self, text="", **kw):
        self.log.append(("label", text, self))


def _draw(panel, scene):
    from types import SimpleNamespace

    log = []
    panel.draw(SimpleNamespace(layout=_Recorder(log)), SimpleNamespace(scene=scene))
    props = {entry[1]: entry[2] for entry in log if isinstance(entry, tuple) and entry[0] == "prop"}
    labels = [entry[1] for entry in log if isinstance(entry, tuple) and entry[0] == "label"]
    return props, labels


def test_the_denoise_setting_greys_out_with_the_reason_where_blender_has_no_oidn(drt, monkeypatch):
    from drt_engine.blender import oidn
    from drt_engine.blender.ui import DRT_PT_sampling_denoise

    scene = bpy.context.scene
    names = ("use_denoising", "use_preview_denoising", "denoising_prefilter", "denoising_quality",
             "preview_denoising_prefilter", "preview_denoising_quality", "preview_denoising_start_sample")
    assert oidn.oidn_library() is not None  # the bpy 5.0 wheel ships it
    props, labels = _draw(DRT_PT_sampling_denoise, scene)
    assert all(props[name].enabled for name in names) and not labels
    monkeypatch.setattr(oidn, "search", lambda: None)  # as in Debian's Blender 4.3.2
    props, labels = _draw(DRT_PT_sampling_denoise, scene)
    assert not any(props[name].enabled for name in names)
    assert labels == [oidn.UNAVAILABLE] and "OpenImageDenoise" in labels[0]


def _denoise_scene(sample_scene):
    bpy.ops.wm.open_mainfile(filepath=str(sample_scene("cornell_box")), load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    set_resolution(scene, 48, 48)
    drt = scene.drt
    drt.samples, drt.seed, drt.use_adaptive_sampling, drt.time_limit, drt.target_error = 8, 1, False, 0.0, 0.0
    return scene


def _render_passes(scene, path):
    set_exr_output(scene, path)
    assert bpy.ops.render.render(write_still=True, scene=scene.name) == {"FINISHED"}
    channels = read_channels(path)
    layer_passes = {key[len(LAYER) + 1:].rsplit(".", 1)[0] for key in channels if key.startswith(LAYER + ".")}
    return channels, layer_passes


def _rgba(channels, name):
    return np.stack([channels[f"{LAYER}.{name}.{c}"] for c in "RGBA"], axis=-1)


def test_a_denoised_render_keeps_the_render_as_noisy_image(drt, sample_scene, tmp_path):
    from drt_engine.blender.hooks import render_hooks
    from drt_engine.blender.status import done_line

    scene = _denoise_scene(sample_scene)
    plain, plain_passes = _render_passes(scene, tmp_path / "plain.exr")
    assert "Noisy Image" not in plain_passes
    scene.drt.use_denoising = True
    denoised, passes = _render_passes(scene, tmp_path / "denoised.exr")
    assert passes == {"Combined", "Noisy Image"}  # the features guide OIDN but are not written
    np.testing.assert_array_equal(_rgba(denoised, "Noisy Image"), _rgba(plain, "Combined"))
    assert not np.array_equal(_rgba(denoised, "Combined")[..., :3], _rgba(plain, "Combined")[..., :3])
    stats = render_hooks.last_reports[LAYER]["stats"]
    assert 0 < stats["relmse_denoised"] < stats["relmse"]
    assert stats["denoising"] == {"prefilter": "ACCURATE", "quality": "HIGH", "seconds": stats["denoising"]["seconds"]}
    assert render_hooks.last_reports[LAYER]["log"][-1]["relmse_denoised"] == stats["relmse_denoised"]
    assert render_hooks.last_reports[LAYER]["settings"]["use_denoising"] is True
    assert "(denoised " in done_line(stats, False)
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(tmp_path / "denoised.exr"))
    metadata = {a.name: a.value for a in image.spec().extra_attribs}
    image.close()
    assert float(metadata[f"drt.{LAYER}.est_relmse_denoised"]) == pytest.approx(stats["relmse_denoised"], rel=1e-5)


def test_without_oidn_a_denoised_render_is_a_warning_and_the_noisy_image(drt, sample_scene, tmp_path, monkeypatch):
    from drt_engine.blender import final, oidn
    from drt_engine.blender.hooks import render_hooks

    warnings = []
    monkeypatch.setattr(oidn, "search", lambda: None)
    monkeypatch.setattr(final, "_warn", lambda engine, messages: warnings.extend(messages))
    scene = _denoise_scene(sample_scene)
    scene.drt.use_denoising = True
    _, passes = _render_passes(scene, tmp_path / "no_oidn.exr")
    assert passes == {"Combined"}
    assert f"{oidn.UNAVAILABLE}; the image is not denoised" in warnings
    assert "relmse_denoised" not in render_hooks.last_reports[LAYER]["stats"]


def test_denoising_adds_the_noisy_image_socket_to_render_layers(drt):
    scene = mirror_and_paint_scene()
    scene.render.engine = "DRT"
    node = new_compositor(scene).nodes.new("CompositorNodeRLayers")
    node.scene, node.layer = scene, LAYER
    assert "Noisy Image" not in {s.name for s in node.outputs if s.enabled}
    scene.drt.use_denoising = True
    assert "Noisy Image" in {s.name for s in node.outputs if s.enabled}
    scene.drt.use_denoising = False
    assert "Noisy Image" not in {s.name for s in node.outputs if s.enabled}


def test_the_cli_denoises_a_scene_saved_with_denoise_on(drt, sample_scene, tmp_path):
    """No --denoise flag yet: the scene's own setting is what the CLI renders with."""
    from test_cli import run_cli

    scene = _denoise_scene(sample_scene)
    scene.drt.samples, scene.drt.use_denoising = 4, True
    blend = tmp_path / "scene.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out = tmp_path / "out.exr"
    result = run_cli("render", blend, "-o", out)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert f"{LAYER}.Noisy Image.R" in read_channels(out)
    stats = json.loads((tmp_path / "out.drt.json").read_text())["stats"]
    assert 0 < stats["relmse_denoised"] < stats["relmse"]


def test_the_viewport_denoises_only_when_asked_and_where_blender_has_oidn(drt, monkeypatch):
    from drt_engine.blender import oidn
    from drt_engine.blender.viewport import ViewDenoise, view_denoise

    scene = bpy.context.scene
    scene.drt.use_preview_denoising, scene.drt.preview_denoising_start_sample = False, 3
    assert view_denoise(scene) is None
    scene.drt.use_preview_denoising = True
    denoise = view_denoise(scene)
    assert isinstance(denoise, ViewDenoise) and denoise.start_sample == 3
    assert (denoise.prefilter, denoise.quality) == ("FAST", "BALANCED")  # Cycles' viewport defaults
    scene.drt.preview_denoising_prefilter, scene.drt.preview_denoising_quality = "ACCURATE", "FAST"
    assert (view_denoise(scene).prefilter, view_denoise(scene).quality) == ("ACCURATE", "FAST")
    monkeypatch.setattr(oidn, "search", lambda: None)
    assert view_denoise(scene) is None


def test_the_settings_choices_are_the_cores(drt):
    from drt_engine.core.settings import DENOISING_PREFILTERS, DENOISING_QUALITIES

    props = bpy.types.Scene.bl_rna.properties["drt"].fixed_type.properties
    for name in ("denoising_prefilter", "preview_denoising_prefilter"):
        assert tuple(i.identifier for i in props[name].enum_items) == DENOISING_PREFILTERS
    for name in ("denoising_quality", "preview_denoising_quality"):
        assert tuple(i.identifier for i in props[name].enum_items) == DENOISING_QUALITIES
    assert props["use_denoising"].default is False and props["denoising_prefilter"].default == "ACCURATE"
