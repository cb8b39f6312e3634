"""The DRT RenderEngine inside Blender: images, passes, view layers, border, errors, progress, cancel.

Scenes are an emissive plane (strength 2) filling the view of a camera 5 m above it,
so every pixel's Combined is exactly 2, its depth exactly 5 and its normal +Z, at
any sample count: the facts below do not depend on noise.
"""
import json
import re
import time
from types import SimpleNamespace

import bpy
import numpy as np
import OpenImageIO as oiio
import pytest

import drt_engine.blender.final as final_module
from drt_engine.core.render import adaptive
from drt_engine.blender.engine import DRTRenderEngine
from drt_engine.blender.final import progress_callback, render_window
from drt_engine.blender.hooks import render_hooks
from drt_engine.blender.properties import result_pass_name
from drt_engine.blender.status import done_line, stats_line
from drt_engine.core.render.render import WAVE, Renderer
from drt_engine.core.scene import DEFAULT_MATERIAL, Camera, Closure, Instance, Material, Mesh, SceneData
from drt_engine.core.settings import CRYPTOMATTE_PASSES, PASSES, RenderSettings, cryptomatte_passes

from tests.support.datablocks import new_compositor

STRENGTH = 2.0
LAYER = "ViewLayer"


def test_engine_is_a_render_engine_subclass(drt):
    assert DRTRenderEngine in bpy.types.RenderEngine.__subclasses__()
    assert DRTRenderEngine.is_registered


def test_render_operator_gives_the_emitted_radiance(bl, tmp_path):
    scene = bl.emission_scene(strength=STRENGTH)
    channels = bl.render_exr(scene, tmp_path / "out.exr")
    combined = bl.pass_pixels(channels, LAYER, "Combined")
    assert combined.shape == (12, 16, 4)
    np.testing.assert_allclose(combined[..., :3], STRENGTH, rtol=1e-4)
    np.testing.assert_allclose(combined[..., 3], 1.0, rtol=1e-5)


def test_persistent_data_reuses_the_prepared_scene_while_only_the_camera_moves(bl, tmp_path):
    """Frames of an animation whose camera alone moves share one prepared scene (Persistent
    Data on, as in Cycles); a changed material prepares anew; Persistent Data off keeps nothing."""
    scene = bl.emission_scene(strength=STRENGTH)
    scene.render.use_persistent_data = True
    camera = scene.camera
    for frame, x in ((1, 0.0), (2, 0.1)):
        camera.location = (x, 0.0, bl.camera_height)
        camera.keyframe_insert("location", frame=frame)
    prepared = []
    for frame in (1, 2):
        scene.frame_set(frame)
        combined = bl.pass_pixels(bl.render_exr(scene, tmp_path / f"f{frame}.exr"), LAYER, "Combined")
        np.testing.assert_allclose(combined[..., :3], STRENGTH, rtol=1e-4)
        prepared.append(render_hooks.persistent[LAYER][1])
    assert prepared[0] is prepared[1]
    emitter = bpy.data.objects["Emitter"].active_material
    emitter.node_tree.nodes["Emission"].inputs["Strength"].default_value = 3.0
    combined = bl.pass_pixels(bl.render_exr(scene, tmp_path / "brighter.exr"), LAYER, "Combined")
    np.testing.assert_allclose(combined[..., :3], 3.0, rtol=1e-4)
    assert render_hooks.persistent[LAYER][1] is not prepared[0]
    scene.render.use_persistent_data = False
    bl.render_exr(scene, tmp_path / "off.exr")
    assert LAYER not in render_hooks.persistent


def test_enabled_passes_are_written_and_disabled_ones_are_not(bl, tmp_path):
    scene = bl.emission_scene(strength=STRENGTH)
    view_layer = scene.view_layers[LAYER]
    view_layer.use_pass_z = True
    view_layer.use_pass_normal = True
    view_layer.drt.use_pass_noise = True
    channels = bl.render_exr(scene, tmp_path / "some.exr")
    assert bl.passes_in(channels, LAYER) == {"Combined", "Depth", "Normal", "Noise"}
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Depth")[..., 0], bl.camera_height, rtol=1e-4)
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Normal"), np.broadcast_to([0, 0, 1], (12, 16, 3)),
                               atol=1e-4)
    noise = bl.pass_pixels(channels, LAYER, "Noise")
    assert np.all(np.isfinite(noise)) and np.all(noise >= 0)


