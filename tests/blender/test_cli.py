"""``python -m drt_engine render``: real subprocesses on small .blend files written by the test.

Success writes the file and nothing on stderr; bad input exits non-zero with exactly
one line on stderr (Blender's own chatter goes to stdout).
"""
import hashlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from drt_engine.headless.errors import EXIT_ERROR, EXIT_USAGE

ROOT = Path(__file__).resolve().parents[2]
STRENGTH = 0.5


def run_cli(*args, timeout=120, env=None):
    return subprocess.run(
        [sys.executable, "-m", "drt_engine", *map(str, args)],
        cwd=ROOT, capture_output=True, text=True, timeout=timeout, env=env,
    )


def assert_one_line_error(result, *words):
    assert result.returncode in (EXIT_ERROR, EXIT_USAGE), (result.returncode, result.stdout[-2000:])
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("drt: error:")
    for word in words:
        assert word in lines[0]


@pytest.fixture
def blend(bl, tmp_path):
    """An emitter of strength 0.5 filling the view, 16x12, Depth and Noise enabled, Standard view."""
    scene = bl.emission_scene(strength=STRENGTH, samples=2)
    scene.view_layers["ViewLayer"].use_pass_z = True
    scene.view_layers["ViewLayer"].drt.use_pass_noise = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    path = tmp_path / "scene.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def test_help():
    result = run_cli("render", "--help", timeout=60)
    assert result.returncode == 0
    for option in ("--samples", "--seed", "--frame", "--resolution", "--engine-threads", "-o", "--time-limit",
                   "--target-error", "--adaptive-threshold", "--adaptive-min-samples", "--adaptive-mode",
                   "--shadow-estimator", "--denoise"):
        assert option in result.stdout
    assert result.stderr == ""


def test_render_to_multilayer_exr_with_overrides(bl, blend, tmp_path):
    before = hashlib.sha256(blend.read_bytes()).hexdigest()
    out = tmp_path / "new folder" / "out.exr"
    result = run_cli("render", blend, "-o", out, "--samples", 3, "--seed", 5, "--resolution", "20x8",
                     "--engine-threads", 1, "--frame", 1)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert result.stderr == ""
    channels = bl.read_channels(out)
    assert bl.passes_in(channels, "ViewLayer") == {"Combined", "Depth", "Noise"}
    combined = bl.pass_pixels(channels, "ViewLayer", "Combined")
    assert combined.shape == (8, 20, 4)
    np.testing.assert_allclose(combined[..., :3], STRENGTH, rtol=1e-4)
    np.testing.assert_allclose(bl.pass_pixels(channels, "ViewLayer", "Depth"), bl.camera_height, rtol=1e-4)
    assert hashlib.sha256(blend.read_bytes()).hexdigest() == before


def test_render_to_png_through_the_view_transform(bl, blend, tmp_path):
    out = tmp_path / "out.png"
    result = run_cli("render", blend, "-o", out)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert result.stderr == ""
    # the render plan and the rays by kind reach the output: an emitter needs no shadow rays
    assert "DRT: plan: dims pixel;" in result.stdout and "left out: lens (aperture 0)" in result.stdout
    assert f"DRT: rays traced: camera {16 * 12 * 2}, shadow 0," in result.stdout, result.stdout[-2000:]
    channels = bl.read_channels(out)
    rgb = np.stack([channels[c] for c in "RGB"], axis=-1)
    assert rgb.shape == (12, 16, 3)
    srgb = 1.055 * STRENGTH ** (1 / 2.4) - 0.055  # Standard view: the sRGB curve, 0.5 -> 0.735
    np.testing.assert_allclose(rgb, srgb, atol=2 / 255)


