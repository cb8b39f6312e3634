"""Render time of the sample scenes, whole and per module, for before/after comparisons of a change.

``python bench/render_time.py [--width 160] [--samples 16] [--threads 1] [--scenes ...] [--top 12]``:
for each scene, the time to prepare the scene (core.render.prepared; export excluded), the render's
wall time (best of ``--repeat``, reusing the prepared scene) and, from one cProfile run of the
render, each core module's own time and the number of Python function calls.
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

import drt_engine  # noqa: E402
from drt_engine.core.render.prepared import PreparedScene  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402

def by_module(stats: pstats.Stats) -> dict[str, float]:
    """Own (tottime) CPU seconds per drt_engine.core module, the rest lumped as 'other'."""
    out: dict[str, float] = {}
    for (path, _, _), (_, _, tottime, _, _) in stats.stats.items():
        name = Path(path).stem if "drt_engine/core" in path else "other (numpy, embree, ...)"
        out[name] = out.get(name, 0.0) + tottime
    return out


def timed(fn) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process) of fn(): CPU time suffers less from a busy machine."""
    wall, cpu = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - wall, time.process_time() - cpu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--top", type=int, default=8)
    args = parser.parse_args(argv)
    drt_engine.register()
    for name in args.scenes:
        scene, data = load(name, args.width)
        s = settings(scene, samples=args.samples, threads=args.threads, seed=7)
        start = time.perf_counter()
        prepared = PreparedScene(data)
        prepare = time.perf_counter() - start
        runs = [timed(Renderer(data, s, prepared).render) for _ in range(args.repeat)]
        best, cpu = min(runs)
        profiler = cProfile.Profile(time.process_time)  # CPU seconds: a busy machine disturbs them less
        renderer = Renderer(data, s, prepared)
        profiler.enable()
        renderer.render()
        profiler.disable()
        stats = pstats.Stats(profiler)
        calls = sum(v[1] for v in stats.stats.values())
        w, h = data.camera.window_size
        print(f"{name} {w}x{h} {args.samples} spp threads={args.threads}: prepare {prepare:.2f} s, "
              f"render {best:.2f} s wall, {cpu:.2f} s CPU (best of {args.repeat}), {calls} Python calls (profiled run)")
        for module, seconds in sorted(by_module(stats).items(), key=lambda kv: -kv[1])[:args.top]:
            print(f"    {module:28s} {seconds:6.2f} s own CPU time")


if __name__ == "__main__":
    main()