def test_all_passes_are_written_and_finite(bl, tmp_path):
    scene = bl.emission_scene(strength=STRENGTH)
    view_layer = scene.view_layers[LAYER]
    for attr in ("use_pass_z", "use_pass_normal", "use_pass_position", "use_pass_diffuse_color",
                 "use_pass_glossy_color", "use_pass_emit", "use_pass_environment", "use_pass_mist",
                 "use_pass_object_index", "use_pass_material_index", "use_pass_vector",
                 "use_pass_cryptomatte_object", "use_pass_cryptomatte_material", "use_pass_cryptomatte_asset",
                 "use_pass_diffuse_direct", "use_pass_diffuse_indirect", "use_pass_glossy_direct",
                 "use_pass_glossy_indirect", "use_pass_transmission_direct", "use_pass_transmission_indirect",
                 "use_pass_transmission_color"):
        setattr(view_layer, attr, True)
    view_layer.drt.use_pass_sample_count = True
    view_layer.drt.use_pass_noise = True
    view_layer.drt.use_pass_denoising_data = True
    view_layer.cycles.use_pass_shadow_catcher = True  # Cycles' own toggle (1 everywhere without catchers)
    channels = bl.render_exr(scene, tmp_path / "all.exr")
    ranks = [rank for name in CRYPTOMATTE_PASSES for rank in cryptomatte_passes(name, view_layer.pass_cryptomatte_depth)]
    assert bl.passes_in(channels, LAYER) == {result_pass_name(name) for name in PASSES
                                             if name not in CRYPTOMATTE_PASSES} | set(ranks)
    for name in PASSES:
        if name not in CRYPTOMATTE_PASSES:
            assert np.all(np.isfinite(bl.pass_pixels(channels, LAYER, name))), name
    for rank in ranks:
        assert all(np.all(np.isfinite(channels[f"{LAYER}.{rank}.{c}"])) for c in "rgba"), rank
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Emit"), STRENGTH, rtol=1e-4)
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Env"), 0.0, atol=1e-6)
    np.testing.assert_array_equal(bl.pass_pixels(channels, LAYER, "Sample Count"), scene.drt.samples)
    position = bl.pass_pixels(channels, LAYER, "Position")
    np.testing.assert_allclose(position[..., 2], 0.0, atol=1e-4)
    assert np.all(np.abs(position[..., :2]) <= 2.0)


def test_every_view_layer_renders_into_its_own_result(bl, tmp_path):
    world = (0.1, 0.2, 0.3)
    scene = bl.emission_scene(strength=STRENGTH, world=world)
    scene.view_layers[LAYER].use_pass_z = True
    background_only = scene.view_layers.new("Background")
    background_only.layer_collection.children["Subject"].exclude = True
    background_only.use_pass_environment = True
    channels = bl.render_exr(scene, tmp_path / "layers.exr")
    assert bl.passes_in(channels, LAYER) == {"Combined", "Depth"}
    assert bl.passes_in(channels, "Background") == {"Combined", "Env"}
    np.testing.assert_allclose(bl.pass_pixels(channels, LAYER, "Combined")[..., :3], STRENGTH, rtol=1e-4)
    np.testing.assert_allclose(bl.pass_pixels(channels, "Background", "Combined")[..., :3],
                               np.broadcast_to(world, (12, 16, 3)), rtol=1e-4)
    np.testing.assert_allclose(bl.pass_pixels(channels, "Background", "Env"),
                               np.broadcast_to(world, (12, 16, 3)), rtol=1e-4)


@pytest.mark.parametrize("crop", [False, True])
def test_border_render_fills_exactly_blenders_region(bl, tmp_path, crop):
    # Blender computes the region in single precision: 0.7 * 20 = 14 (13 in double precision).
    scene = bl.emission_scene(width=20, height=10, strength=STRENGTH)
    render = scene.render
    render.use_border = True
    render.use_crop_to_border = crop
    render.border_min_x, render.border_max_x = 0.25, 0.7
    render.border_min_y, render.border_max_y = 0.5, 1.0
    assert render_window(render, 20, 10) == (5, 5, 14, 10)
    combined = bl.pass_pixels(bl.render_exr(scene, tmp_path / "border.exr"), LAYER, "Combined")
    if crop:
        assert combined.shape == (5, 9, 4)
        np.testing.assert_allclose(combined[..., :3], STRENGTH, rtol=1e-4)
        return
    assert combined.shape == (10, 20, 4)
    inside = np.zeros((10, 20), bool)
    inside[0:5, 5:14] = True  # file rows run top to bottom: Blender's rows 5..9 are the top five
    np.testing.assert_allclose(combined[inside][:, :3], STRENGTH, rtol=1e-4)
    np.testing.assert_allclose(combined[inside][:, 3], 1.0, rtol=1e-5)
    np.testing.assert_array_equal(combined[~inside], 0.0)


