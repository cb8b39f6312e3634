"""Where a render's time goes: the sample scenes' render time, per compiled kernel and per core
module, for before/after comparisons of a change and for the performance page.

``python bench/render_time.py [--width 256] [--samples 16] [--threads 1] [--scenes ...] [--top 8]
[--publish]``: for each scene, the time to prepare the scene (core.render.prepared; export
excluded), the render's wall and CPU time (best of ``--repeat``, reusing the prepared scene), one
render with every kernel the core calls from Python timed (CPU seconds inside each call, Embree's
queries made from inside a kernel included; kernels called from compiled code count in their
caller) and one cProfile run of the render: each core module's own time in Python and NumPy, the
kernels' time apart, and the number of Python function calls. ``--publish`` writes the kernel table
into docs/performance.md (block ``bench:render-time``).
"""
from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

from numba import _dispatcher as numba_dispatcher  # noqa: E402
from numba.core.registry import CPUDispatcher  # noqa: E402

import drt_engine  # noqa: E402
from blocks import write_block  # noqa: E402
from drt_engine.core.render.prepared import PreparedScene  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402

KERNELS = "kernels (compiled)"
"""by_module's name for the kernels' time: Numba shows a profiler each call from Python as a call of
the kernel's Python function, in the module that defines it."""


def by_module(stats: pstats.Stats, kernels: set) -> dict[str, float]:
    """Own (tottime) CPU seconds per drt_engine.core module, the kernels (``kernels``: their functions'
    (file, line, name)) and the rest lumped."""
    out: dict[str, float] = {}
    for key, (_, _, tottime, _, _) in stats.stats.items():
        path = key[0]
        name = (KERNELS if key in kernels else Path(path).stem if "drt_engine/core" in path
                else "other (numpy, Python)")
        out[name] = out.get(name, 0.0) + tottime
    return out


def timed(fn) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process) of fn(): CPU time suffers less from a busy machine."""
    wall, cpu = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - wall, time.process_time() - cpu


@contextmanager
def kernel_timers():
    """Every call of a compiled kernel from Python timed for the duration (Numba's dispatcher class
    given a timing ``__call__``; calls between kernels are native and count in their caller): yields
    {"module.kernel": [CPU seconds of the calling thread, calls, (file, line, name) of its function]}."""
    spent: dict[str, list] = {}
    lock = threading.Lock()
    call = numba_dispatcher.Dispatcher.__call__

    def timed_call(dispatcher, *args, **kwargs):
        start = time.thread_time()
        try:
            return call(dispatcher, *args, **kwargs)
        finally:
            seconds = time.thread_time() - start
            with lock:
                code = dispatcher.py_func.__code__
                entry = spent.setdefault(f"{Path(code.co_filename).stem}.{code.co_name}",
                                         [0.0, 0, (code.co_filename, code.co_firstlineno, code.co_name)])
                entry[0] += seconds
                entry[1] += 1

    CPUDispatcher.__call__ = timed_call
    try:
        yield spent
    finally:
        del CPUDispatcher.__call__  # the C type's own call again


def kernel_table(rows: list[tuple], top: int) -> str:
    """The published block: per scene, the render's CPU time, the kernels' share and the largest."""
    lines = ["| scene | render CPU s | in kernels | Python and NumPy between them | largest kernels, CPU s (calls) |",
             "|---|---|---|---|---|"]
    for name, size, cpu, spent in rows:
        inside = sum(s for s, _, _ in spent.values())
        largest = ", ".join(f"{k} {s:.2f} ({c})" for k, (s, c, _) in
                            sorted(spent.items(), key=lambda kv: -kv[1][0])[:top])
        lines.append(f"| {name} {size} | {cpu:.2f} | {inside:.2f} ({inside / cpu:.0%}) | "
                     f"{cpu - inside:.2f} ({(cpu - inside) / cpu:.0%}) | {largest} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=256)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--top", type=int, default=8)
    parser.add_argument("--publish", action="store_true", help="write docs/performance.md's block")
    args = parser.parse_args(argv)
    drt_engine.register()
    rows = []
    for name in args.scenes:
        scene, data = load(name, args.width)
        s = settings(scene, samples=args.samples, threads=args.threads, seed=7)
        start = time.perf_counter()
        prepared = PreparedScene(data)
        prepare = time.perf_counter() - start
        runs = [timed(Renderer(data, s, prepared).render) for _ in range(args.repeat)]
        best, cpu = min(runs)
        with kernel_timers() as spent:
            _, kernel_cpu = timed(Renderer(data, s, prepared).render)
        profiler = cProfile.Profile(time.process_time)  # CPU seconds: a busy machine disturbs them less
        renderer = Renderer(data, s, prepared)
        profiler.enable()
        renderer.render()
        profiler.disable()
        stats = pstats.Stats(profiler)
        calls = sum(v[1] for v in stats.stats.values())
        w, h = data.camera.window_size
        rows.append((name, f"{w}x{h}", kernel_cpu, spent))
        inside = sum(seconds for seconds, _, _ in spent.values())
        print(f"{name} {w}x{h} {args.samples} spp threads={args.threads}: prepare {prepare:.2f} s, "
              f"render {best:.2f} s wall, {cpu:.2f} s CPU (best of {args.repeat}); timed run {kernel_cpu:.2f} s CPU, "
              f"{inside:.2f} s in kernels; {calls} Python calls (profiled run)")
        for kernel, (seconds, count, _) in sorted(spent.items(), key=lambda kv: -kv[1][0])[:args.top]:
            print(f"    kernel {kernel:35s} {seconds:6.2f} s CPU, {count} calls")
        codes = {code for _, _, code in spent.values()}
        for module, seconds in sorted(by_module(stats, codes).items(), key=lambda kv: -kv[1])[:args.top]:
            print(f"    {module:35s} {seconds:6.2f} s own CPU time (profiled)")
    if args.publish:
        load1 = os.getloadavg()[0]
        write_block("render-time", (
            f"Made by `bench/render_time.py --publish` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
            f"{os.cpu_count()} cores, load average {load1:.1f} at the end; {args.samples} spp, "
            f"{args.threads} thread{'' if args.threads == 1 else 's'}, kernels cached; CPU seconds of one render per "
            "scene:\n\n"
            + kernel_table(rows, 4)))


if __name__ == "__main__":
    main()
