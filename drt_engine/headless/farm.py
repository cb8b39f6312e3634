"""``render --workers N`` / ``--cluster ADDRESS``: a render split over a Dask cluster.

The CLI process is the Dask client. It reads the scene's samples and frames from the
.blend, sends the file's bytes once to every worker, submits one task per sample range
of each frame (``farm_task.render_range``), and adds the parts into each frame's image in
range order as they come back (``core.render.merge``). Dask reschedules the task of a worker
that dies; parts depend only on their range, so the image does not change. Only the
CLI uses this module: the Blender extension never imports Dask.
"""
from __future__ import annotations

import logging
import os
import re
import time
from pathlib import Path

from ..core.render import merge, report
from .errors import CLIError
from .outputs import done_line, write_merged_report, write_output
from .scene import check_splittable, open_scene

LOCALHOST = "127.0.0.1"


def split(samples: int, tasks: int) -> list[tuple[int, int]]:
    """``tasks`` contiguous ranges of sample ids covering 0..samples-1 (fewer if there are fewer samples)."""
    tasks = max(1, min(tasks, samples))
    bounds = [round(samples * k / tasks) for k in range(tasks + 1)]
    return list(zip(bounds[:-1], bounds[1:]))


def frame_output(output: Path, frame: int, several: bool) -> Path:
    """OUT with its run of # replaced by the frame number (zero-padded), or the number appended for several frames."""
    name = output.name
    match = re.search(r"#+", name)
    if match:
        return output.with_name(name[:match.start()] + f"{frame:0{len(match[0])}d}" + name[match.end():])
    return output.with_name(f"{output.stem}{frame:04d}{output.suffix}") if several else output


def render(args, blend: Path, output: Path) -> str:
    if output.suffix.lower() != ".exr":
        raise CLIError(f"a render split over a cluster is written as .exr: {output}")
    began = time.perf_counter()
    client = cluster = None
    futures = []
    try:
        client, cluster = _connect(args)  # first: a missing scheduler or a broken worker is said at once
        workers = _check_workers(client, args)
        timing = {"connect": time.perf_counter() - began, "workers": len(workers)}
        samples, frames, options = _plan(args, blend)
        tasks = args.tasks or (len(workers) if len(frames) == 1 else 1)
        ranges = split(samples, tasks)
        shipping = time.perf_counter()
        shipped = client.scatter(blend.read_bytes(), broadcast=True, hash=False)
        timing["ship"] = time.perf_counter() - shipping
        from . import farm_task  # (imports embreex, which the client needs only from here on)

        futures = [client.submit(farm_task.render_range, shipped, blend.name, options, frame, a, b, pure=False,
                                 key=f"drt-frame{frame}-samples{a}-{b}-{os.getpid()}")
                   for frame in frames for a, b in ranges]
        print(f"DRT: {len(futures)} tasks ({len(frames)} frame(s) x {len(ranges)} sample range(s)) on "
              f"{len(workers)} worker(s)", flush=True)
        lines = _gather(futures, frames, ranges, blend, output, began, timing)
    except KeyboardInterrupt:
        if futures:
            client.cancel(futures, force=True)
        if cluster is not None:
            _end_local_renders()
        raise CLIError("cancelled: the tasks were cancelled" + (" and the local cluster shut down" if cluster
                                                                else ""), 130) from None
    finally:
        _close(client, cluster)
    return "\n".join(lines)