def test_the_first_render_of_an_install_says_it_compiles_the_kernels(blend, tmp_path):
    """With an empty kernel cache the output names the wait once; the next render loads the cache."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "kernels"))
    message = "DRT: Compiling DRT kernels (first run only)"
    first = run_cli("render", blend, "-o", tmp_path / "a.png", env=env)
    assert first.returncode == 0 and first.stderr == "", first.stdout[-2000:] + first.stderr
    assert first.stdout.count(message) == 1
    second = run_cli("render", blend, "-o", tmp_path / "b.png", env=env)
    assert second.returncode == 0 and message not in second.stdout


def test_every_render_writes_its_report_and_plot(bl, blend, tmp_path):
    out = tmp_path / "out.exr"
    result = run_cli("render", blend, "-o", out, "--resolution", "128x96", "--samples", 32, "--time-limit", 60,
                     "--target-error", 0, "--adaptive-threshold", 0.05, "--adaptive-min-samples", 8,
                     "--adaptive-mode", "noise", "--shadow-estimator", "ratio")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert result.stderr == ""
    report = json.loads((tmp_path / "out.drt.json").read_text())
    assert report["file"] == str(blend)
    settings = report["settings"]
    assert settings["use_adaptive_sampling"] and settings["adaptive_mode"] == "NOISE"
    assert settings["shadow_estimator"] == "RATIO"
    assert settings["time_limit"] == 60 and settings["samples"] == 32
    assert settings["adaptive_threshold"] == pytest.approx(0.05) and settings["adaptive_min_samples"] == 8
    assert report["scene"]["resolution"] == [128, 96] and report["scene"]["triangles"] == 2
    log = report["log"]
    assert len(log) >= 3
    for key in ("elapsed", "samples", "spp_max"):
        values = [entry[key] for entry in log]
        assert all(a < b for a, b in zip(values, values[1:])), (key, values)
    # a noiseless emitter: every pixel converges at the first test, after the 8 minimum samples
    assert log[-1]["samples"] == report["stats"]["rays"]["camera"] == 128 * 96 * 8
    assert log[-1]["stopped"] == report["stats"]["stopped_by"] == "threshold"
    plot = bl.read_channels(tmp_path / "out.error.png")
    assert plot["R"].shape == (420, 640)
    assert plot["R"].min() < 0.5  # axes and curves drawn on the white page
    # not a terminal: the live progress comes as plain lines, the first as the render starts
    progress = [line for line in result.stdout.splitlines() if line.startswith("DRT: Sample ")]
    assert progress and "\r" not in result.stdout
    assert re.fullmatch(r"DRT: Sample \d+/32 \| est\. error \S+ \| [\d.]+ s( \| ~\d+ s left to the .+)?", progress[0])


@pytest.mark.parametrize("option, value", [("--time-limit", "-1"), ("--target-error", "abc"),
                                           ("--adaptive-threshold", "2"), ("--adaptive-threshold", "nan"),
                                           ("--adaptive-min-samples", "-4"), ("--adaptive-mode", "FAST"),
                                           ("--shadow-estimator", "EXACT")])
def test_bad_stop_rule_values(blend, tmp_path, option, value):
    out = tmp_path / "o.exr"
    assert_one_line_error(run_cli("render", blend, "-o", out, option, value), option)
    assert not out.exists() and not (tmp_path / "o.drt.json").exists()


def test_frame_override_moves_to_that_frame(bl, tmp_path):
    scene = bl.emission_scene(strength=STRENGTH, world=(0.25, 0.25, 0.25), samples=1)
    plane = bpy.data.objects["Emitter"]
    plane.keyframe_insert("location", frame=1)
    plane.location.x = 100.0  # out of view at frame 5
    plane.keyframe_insert("location", frame=5)
    scene.frame_set(1)
    path = tmp_path / "animated.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    out = tmp_path / "frame5.exr"
    result = run_cli("render", path, "-o", out, "--frame", 5)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    combined = bl.pass_pixels(bl.read_channels(out), "ViewLayer", "Combined")
    np.testing.assert_allclose(combined[..., :3], 0.25, rtol=1e-4)


def test_exit_status_is_the_clis_own_and_blenders_temp_folder_goes(blend, tmp_path):
    """Whatever the bpy module does at interpreter teardown (Blender 4.2's crashes, exit 139), the
    process ends with the CLI's status, and Blender's session temp folder is removed as its
    teardown would."""
    temp = tmp_path / "tmp"
    temp.mkdir()
    env = {**os.environ, "TMPDIR": str(temp)}
    result = run_cli("render", blend, "-o", tmp_path / "o.png", "--samples", 1, env=env)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert result.stderr == "" and (tmp_path / "o.png").is_file()
    assert list(temp.iterdir()) == []


def test_missing_file(tmp_path):
    assert_one_line_error(run_cli("render", tmp_path / "nope.blend", "-o", tmp_path / "o.exr"), "no such file")


def test_not_a_blend_file(tmp_path):
    fake = tmp_path / "fake.blend"
    fake.write_text("not a blend file\n")
    assert_one_line_error(run_cli("render", fake, "-o", tmp_path / "o.exr"), "not a .blend file")


def test_no_camera(bl, tmp_path):
    scene = bl.emission_scene()
    scene.camera = None
    bpy.data.objects.remove(bpy.data.objects["Camera"])
    path = tmp_path / "nocamera.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    out = tmp_path / "o.exr"
    assert_one_line_error(run_cli("render", path, "-o", out), "no camera")
    assert not out.exists()


def test_scene_the_engine_rejects(bl, tmp_path):
    scene = bl.emission_scene()
    scene.camera = next(obj for obj in scene.objects if obj.type == "MESH")
    path = tmp_path / "mesh_camera.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    out = tmp_path / "o.exr"
    assert_one_line_error(run_cli("render", path, "-o", out), "render failed", "is not a camera object")
    assert not out.exists()


def test_unwritable_output(blend, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("a file where the output folder should be\n")
    assert_one_line_error(run_cli("render", blend, "-o", blocker / "o.exr"), "cannot create output folder")


def test_unsupported_output_format(blend, tmp_path):
    assert_one_line_error(run_cli("render", blend, "-o", tmp_path / "o.jpg"), ".exr or .png")


@pytest.mark.parametrize("resolution", ["abc", "16", "3x10", "16x-2"])
def test_bad_resolution(blend, tmp_path, resolution):
    assert_one_line_error(run_cli("render", blend, "-o", tmp_path / "o.exr", "--resolution", resolution),
                          "--resolution")


def test_missing_output_argument(blend):
    assert_one_line_error(run_cli("render", blend), "-o/--output")


def test_denoise_keeps_the_noisy_image_and_reports_both_errors(bl, blend, tmp_path):
    """``--denoise``: Combined denoised with Blender's OpenImageDenoise (the bpy wheel ships it), the
    image as rendered as Noisy Image, the denoised estimate in the done line and the report."""
    out = tmp_path / "out.exr"
    result = run_cli("render", blend, "-o", out, "--samples", 8, "--resolution", "64x48", "--denoise")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert result.stderr == ""
    assert re.search(r"est\. error \S+ \(denoised \S+\)", result.stdout), result.stdout[-2000:]
    report = json.loads((tmp_path / "out.drt.json").read_text())
    assert report["settings"]["use_denoising"] and report["stats"]["relmse_denoised"] is not None
    channels = bl.read_channels(out)
    noisy = bl.pass_pixels(channels, "ViewLayer", "Noisy Image")[..., :3]
    denoised = bl.pass_pixels(channels, "ViewLayer", "Combined")[..., :3]
    np.testing.assert_allclose(noisy, STRENGTH, rtol=1e-4)  # a noiseless emitter, as rendered
    # OIDN keeps a flat image's mean, with ripples of a few percent (measured: up to 7% at 64x48, 26% at 16x12)
    assert np.isfinite(denoised).all() and np.abs(denoised / STRENGTH - 1).max() < 0.15
    assert abs(denoised.mean() / STRENGTH - 1) < 5e-3


def test_denoise_without_oidn_is_one_clear_error(blend, tmp_path, monkeypatch):
    """Where Blender ships no OpenImageDenoise (Debian's 4.3.2) the CLI says so instead of rendering."""
    from drt_engine.blender import oidn
    from drt_engine.headless import cli, scene
    from drt_engine.headless.errors import CLIError

    monkeypatch.setattr(oidn, "search", lambda: None)
    args = cli.build_parser().parse_args(["render", str(blend), "-o", str(tmp_path / "x.exr"), "--denoise"])
    with pytest.raises(CLIError, match="--denoise: .*OpenImageDenoise"):
        scene.open_scene(args, blend)


def test_merging_denoised_parts_where_blender_has_no_oidn_warns_and_keeps_the_image(monkeypatch, capsys):
    """Parts rendered with denoising, merged where Blender ships no OpenImageDenoise: one warning line,
    and the merged image as rendered (as a render in such a Blender is)."""
    from types import SimpleNamespace

    from drt_engine.blender import oidn
    from drt_engine.headless import outputs

    assert outputs.merge_denoiser(SimpleNamespace(denoising=False)) is None
    monkeypatch.setattr(oidn, "search", lambda: None)
    assert outputs.merge_denoiser(SimpleNamespace(denoising=True)) is None
    printed = capsys.readouterr().out
    assert printed.count("\n") == 1 and printed.startswith("DRT: warning:") and "not denoised" in printed
