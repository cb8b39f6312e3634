"""make bench (throughput part): DRT's ray throughput against raw Embree, and its peak memory.

For each sample scene, in one run:
(a) raw Embree: the scene's own camera rays (pixel jitter, lens, shutter as the scene
    has them, at mid-shutter) traced through the scene's top-level Embree scene by the
    binding's batch kernel alone (core.geometry.embree), on 1 thread and on every core (one
    chunk per thread);
(b) DRT end to end: every ray the renderer traced (camera, shadow, reflection,
    refraction, transparent) over its render time (export and BVH build excluded), on
    1 thread and on every core;
(c) b / a per CPU second on 1 thread (target: at least 0.5), and DRT's wall-time speed-up on
    every core against 1 thread (target: at least 1.8 on 2 cores), raw Embree's own beside it;
(d) time to relMSE 1e-3, DRT (best of its curves) against Cycles with adaptive sampling,
    taken from bench/run.py's per-scene results (bench/results/<scene>.json) when they exist,
    and from the same curves the time per sample, DRT against Cycles (target: at most 1.5x);
(e) peak memory (VmHWM, the process's own: tests/support/memory.py) of a 1920x1080 render in a
    fresh process, and of the same process before the renderer is made (bpy, the scene, the export);
(f) cold and warm start (bench/startup.py): the first render with an empty kernel cache, with
    the cache filled, and with only the kernels the Linux zip ships, each in a fresh process.
The scene is prepared once (core.render.prepared) and shared by the raw rays and both DRT renders;
(a) and (b) run in three alternating rounds and each figure is the best of its rounds.
Writes bench/THROUGHPUT.md and its section of bench/RESULTS.md.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import drt_engine  # noqa: E402
from drt_engine.core.geometry import camera as camera_rays, embree  # noqa: E402
from drt_engine.core.render.prepared import PreparedScene  # noqa: E402
from drt_engine.core.render.render import WAVE, Renderer  # noqa: E402
from blocks import RESULTS_THROUGHPUT, write_block  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402
from startup import describe, measure  # noqa: E402

TARGET_RATIO = 0.5  # DRT's rays per CPU second over raw Embree's, 1 thread
TARGET_SPEEDUP = 1.8  # DRT's wall time on 1 thread over every core's, on 2 cores
TARGET_WARM = 1.0  # seconds to load the cached kernels
TARGET_COLD = 15.0  # seconds of the first render with nothing cached
TARGET_MEMORY = 300  # MB the 1920x1080 render adds to the process's peak
TARGET_PER_SAMPLE = 1.5  # DRT's time per sample over Cycles'
MARK_BEGIN, MARK_END = RESULTS_THROUGHPUT
ROUNDS = 3  # alternating rounds of the four measurements (raw 1 thread, raw all, DRT 1 thread, DRT all)


def camera_batch(data, n, seed=0):
    """n camera rays of the scene: uniform over the image, the lens and the shutter."""
    rng = np.random.default_rng(seed)
    w, h = data.camera.window_size
    px, py = rng.random(n) * w, rng.random(n) * h
    lens = rng.random((n, 2)) if data.camera.aperture_radius > 0 else None
    return camera_rays.generate(data.camera, px, py, lens, rng.random(n))


def raw_embree(geometry, cam, threads, seconds=1.0):
    """(rays per wall second, rays per CPU second) of Embree alone: the binding's batch kernel over
    the scene's top-level Embree scene at mid-shutter, for closest hits as DRT asks."""
    top = geometry.instance_scene
    if top is None:
        return float("nan"), float("nan")
    n = len(cam.origins)
    rays = (np.ascontiguousarray(cam.origins - geometry.center, np.float32),
            np.ascontiguousarray(cam.directions, np.float32), np.zeros(n, np.float32),
            np.minimum(cam.tmax, 3e38).astype(np.float32), np.full(n, 0.5, np.float32), np.full(n, -1, np.int32))
    out = (np.empty(n, np.float32), np.empty((n, 2), np.float32), np.empty((n, 3), np.float32),
           np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n, np.int32))
    bounds = np.linspace(0, n, threads + 1).astype(int)
    with ThreadPoolExecutor(threads) as pool:
        def once():
            jobs = [pool.submit(embree.intersect_batch, top.handle, *(x[a:b] for x in rays + out))
                    for a, b in zip(bounds[:-1], bounds[1:])]
            for job in jobs:
                job.result()
        once()
        reps, start, cpu = 0, time.perf_counter(), time.process_time()
        while reps < 3 or time.perf_counter() - start < seconds:
            once()
            reps += 1
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    return n * reps / elapsed, n * reps / cpu