def test_scene_error_is_one_report_without_traceback(bl, tmp_path, capfd):
    scene = bl.emission_scene()
    scene.camera = next(obj for obj in scene.objects if obj.type == "MESH")
    with pytest.raises(RuntimeError) as error:
        bpy.ops.render.render(scene=scene.name)
    message = str(error.value).strip()
    assert "is not a camera object" in message
    assert len(message.splitlines()) == 1
    captured = capfd.readouterr()
    assert "Traceback" not in captured.out + captured.err


def test_unexpected_error_is_one_report(bl, monkeypatch):
    def broken_export(*args, **kwargs):
        raise ValueError("synthetic failure")

    monkeypatch.setattr("drt_engine.blender.export.export_scene", broken_export)
    scene = bl.emission_scene()
    with pytest.raises(RuntimeError) as error:
        bpy.ops.render.render(scene=scene.name)
    message = str(error.value).strip()
    assert len(message.splitlines()) == 1
    assert "ValueError: synthetic failure" in message


def test_export_warnings_are_reported(bl, tmp_path, capfd):
    scene = bl.emission_scene()
    tree = bpy.data.materials["Emitter"].node_tree
    info = tree.nodes.new("ShaderNodePointInfo")  # a node DRT does not evaluate
    tree.links.new(info.outputs["Radius"], tree.nodes["Emission"].inputs["Color"])
    bl.render_exr(scene, tmp_path / "warn.exr")
    out = capfd.readouterr().out
    assert any(line.startswith("Warning:") and "Emitter" in line for line in out.splitlines()), out


class RecordingEngine:
    """Stands in for Blender's side of the engine: Blender's RNA methods cannot be patched on the class."""

    def __init__(self, cancel_after_updates=None):
        self.progress, self.stats, self.displayed = [], [], []
        self.cancel_after_updates = cancel_after_updates

    def update_progress(self, value):
        self.progress.append(value)

    def update_stats(self, stats, info):
        self.stats.append(info)

    def test_break(self):
        return self.cancel_after_updates is not None and len(self.progress) >= self.cancel_after_updates

    def update_result(self, result):
        self.displayed.append(result.layers[0].passes.get("Combined").rect.pixels.copy())


class RecordingResult:
    """A render result whose passes keep what foreach_set wrote."""

    def __init__(self, names):
        passes = {name: SimpleNamespace(rect=_Rect()) for name in names}
        self.layers = [SimpleNamespace(passes=passes)]


class _Rect:
    pixels = None

    def foreach_set(self, values):
        self.pixels = np.array(values)


def emitter_scene_data(size=64):
    """SceneData of the emission scene: a 4x4 m plane of radiance 2 filling a 50 mm camera's view at 5 m."""
    camera_matrix = np.eye(4)
    camera_matrix[2, 3] = 5.0
    half = 18.0 / 50.0
    plane = Mesh("Emitter", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], [(0, 1, 2), (0, 2, 3)], [1])
    emitter = Material("Emitter", [Closure("EMISSION", emission=(STRENGTH,) * 3)])
    return SceneData(Camera(camera_matrix[None], (-half, half, -half, half), (size, size)),
                     meshes=[plane], instances=[Instance(0, np.eye(4))], materials=[DEFAULT_MATERIAL, emitter])


