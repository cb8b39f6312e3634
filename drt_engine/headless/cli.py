"""``python -m drt_engine render FILE.blend -o OUT`` / ``merge``: the options, and the process around
a command (commands.py does the work).

Blender prints freely on both streams. While it works, file descriptor 2 points at
stdout, so the real stderr carries exactly one line from us when something is wrong
(and nothing otherwise); the exit code says which.
"""
import argparse
import math
import os
import re
import sys

from ..core.errors import DRTError
from ..core.settings import ADAPTIVE_MODES, SHADOW_ESTIMATORS
from . import commands
from .errors import EXIT_ERROR, EXIT_USAGE, CLIError

MIN_SIDE = 4  # the smallest image side Blender renders


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
    render.add_argument("--denoise", action="store_true",
                        help="denoise Combined with the OpenImageDenoise library Blender ships, keeping the image "
                        "as rendered as the Noisy Image pass (scene.drt.use_denoising); a split render is "
                        "denoised once, after its parts are merged")
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


def main(argv=None) -> int:
    stderr = os.fdopen(os.dup(2), "w")
    saved_stderr = os.dup(2)
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(1, 2)  # Blender's own messages, Python's included, go to stdout from here on
    try:
        args = build_parser().parse_args(argv)
        print(commands.render(args) if args.command == "render" else commands.merge(args), flush=True)
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
    if "bpy" in sys.modules:  # Blender was loaded, by this process or its caller
        from ..blender import batch

        batch.remove_session_folder()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