def drt_rate(data, prepared, scene, threads, samples):
    """(rays per wall second, rays per CPU second, seconds, rays by kind, plan summary) of one
    DRT render."""
    renderer = Renderer(data, settings(scene, samples=samples, threads=threads, seed=7), prepared)
    cpu = time.process_time()
    stats = renderer.render().stats
    cpu = time.process_time() - cpu
    total = sum(stats["rays"].values())
    return total / stats["elapsed"], total / cpu, stats["elapsed"], stats["rays"], stats["plan_summary"]


def _results(name) -> dict | None:
    """bench/run.py's results for scene ``name`` (bench/results/<scene>.json), None before a run."""
    path = ROOT / "bench" / "results" / f"{name}.json"
    return json.loads(path.read_text()) if path.exists() else None


def time_to_error(name, level=1e-3):
    """(DRT's best seconds, its curve, Cycles' best seconds, its curve, bench/run.py's settings) from
    bench/run.py's results."""
    found = _results(name)
    if found is None:
        return None
    from bench.run import time_to

    curves = found["curves"]
    times = {k: time_to(v, level) for k, v in curves.items()}

    def best(cycles):
        found = {k: t for k, t in times.items() if t is not None and k.startswith("Cycles") == cycles}
        k = min(found, key=found.get) if found else None
        return (found[k] if k else None), k

    w, h = found["resolution"]
    return best(False) + best(True) + (f"{w}x{h}, cap {found['cap']} spp, references {found['reference_samples']} spp",)


def time_per_sample(name, drt="SOBOL", cycles="Cycles"):
    """(DRT's seconds per sample, Cycles', the sample count) of bench/run.py's uniform curves at the
    largest count both rendered (each point a render of its own, so fixed costs spread the most)."""
    found = _results(name)
    if found is None:
        return None
    curves = found["curves"]
    if drt not in curves or cycles not in curves:
        return None
    points = [{p[4]: p[0] for p in curves[k]} for k in (drt, cycles)]
    spp = max(set(points[0]) & set(points[1]), default=None)
    return None if spp is None else (points[0][spp] / spp, points[1][spp] / spp, spp)


MEMORY_SCRIPT = """
import sys
sys.path[:0] = [{root!r}, {root!r} + '/bench']
sys.argv = ["x"]
from scenes import load, settings
from drt_engine.core.render.render import Renderer
import drt_engine
from tests.support.memory import peak_resident_mb
drt_engine.register()
scene, data = load({name!r}, 1920, 1080)
before = peak_resident_mb()
result = Renderer(data, settings(scene, samples={samples}, threads=0,
                                 passes=("Combined", "Noise"))).render()
after = peak_resident_mb()
print("MEMORY", before, after, result.stats["elapsed"], result.passes["Combined"].shape)
"""


def peak_memory(name, samples):
    """(peak MB before the renderer, peak MB of the whole render, seconds, image shape) in a fresh process."""
    code = MEMORY_SCRIPT.format(root=str(ROOT), name=name, samples=samples)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    line = next(x for x in out.splitlines() if x.startswith("MEMORY"))
    _, before, after, seconds, *shape = line.split(maxsplit=4)
    return float(before), float(after), float(seconds), " ".join(shape)


def fmt(x, spec=".2f"):
    return "—" if x is None else format(x, spec)