def test_progress_callback_reports_and_refreshes_the_image(monkeypatch):
    monkeypatch.setattr(final_module, "DISPLAY_INTERVAL", 0.0)
    fake, result = RecordingEngine(), RecordingResult(["Combined"])
    samples = 3 * (WAVE // 64**2)  # several checkpoints (1, 2, 4, ... spp) and several waves
    renderer = Renderer(emitter_scene_data(), RenderSettings(samples=samples, threads=1))
    outcome = renderer.render(progress=progress_callback(fake, result))
    assert not outcome.cancelled
    assert len(fake.progress) >= 3
    assert all(0 < a < b for a, b in zip(fake.progress, fake.progress[1:]))
    assert fake.progress[-1] == pytest.approx(1.0)
    first = adaptive.next_checkpoint(adaptive.checkpoints(samples, samples), 0, 64 * 64, samples)
    # the emitter is noiseless: the estimated error is known from the first checkpoint on
    assert re.fullmatch(rf"Sample {first}/{samples} \| est\. error 0% \| \d+\.\d s", fake.stats[0]), fake.stats[0]
    assert len(fake.displayed) == len(fake.progress)
    for image in fake.displayed:
        np.testing.assert_allclose(image.reshape(64, 64, 4)[..., :3], STRENGTH, rtol=1e-4)


def test_cancel_returns_promptly_with_the_image_so_far():
    fake = RecordingEngine(cancel_after_updates=1)
    result = RecordingResult(["Combined", "Sample Count"])
    settings = RenderSettings(samples=1_000_000, threads=1, passes=("Combined", "Sample Count"))
    renderer = Renderer(emitter_scene_data(), settings)  # hours of work if it were not cancelled
    start = time.perf_counter()
    outcome = renderer.render(progress=progress_callback(fake, result))
    assert time.perf_counter() - start < 10.0
    assert outcome.cancelled and len(fake.progress) == 1
    np.testing.assert_allclose(outcome.passes["Combined"][..., :3], STRENGTH, rtol=1e-4)
    counts = outcome.passes["Sample Count"]
    first = adaptive.next_checkpoint(adaptive.checkpoints(settings.samples, settings.samples), 0, 64 * 64,
                                     settings.samples)
    assert np.all(counts == first)  # the first checkpoint (the same samples in every pixel), then the stop


def test_pass_toggles_update_the_compositor_sockets(bl):
    scene = bl.emission_scene()
    node = new_compositor(scene).nodes.new("CompositorNodeRLayers")
    node.scene, node.layer = scene, LAYER
    view_layer = scene.view_layers[LAYER]

    def sockets():
        return {socket.name for socket in node.outputs if socket.enabled}

    assert sockets() == {"Image", "Alpha"}
    view_layer.drt.use_pass_noise = True
    view_layer.drt.use_pass_sample_count = True
    view_layer.use_pass_normal = True
    assert sockets() == {"Image", "Alpha", "Noise", "Sample Count", "Normal"}
    view_layer.drt.use_pass_noise = False
    assert sockets() == {"Image", "Alpha", "Sample Count", "Normal"}


def test_adaptive_render_reports_its_error_log_in_the_metadata(bl, tmp_path):
    scene = bl.emission_scene(samples=64)
    scene.drt.use_adaptive_sampling = True
    scene.drt.adaptive_min_samples = 8
    render_hooks.last_reports.clear()
    path = tmp_path / "adaptive.exr"
    bl.render_exr(scene, path)
    image = oiio.ImageInput.open(str(path))
    metadata = {a.name: a.value for a in image.spec().extra_attribs}
    image.close()
    # a noiseless emitter: every pixel converges at the first test
    assert metadata[f"drt.{LAYER}.stopped_by"] == "threshold"
    assert metadata[f"drt.{LAYER}.samples"] == str(adaptive.first_test(8))
    log = json.loads(metadata[f"drt.{LAYER}.error_log"])
    report = render_hooks.last_reports[LAYER]
    assert log == report["log"] and log[-1]["stopped"] == "threshold"
    assert report["settings"]["use_adaptive_sampling"] and report["settings"]["adaptive_mode"] == "NOISE"
    assert report["scene"]["resolution"] == [16, 12] and report["view_layer"] == LAYER


def test_done_line_says_what_stopped_the_render():
    renderer = Renderer(emitter_scene_data(16), RenderSettings(samples=64, threads=1, use_adaptive_sampling=True,
                                                                adaptive_min_samples=8))
    outcome = renderer.render()
    line = done_line(outcome.stats, outcome.cancelled)
    assert re.fullmatch(r"Done \| 8 samples \(mean 8\.0\) \| est\. error 0% \| \d+\.\d\d s "
                        r"\| stopped by noise threshold \| plan: .+", line), line
    assert stats_line(12, 64, 6.4e-5, 12.34) == "Sample 12/64 | est. error 0.8% | 12.3 s"
    assert stats_line(1, 64, float("inf"), 0.0) == "Sample 1/64 | est. error ? | 0.0 s"
