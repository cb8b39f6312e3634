"""``python -m drt_engine render FILE.blend -o OUT``: render a .blend with DRT through the bpy module.

Blender prints freely on both streams. While it works, file descriptor 2 points at
stdout, so the real stderr carries exactly one line from us when something is wrong
(and nothing otherwise); the exit code says which.
"""
import argparse
import math
import os
import re
import shutil
import sys
import time
from pathlib import Path

from .headless.progress import ProgressDisplay
from .core.errors import DRTError
from .core.film import parts
from .core.render import merge, report
from .core.settings import ADAPTIVE_MODES, SHADOW_ESTIMATORS

EXIT_ERROR = 1
EXIT_USAGE = 2
BLEND_MAGIC = (b"BLENDER", b"\x1f\x8b", b"\x28\xb5\x2f\xfd")  # plain, gzip, zstd
MIN_SIDE = 4  # the smallest image side Blender renders


class CLIError(Exception):
    """Bad input: the message is the one line the user sees."""

    def __init__(self, message: str, code: int = EXIT_ERROR):
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise CLIError(message, EXIT_USAGE)


def _resolution(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(f"must look like WxH, e.g. 640x480, got {text!r}")
    width, height = int(match[1]), int(match[2])
    if min(width, height) < MIN_SIDE:
        raise argparse.ArgumentTypeError(f"each side must be at least {MIN_SIDE} pixels, got {text!r}")
    return width, height


def _at_least(minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {value}")
        return value

    return parse


def _float_in(minimum: float, maximum: float = math.inf):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not (minimum <= value <= maximum) or not math.isfinite(value):
            bounds = f"at least {minimum:g}" if maximum == math.inf else f"between {minimum:g} and {maximum:g}"
            raise argparse.ArgumentTypeError(f"must be {bounds}, got {text!r}")
        return value

    return parse


def _one_of(names):
    def parse(text: str) -> str:
        if text.upper() not in names:
            raise argparse.ArgumentTypeError(f"must be one of {', '.join(names)}, got {text!r}")
        return text.upper()
    return parse


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m drt_engine", description="DRT, a distribution ray tracer for Blender scenes.")
    commands = parser.add_subparsers(dest="command", metavar="{render,merge}", required=True, parser_class=_Parser)
    render = commands.add_parser(
        "render",
        help="render a .blend file with DRT",
        description="Render FILE.blend with DRT and write OUT: a multilayer EXR with every pass "
        "enabled on the view layers (.exr) or a PNG through the scene's view transform (.png). "
        "Beside OUT it writes OUT's stem + .drt.json (settings, scene summary, stats and the "
        "error-against-time log) and + .error.png (the log plotted). "
        "Overrides change the scene in memory only; the .blend file is never saved.",
    )
    render.add_argument("blend", metavar="FILE.blend", help="the scene to render (its active scene and camera)")
    render.add_argument("-o", "--output", required=True, metavar="OUT", help="output file, .exr or .png")
    render.add_argument("--samples", type=_at_least(1), metavar="N", help="samples per pixel (scene.drt.samples)")
    render.add_argument("--seed", type=_at_least(0), metavar="S", help="random seed (scene.drt.seed)")
    render.add_argument("--frame", type=int, metavar="F", help="frame to render (default: the file's current frame)")
    render.add_argument("--resolution", type=_resolution, metavar="WxH", help="image size in pixels (at 100%%)")
    render.add_argument("--engine-threads", type=_at_least(0), metavar="T", help="render threads, 0 = all cores")
    render.add_argument("--time-limit", type=_float_in(0.0), metavar="SECONDS",
                        help="stop after this many seconds, 0 = none (scene.drt.time_limit)")
    render.add_argument("--target-error", type=_float_in(0.0), metavar="E",
                        help="stop when the estimated relMSE of the image is under E, 0 = none "
                        "(scene.drt.target_error)")
    render.add_argument("--adaptive-threshold", type=_float_in(0.0, 1.0), metavar="T",
                        help="noise threshold, 0 = automatic; turns adaptive sampling on "
                        "(scene.drt.adaptive_threshold)")
    render.add_argument("--adaptive-min-samples", type=_at_least(0), metavar="N",
                        help="samples every pixel takes before adaptive sampling starts, 0 = automatic; "
                        "turns adaptive sampling on (scene.drt.adaptive_min_samples)")
    render.add_argument("--adaptive-mode", type=_one_of(ADAPTIVE_MODES), metavar="NOISE|CONTRAST",
                        help="adaptive sampling mode; turns adaptive sampling on (scene.drt.adaptive_mode)")
    render.add_argument("--shadow-estimator", type=_one_of(SHADOW_ESTIMATORS), metavar="MONTE_CARLO|RATIO",
                        help="diffuse direct light of lights with a closed form: per shadow ray, or the "
                        "analytic light times the pixel's visible fraction (scene.drt.shadow_estimator)")
    farm = render.add_argument_group(
        "render farm", "Split the render over processes or machines: sample ranges of a frame, frames of an "
        "animation. Parts need a fixed sample count (no adaptive sampling, time limit or target error).")
    farm.add_argument("--sample-range", type=_sample_range, metavar="START:END",
                      help="render only sample ids START to END-1 of the --samples set and write OUT (.exr) as "
                      "a part for `merge`")
    farm.add_argument("--workers", type=_at_least(1), metavar="N",
                      help="render on a Dask LocalCluster of N worker processes on this machine (127.0.0.1 only)")
    farm.add_argument("--cluster", metavar="ADDRESS",
                      help="render on the Dask scheduler at ADDRESS (tcp://host:8786 or tls://host:8786)")
    farm.add_argument("--frames", type=_frames, metavar="A-B",
                      help="render frames A to B, one task a frame unless --tasks says more (OUT's #### become "
                      "the frame number)")
    farm.add_argument("--tasks", type=_at_least(1), metavar="K",
                      help="sample ranges per frame (default: one per worker for one frame, 1 for several)")
    farm.add_argument("--connect-timeout", type=_float_in(1.0, 600.0), default=30.0, metavar="SECONDS",
                      help="give up on a --cluster scheduler that does not answer in this time (default 30)")
    farm.add_argument("--tls-ca-file", metavar="PEM", help="TLS: the certificate authority of the cluster")
    farm.add_argument("--tls-cert", metavar="PEM", help="TLS: this client's certificate")
    farm.add_argument("--tls-key", metavar="PEM", help="TLS: this client's private key")

    merge = commands.add_parser(
        "merge",
        help="add parts rendered with --sample-range into the image",
        description="Add the parts (EXR files written by `render --sample-range` or by Blender with "
        "scene.drt.sample_offset / sample_count) into the image of all the samples and write OUT (.exr) "
        "with its report, as a whole render does. The parts must be of one scene, seed, settings and "
        "frame, and their ranges must cover all the samples once.",
    )
    merge.add_argument("parts", metavar="PART.exr", nargs="+", help="the parts, in any order")
    merge.add_argument("-o", "--output", required=True, metavar="OUT", help="output file, .exr")
    return parser


def _sample_range(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*:\s*(\d+)\s*", text)
    if not match or int(match[1]) >= int(match[2]):
        raise argparse.ArgumentTypeError(f"must look like START:END with START < END, e.g. 0:256, got {text!r}")
    return int(match[1]), int(match[2])


def _frames(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(-?\d+)\s*(?:-\s*(-?\d+)\s*)?", text)
    if not match or (match[2] is not None and int(match[2]) < int(match[1])):
        raise argparse.ArgumentTypeError(f"must look like A-B with A <= B, or one frame, got {text!r}")
    first = int(match[1])
    return first, int(match[2]) if match[2] is not None else first


def _check_paths(blend: Path, output: Path) -> None:
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


def _blender_message(error: Exception) -> str:
    """Blender's operator errors read 'Error: message\\n...': keep the message."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    text = lines[0] if lines else type(error).__name__
    return re.sub(r"^(Error|Warning):\s*", "", text)


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


def _open_scene(args, blend: Path):
    """Open ``blend`` in this process's bpy with DRT registered and the overrides applied."""
    import bpy

    from . import register
    from .blender.engine import DRTRenderEngine

    if not DRTRenderEngine.is_registered:  # once per process (a test may have done it)
        register()
    try:
        bpy.ops.wm.open_mainfile(filepath=str(blend), load_ui=False)
    except RuntimeError as error:
        raise CLIError(f"cannot open {blend}: {_blender_message(error)}") from None
    scene = bpy.context.scene
    if args.frame is not None:
        scene.frame_set(args.frame)
    if scene.camera is None:
        raise CLIError(f"scene {scene.name!r} in {blend.name} has no camera")
    render = scene.render
    render.engine = "DRT"
    if args.resolution:
        render.resolution_x, render.resolution_y = args.resolution
        render.resolution_percentage = 100
    if args.samples is not None:
        scene.drt.samples = args.samples
    if args.seed is not None:
        scene.drt.seed = args.seed
    if args.engine_threads is not None:
        scene.drt.threads = args.engine_threads
    if args.time_limit is not None:
        scene.drt.time_limit = args.time_limit
    if args.target_error is not None:
        scene.drt.target_error = args.target_error
    if args.adaptive_threshold is not None:
        scene.drt.use_adaptive_sampling = True
        scene.drt.adaptive_threshold = args.adaptive_threshold
    if args.adaptive_min_samples is not None:
        scene.drt.use_adaptive_sampling = True
        scene.drt.adaptive_min_samples = args.adaptive_min_samples
    if args.adaptive_mode is not None:
        scene.drt.use_adaptive_sampling = True
        scene.drt.adaptive_mode = args.adaptive_mode
    if args.shadow_estimator is not None:
        scene.drt.shadow_estimator = args.shadow_estimator
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


def _render(args) -> str:
    blend = Path(args.blend).expanduser().resolve()
    output = Path(args.output).expanduser().resolve()
    _check_paths(blend, output)
    if args.workers is not None and args.cluster is not None:
        raise CLIError("choose --workers (a local cluster) or --cluster (a running one), not both")
    if args.workers is not None or args.cluster is not None:
        if args.sample_range is not None:
            raise CLIError("--sample-range renders one part here; --workers and --cluster split the render themselves")
        from . import farm

        return farm.render(args, blend, output)
    for option, value in (("--frames", args.frames), ("--tasks", args.tasks)):
        if value is not None:
            raise CLIError(f"{option} needs --workers or --cluster")

    import bpy

    from .blender.hooks import render_hooks

    scene = _open_scene(args, blend)
    render = scene.render
    if args.sample_range is not None:
        first, end = args.sample_range
        if output.suffix.lower() != ".exr":
            raise CLIError(f"a part is written as .exr: {output}")
        check_splittable(scene, blend)
        if end > scene.drt.samples:
            raise CLIError(f"--sample-range {first}:{end} goes past the {scene.drt.samples} samples")
        scene.drt.sample_offset, scene.drt.sample_count = first, end - first
        render_hooks.collect_parts = True
        render_hooks.last_parts.clear()

    render_hooks.last_reports.clear()
    start = time.perf_counter()
    render_hooks.progress_listener = ProgressDisplay(sys.stdout, scene.drt.time_limit, scene.drt.target_error)
    try:
        bpy.ops.render.render(write_still=False, scene=scene.name)
    except RuntimeError as error:
        raise CLIError(f"render failed: {_blender_message(error)}") from None
    finally:
        render_hooks.progress_listener.close()
        render_hooks.progress_listener = None
    elapsed = time.perf_counter() - start
    if not render_hooks.last_reports:
        raise CLIError("the render produced no image")

    if args.sample_range is not None:
        try:
            parts.write(output, next(iter(render_hooks.last_parts.values())))
        except OSError as error:
            raise CLIError(str(error)) from None
        done = f"samples {args.sample_range[0]}:{args.sample_range[1]} of {scene.drt.samples} as a part"
    else:
        _set_output_format(render.image_settings, output.suffix.lower() == ".exr")
        try:
            bpy.data.images["Render Result"].save_render(filepath=str(output), scene=scene)
        except RuntimeError as error:
            raise CLIError(f"cannot write {output}: {_blender_message(error)}") from None
        if not output.is_file():
            raise CLIError(f"cannot write {output}")
        done = None
    stats = _write_report(output, blend, args.frame, render_hooks.last_reports)
    width, height = (side * render.resolution_percentage // 100 for side in (render.resolution_x, render.resolution_y))
    return done_line(output, width, height, stats, elapsed, done)


def done_line(output: Path, width: int, height: int, stats: dict, elapsed: float, samples: str | None = None) -> str:
    error = report.relative_error_text(stats["relmse"])
    samples = samples or f"{stats['samples']} samples"
    return (f"DRT: wrote {output} ({width}x{height}, {samples}, est. error {error}, "
            f"stopped by {report.STOP_REASONS[stats['stopped_by']]}, {elapsed:.1f} s) and its report")


def _merge(args) -> str:
    output = Path(args.output).expanduser().resolve()
    if output.suffix.lower() != ".exr":
        raise CLIError(f"merge writes .exr: {output}")
    paths = [Path(p).expanduser() for p in args.parts]
    for path in paths:
        if not path.is_file():
            raise CLIError(f"no such file: {path}")
    start = time.perf_counter()
    merger = merge.merge_parts([parts.read(path) for path in paths], [path.name for path in paths])
    write_output(output, merger)
    stats = write_merged_report(output, merger, merger.report(merger.log.last["elapsed"]))
    return done_line(output, merger.film.width, merger.film.height, stats, time.perf_counter() - start,
                     f"{len(paths)} parts, {stats['samples']} samples")


def write_output(output: Path, merger) -> None:
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
        merge.write_exr(output, merger.film, merger.first.header["view_layer"])
    except OSError as error:
        raise CLIError(f"cannot write {output}: {error.strerror or error}") from None


def write_merged_report(output: Path, merger, summary: dict, blend: Path | None = None) -> dict:
    """The merged render's report files beside OUT, as a whole render writes them (``blend``: the
    scene's file, when the parts' own record of it is a worker's copy)."""
    header = merger.first.header
    return _write_report(output, blend or Path(header["blend"]), header["frame"], {header["view_layer"]: summary})


def report_paths(output: Path) -> tuple[Path, Path]:
    """``<OUT stem>.drt.json`` and ``<OUT stem>.error.png`` beside OUT."""
    return output.with_name(output.stem + ".drt.json"), output.with_name(output.stem + ".error.png")


def _write_report(output: Path, blend: Path, frame, reports: dict[str, dict]) -> dict:
    """The first view layer's report at the top of the JSON, any others under ``other_view_layers``."""
    json_path, plot_path = report_paths(output)
    layers = list(reports.values())
    data = {"file": str(blend), "output": str(output), "frame": frame, **layers[0]}
    if len(layers) > 1:
        data["other_view_layers"] = layers[1:]
    try:
        report.write_json(json_path, data)
        report.plot_log(plot_path, {name: r["log"] for name, r in reports.items()},
                        f"{blend.stem}: estimated error vs time")
    except OSError as error:
        raise CLIError(f"cannot write the report beside {output}: {error.strerror or error}") from None
    return layers[0]["stats"]


def main(argv=None) -> int:
    stderr = os.fdopen(os.dup(2), "w")
    saved_stderr = os.dup(2)
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(1, 2)  # Blender's own messages, Python's included, go to stdout from here on
    try:
        args = build_parser().parse_args(argv)
        print(_render(args) if args.command == "render" else _merge(args), flush=True)
        return 0
    except (CLIError, DRTError) as error:
        stderr.write(f"drt: error: {' '.join(str(error).split())}\n")
        return getattr(error, "code", EXIT_ERROR)
    except Exception as error:  # a bug of ours: still one line, the details on stdout
        import traceback

        traceback.print_exc(file=sys.stdout)
        stderr.write(f"drt: internal error: {type(error).__name__}: {error}\n")
        return EXIT_ERROR
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        stderr.flush()
        os.dup2(saved_stderr, 2)
        os.close(saved_stderr)
        stderr.close()


def exit_now(code: int) -> None:
    """End the process with the CLI's own exit status, skipping the interpreter's teardown.

    The bpy module of Blender 4.2 crashes while Python tears it down (SIGSEGV, exit 139), after
    the image and the report are written; a caller must see the status of the work, not of the
    teardown. The one thing that teardown does that matters here, removing Blender's session
    temp folder, is done first.
    """
    bpy = sys.modules.get("bpy")
    if bpy is not None and os.path.basename(os.path.normpath(bpy.app.tempdir)).startswith("blender_"):
        shutil.rmtree(bpy.app.tempdir, ignore_errors=True)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