def table(rows, memory, startup, width, samples, cores, memory_scene, memory_samples) -> str:
    lines = [
        "# DRT throughput and memory",
        "",
        f"Made by `make bench` (bench/throughput.py) on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
        f"{cores} cores, Python {sys.version.split()[0]}, NumPy {np.__version__}; machine load average "
        f"{os.getloadavg()[0]:.1f} when it ended. Scenes at width {width} px, DRT {samples} spp. Raw: the scene's "
        "own camera rays through the binding's batch kernel on its top-level Embree scene only. DRT: every "
        f"ray it traced (all kinds) over its render time. Each figure the best of {ROUNDS} alternating rounds. "
        "Mrays/s per wall second, and per CPU second of the process on 1 thread (which other "
        "processes on the machine disturb less).",
        "",
        "| scene | raw 1 thread | raw all | DRT 1 thread | DRT all | DRT / raw, all | per CPU s: raw, DRT, "
        f"ratio (1 thread, target {TARGET_RATIO}) | DRT wall time, 1 thread / all (target {TARGET_SPEEDUP}) "
        "| raw Embree, all / 1 thread |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['name']} | {r['raw1'] / 1e6:.2f} | {r['raw'] / 1e6:.2f} | {r['drt1'] / 1e6:.2f} | "
                     f"{r['drt'] / 1e6:.2f} | {r['drt'] / r['raw']:.3f} | {r['raw_cpu'] / 1e6:.2f}, "
                     f"{r['drt_cpu'] / 1e6:.2f}, {r['drt_cpu'] / r['raw_cpu']:.3f} | "
                     f"{r['seconds1']:.2f} s / {r['seconds']:.2f} s = {r['seconds1'] / r['seconds']:.2f} | "
                     f"{r['raw'] / r['raw1']:.2f} |")
    lines += ["", "Time to relMSE 1e-3 (seconds) from bench/run.py's curves (its resolution and settings; "
              "DRT's best curve against Cycles' best, diffuse bounces 0, with or without its adaptive sampling):",
              "", "| scene | DRT | Cycles | DRT / Cycles | bench/run.py at |", "|---|---|---|---|---|"]
    for r in rows:
        d, dk, c, ck, where = r["to_error"]
        ratio = f"{d / c:.1f}" if d and c else "—"
        lines.append(f"| {r['name']} | {fmt(d)}{f' ({dk})' if dk else ''} | {fmt(c)}{f' ({ck})' if ck else ''} "
                     f"| {ratio} | {where} |")
    lines += ["", f"Time per sample from the same curves (DRT's uniform SOBOL against Cycles without adaptive sampling, "
              f"seconds over samples at the largest count both rendered; target {TARGET_PER_SAMPLE}x):", "",
              "| scene | DRT ms / sample | Cycles ms / sample | DRT / Cycles | at |", "|---|---|---|---|---|"]
    for r in rows:
        if r["per_sample"] is None:
            lines.append(f"| {r['name']} | — | — | — | no bench/run.py results |")
            continue
        d, c, spp = r["per_sample"]
        lines.append(f"| {r['name']} | {1e3 * d:.1f} | {1e3 * c:.1f} | {d / c:.2f} | {spp} spp |")
    lines += ["", "Rays traced per kind (all threads) and the render plan:", ""]
    for r in rows:
        kinds = ", ".join(f"{k} {v}" for k, v in r["rays"].items())
        lines.append(f"- {r['name']}: {kinds}. {r['plan']}")
    if memory is not None:
        before, after, seconds, shape = memory
        lines += ["", f"Peak memory, {memory_scene} at 1920x1080, {memory_samples} spp, every core: {after:.0f} MB "
                  f"(VmHWM; {before:.0f} MB of it before the renderer: Python, bpy, the scene and its export; "
                  f"render {seconds:.1f} s, image {shape}): the render's own {after - before:.0f} MB. Target: the "
                  f"render's own under {TARGET_MEMORY} MB."]
    lines += ["", f"Start-up (bench/startup.py, {startup['where']}; each line a fresh process; start-up = first render "
              f"minus a second one in the same process; cold: nothing cached or shipped; shipped: the kernels "
              f"the Linux zip ships, what an installed extension's first render loads; targets: the first render "
              f"after an install under {TARGET_COLD:.0f} s wall, warm under {TARGET_WARM:.0f} s):", ""]
    lines += [f"- {line}" for line in describe(startup).splitlines()] + [""]
    return "\n".join(lines) + "\n"


