"""What ``render`` and ``merge`` do once their options are parsed: each returns the line printed at the
end or raises CLIError. A render runs here (the whole image, or one sample range as a part) or on a
Dask cluster (farm.py)."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from ..core.film import parts
from ..core.render import merge as merging
from . import farm
from .errors import CLIError
from .outputs import done_line, save_image, write_merged_report, write_output, write_part, write_report
from .progress import ProgressDisplay
from .scene import check_paths, check_splittable, open_scene


def render(args) -> str:
    blend = Path(args.blend).expanduser().resolve()
    output = Path(args.output).expanduser().resolve()
    check_paths(blend, output)
    if args.workers is not None and args.cluster is not None:
        raise CLIError("choose --workers (a local cluster) or --cluster (a running one), not both")
    if args.workers is not None or args.cluster is not None:
        if args.sample_range is not None:
            raise CLIError("--sample-range renders one part here; --workers and --cluster split the render themselves")
        return farm.render(args, blend, output)
    for option, value in (("--frames", args.frames), ("--tasks", args.tasks)):
        if value is not None:
            raise CLIError(f"{option} needs --workers or --cluster")

    from ..blender import batch

    scene = open_scene(args, blend)
    if args.sample_range is not None:
        first, end = args.sample_range
        if output.suffix.lower() != ".exr":
            raise CLIError(f"a part is written as .exr: {output}")
        check_splittable(scene, blend)
        if end > scene.drt.samples:
            raise CLIError(f"--sample-range {first}:{end} goes past the {scene.drt.samples} samples")
        batch.set_settings(scene, sample_offset=first, sample_count=end - first)

    start = time.perf_counter()
    display = ProgressDisplay(sys.stdout, scene.drt.time_limit, scene.drt.target_error)
    try:
        reports, rendered = batch.render(scene, display, collect_parts=args.sample_range is not None)
    except batch.BatchError as error:
        raise CLIError(f"render failed: {error}") from None
    finally:
        display.close()
    elapsed = time.perf_counter() - start
    if not reports:
        raise CLIError("the render produced no image")

    if args.sample_range is not None:
        write_part(output, next(iter(rendered.values())))
        done = f"samples {args.sample_range[0]}:{args.sample_range[1]} of {scene.drt.samples} as a part"
    else:
        save_image(scene, output)
        done = None
    stats = write_report(output, blend, args.frame, reports)
    return done_line(output, *batch.output_size(scene), stats, elapsed, done)


def merge(args) -> str:
    output = Path(args.output).expanduser().resolve()
    if output.suffix.lower() != ".exr":
        raise CLIError(f"merge writes .exr: {output}")
    paths = [Path(p).expanduser() for p in args.parts]
    for path in paths:
        if not path.is_file():
            raise CLIError(f"no such file: {path}")
    start = time.perf_counter()
    merger = merging.merge_parts([parts.read(path) for path in paths], [path.name for path in paths])
    write_output(output, merger)
    stats = write_merged_report(output, merger, merger.report(merger.log.last["elapsed"]))
    return done_line(output, merger.film.width, merger.film.height, stats, time.perf_counter() - start,
                     f"{len(paths)} parts, {stats['samples']} samples")