def _plan(args, blend: Path) -> tuple[int, list[int], list[str]]:
    """(samples, frames, the render options every task passes on) from the .blend and the overrides."""
    scene = open_scene(args, blend)
    check_splittable(scene, blend)
    samples = scene.drt.samples
    frames = list(range(args.frames[0], args.frames[1] + 1)) if args.frames else [scene.frame_current]
    options = ["--samples", str(samples), "--seed", str(scene.drt.seed)]
    if args.resolution:
        options += ["--resolution", "{}x{}".format(*args.resolution)]
    threads = args.engine_threads
    if threads is None and args.workers:  # the local workers share this machine's cores
        threads = max(1, (os.cpu_count() or 1) // args.workers)
    if threads is not None:
        options += ["--engine-threads", str(threads)]
    if args.denoise:  # the parts carry the denoiser's features; the merge denoises
        options.append("--denoise")
    return samples, frames, options


def _gather(futures, frames, ranges, blend, output, began, farm: dict) -> list[str]:
    """Merge the parts as they come, print progress, write each frame when its parts are in.

    ``farm`` (timings so far) goes into each frame's report as stats["farm"], with every
    task's seconds on its worker, rendering, and from submission to its part's arrival here.
    """
    from distributed import as_completed

    mergers = {frame: merge.Merger(ranges) for frame in frames}
    submitted = time.perf_counter() - began
    tasks = {frame: [] for frame in frames}
    done, lines = 0, []
    for future in as_completed(futures):
        try:
            part, timing = future.result()
        except Exception as error:  # a task's own error names its worker; Dask's say what failed
            raise CLIError(f"a render task failed: {_one_line(error)}") from None
        done += 1
        frame = part.header["frame"]
        merger = mergers[frame]
        arrived = time.perf_counter()
        entry = merger.add(part, arrived - began, f"the part of samples {part.sample_range}")
        tasks[frame].append(dict(timing, range=list(part.sample_range), returned=arrived - began - submitted,
                                 merge=time.perf_counter() - arrived))
        latest = entry or merger.log.last  # a part ahead of a missing range waits, the estimate stays
        error = report.relative_error_text(latest["relmse"]) if latest else "?"
        print(f"DRT: {done}/{len(futures)} tasks done (frame {frame} samples {part.sample_range[0]}:"
              f"{part.sample_range[1]}, {timing['task']:.1f} s on {timing['worker']}, {timing['render']:.1f} s "
              f"rendering); frame {frame}: {merger.merged}/{len(ranges)} parts merged, est. error {error}",
              flush=True)
        if merger.done:
            path = frame_output(output, frame, len(frames) > 1)
            write_output(path, merger)
            summary = merger.report(time.perf_counter() - began)
            summary["stats"]["farm"] = dict(farm, tasks=tasks.pop(frame))
            stats = write_merged_report(path, merger, summary, blend)
            lines.append(done_line(path, merger.film.width, merger.film.height, stats,
                                   time.perf_counter() - began, f"{stats['samples']} samples in {len(ranges)} parts"))
            del mergers[frame]
    return lines


def _connect(args):
    """(client, local cluster or None); one line when there is no scheduler to talk to."""
    from distributed import Client, LocalCluster

    if args.workers:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, host=LOCALHOST,
                               dashboard_address=None, silence_logs=logging.ERROR)
        try:
            return Client(cluster), cluster
        except BaseException:
            cluster.close()
            raise
    security = _security(args)
    logging.getLogger("distributed").setLevel(logging.CRITICAL)  # the one line below says it
    try:
        return Client(args.cluster, timeout=args.connect_timeout, security=security), None
    except (OSError, TimeoutError) as error:
        raise CLIError(f"no Dask scheduler answered at {args.cluster} within {args.connect_timeout:g} s "
                       f"({_one_line(error)[:120]})") from None
    except ValueError as error:
        raise CLIError(f"not a Dask scheduler address: {args.cluster} ({_one_line(error)[:120]})") from None


def _security(args):
    """Dask's TLS settings: the options given, else Dask's own configuration (distributed.comm.tls)."""
    from distributed.security import Security

    given = {k: v for k, v in (("tls_ca_file", args.tls_ca_file), ("tls_client_cert", args.tls_cert),
                               ("tls_client_key", args.tls_key)) if v}
    for path in given.values():
        if not Path(path).is_file():
            raise CLIError(f"no such file: {path}")
    return Security(require_encryption=True, **given) if given else Security()


def _check_workers(client, args) -> list[str]:
    """The workers' addresses, after checking each can import DRT, embreex and bpy (one line naming
    a worker that cannot)."""
    try:
        client.wait_for_workers(1, timeout=args.connect_timeout)
    except (TimeoutError, OSError):
        raise CLIError(f"no Dask worker joined the scheduler within {args.connect_timeout:g} s") from None
    results = client.run(exec, "import drt_engine.headless.farm_task as t; t.check()", on_error="return")
    for address, result in sorted(results.items()):
        if isinstance(result, BaseException):
            raise CLIError(f"worker {address} cannot run DRT: {_one_line(result)}")
    return sorted(results)


def _end_local_renders() -> None:
    """Ctrl-C on a local cluster: end the workers' render processes at once. A render busy in
    compiled code (a kernel compiling on a cold cache) answers its SIGINT only when it returns to
    Python, and its worker cannot close before it ends."""
    import psutil

    for child in psutil.Process().children(recursive=True):
        try:
            if "--sample-range" in child.cmdline():
                child.kill()
        except psutil.Error:
            pass


def _close(client, cluster) -> None:
    try:
        if client is not None:
            client.close(timeout=10)
    finally:
        if cluster is not None:
            cluster.close(timeout=30)


def _one_line(error) -> str:
    text = " ".join(str(error).split()) or type(error).__name__
    return text if isinstance(error, CLIError) else f"{type(error).__name__}: {text}"