def write_results_section(text):
    """Put the table into bench/RESULTS.md between its markers (the rest of the file is bench/run.py's)."""
    path = ROOT / "bench" / "RESULTS.md"
    old = path.read_text() if path.exists() else ""
    body = text.replace("# DRT throughput and memory", "## Throughput and memory (bench/throughput.py, also in "
                        "[THROUGHPUT.md](THROUGHPUT.md))", 1)
    section = f"{MARK_BEGIN}\n{body}{MARK_END}\n"
    pattern = re.compile(re.escape(MARK_BEGIN) + ".*?" + re.escape(MARK_END) + "\n?", re.S)
    new = pattern.sub(lambda _: section, old) if MARK_BEGIN in old else old + ("\n" if old else "") + section
    path.write_text(new)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=256)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--memory-scene", default="cornell_box")
    parser.add_argument("--memory-samples", type=int, default=2)
    parser.add_argument("--no-memory", action="store_true", help="skip the 1920x1080 memory render")
    args = parser.parse_args(argv)
    drt_engine.register()
    cores = os.cpu_count() or 1
    rows = []
    for name in args.scenes:
        scene, data = load(name, args.width)
        prepared = PreparedScene(data)
        cam = camera_batch(data, WAVE)
        drt_rate(data, prepared, scene, 1, 1)  # compile or load the kernels before timing (Cycles' are built in)
        rounds = [(raw_embree(prepared.geometry, cam, 1), raw_embree(prepared.geometry, cam, cores),
                   drt_rate(data, prepared, scene, 1, args.samples), drt_rate(data, prepared, scene, 0, args.samples))
                  for _ in range(ROUNDS)]
        # each figure the best of its rounds: a shared machine's neighbours only ever slow a run down
        raw1, raw_cpu = (max(r[0][i] for r in rounds) for i in (0, 1))
        raw = max(r[1][0] for r in rounds)
        drt1, drt_cpu = max(r[2][0] for r in rounds), max(r[2][1] for r in rounds)
        seconds1 = min(r[2][2] for r in rounds)
        drt, seconds, rays, plan = max(r[3][0] for r in rounds), min(r[3][2] for r in rounds), *rounds[0][3][3:]
        found = time_to_error(name) or (None, None, None, None, "no bench/run.py results")
        rows.append(dict(name=name, raw1=raw1, raw=raw, raw_cpu=raw_cpu, drt1=drt1, drt=drt, drt_cpu=drt_cpu,
                         seconds1=seconds1, seconds=seconds, rays=rays, plan=plan, to_error=found,
                         per_sample=time_per_sample(name)))
        print(f"{name}: raw {raw1 / 1e6:.2f} / {raw / 1e6:.2f} Mrays/s, DRT {drt1 / 1e6:.2f} / {drt / 1e6:.2f} "
              f"Mrays/s ({seconds1:.1f} s / {seconds:.1f} s), ratio {drt / raw:.3f}; per CPU s "
              f"{drt_cpu / raw_cpu:.3f}; to 1e-3: DRT {fmt(found[0])} Cycles {fmt(found[2])}", flush=True)
    memory = None if args.no_memory else peak_memory(args.memory_scene, args.memory_samples)
    if memory is not None:
        print(f"peak memory {memory[1]:.0f} MB ({memory[0]:.0f} MB before the renderer)", flush=True)
    startup = measure()
    startup["where"] = "cornell_box at 64 px, 1 spp, 1 thread"
    print(describe(startup), flush=True)
    text = table(rows, memory, startup, args.width, args.samples, cores, args.memory_scene, args.memory_samples)
    (ROOT / "bench" / "THROUGHPUT.md").write_text(text)
    write_results_section(text)
    write_block("throughput", text.split("\n", 2)[2])  # docs/performance.md's copy, without the title
    print(text)


if __name__ == "__main__":
    main()
