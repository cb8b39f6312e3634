"""make bench: error against time for DRT's sampling strategies and for Cycles, per sample scene.

For each scene (at a small resolution so the whole run takes minutes on two cores):
- a DRT reference (SOBOL, many samples, another seed) and a Cycles reference (the
  mean of two seeds); every error below is the true relMSE against the renderer's own
  reference, less the reference's own estimated variance;
- DRT GRID and JITTERED: one render per sample count (their patterns depend on it);
- DRT SOBOL: one progressive render, its error at every logged step;
- DRT SOBOL + NOISE adaptive: one progressive render (automatic threshold, Min Samples
  4), its error at every round: each is the image a target error or time limit met
  there would return; and, as Cycles adaptive below, one render per noise threshold
  with automatic min samples ("auto min");
- DRT SOBOL + CONTRAST adaptive: one progressive render, its error at every step;
- Cycles with diffuse bounces 0 (a distribution ray tracer), without and with its
  adaptive sampling: one render per sample count, resp. noise threshold.
Times are CPU seconds of this process, every thread counted (both renderers run in
it): on a shared, loaded machine they vary far less than wall time. DRT's are the
renderer's own (scene export and BVH build excluded, the bench's error measurements
subtracted); Cycles' are those of the render less those of a 1-sample render of the
same scene (its sync and BVH build).

Writes bench/results/<scene>.png (log-log plot), bench/results/<scene>.json, and
bench/results/RESULTS.md (the table); with --publish also bench/RESULTS.md and the
plots in bench/plots/, the copies that are committed.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import drt_engine  # noqa: E402
from drt_engine.core.adaptive import true_error  # noqa: E402
from drt_engine.core.render import Renderer  # noqa: E402
from drt_engine.core.report import plot_loglog  # noqa: E402
from drt_engine.core.settings import RenderSettings  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402

sys.path.insert(0, str(ROOT / "tests" / "blender"))
from render_helpers import configure_cycles, read_channels  # noqa: E402  (the tests' Cycles set-up and EXR reader)

LEVELS = (1e-2, 3e-3, 1e-3, 1e-4)
SWEEP = (4, 16, 64, 256, 1024)
THRESHOLDS = (0.16, 0.08, 0.04, 0.02, 0.01, 0.005, 0.0025, 0.00125)
REPEAT = 2
"""Timed DRT renders run this many times: interference from other work only ever adds time."""
NOISE_MIN_SAMPLES = 4
"""Min Samples of the progressive SOBOL+NOISE curve: Cycles' least, the earliest test."""
CURVES = ("GRID", "JITTERED", "SOBOL", "SOBOL+NOISE", "SOBOL+NOISE auto min", "SOBOL+CONTRAST", "Cycles",
          "Cycles adaptive")


def drt_settings(scene, **kw) -> RenderSettings:
    return settings(scene, **{"threads": 0, "passes": ("Combined", "Noise"), **kw})


def drt_run(data, settings, reference=None, repeat=REPEAT):
    """One DRT render, timed ``repeat`` times (the least CPU time of each step counts).

    Returns the result, (CPU seconds, true relMSE, estimated relMSE, mean samples per
    pixel) at every logged step (true errors with a reference only) and the render's
    CPU seconds, the measuring excluded. Renders are deterministic, so every repeat
    traces the same samples and only the first is measured.
    """
    runs = []
    for run in range(repeat):
        points = []
        spent = 0.0

        def progress(update):
            nonlocal spent
            if update.entry is not None:
                t = time.process_time()
                rel = None
                if reference is not None and run == 0:
                    rel = true_error(update.passes()["Combined"][..., :3], *reference)[1]
                points.append((update.entry["cpu"] - spent, rel, update.entry["relmse"], update.entry["spp_mean"]))
                spent += time.process_time() - t
            return True

        result = Renderer(data, settings).render(progress=progress)
        runs.append((result, points, result.stats["cpu"] - spent))
    first = runs[0][1]
    points = [(min(r[1][k][0] for r in runs), *first[k][1:]) for k in range(len(first))]
    return runs[0][0], points, min(r[2] for r in runs)


def cycles_run(scene, out_dir, samples, seed=0, threshold=None):
    configure_cycles(scene, samples, seed, threshold)
    scene.render.engine = "CYCLES"
    path = Path(out_dir) / "cycles.exr"
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    settings = scene.render.image_settings
    settings.media_type = "IMAGE"
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    start = time.process_time()
    bpy.ops.render.render(write_still=True, scene=scene.name)
    seconds = time.process_time() - start
    channels = read_channels(path)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64), seconds


def time_to(points, level):
    """First time the error reaches ``level``, interpolated log-log from the point before; None if never."""
    points = sorted((t, e) for t, e, *_ in points if t > 0 and e > 0)
    for k, (t, e) in enumerate(points):
        if e <= level:
            if k == 0:
                return t
            t0, e0 = points[k - 1]
            if e0 <= e:
                return t
            f = (math.log(e0) - math.log(level)) / (math.log(e0) - math.log(e))
            return math.exp(math.log(t0) + f * (math.log(t) - math.log(t0)))
    return None


def bench_scene(name, width, ref_samples, cap, out_dir, tmp):
    scene, data = load(name, width)
    r = scene.render
    curves = {}
    log = print

    t = time.perf_counter()
    ref = Renderer(data, drt_settings(scene, samples=ref_samples, seed=1 << 20)).render()
    reference = (ref.passes["Combined"][..., :3].astype(np.float64), ref.passes["Noise"].astype(np.float64) ** 2)
    log(f"  DRT reference {ref_samples} spp: {time.perf_counter() - t:.1f} s, est. relMSE {ref.stats['relmse']:.2e}")

    for pattern in ("GRID", "JITTERED"):
        pts = []
        for n in SWEEP:
            res, _, cpu = drt_run(data, drt_settings(scene, samples=n, sampling_pattern=pattern))
            _, rel = true_error(res.passes["Combined"][..., :3], *reference)
            pts.append((cpu, rel, res.stats.get("relmse"), res.stats["samples_mean"]))
        curves[pattern] = pts
        log(f"  {pattern}: {[(round(p[0], 2), f'{p[1]:.1e}') for p in pts]}")

    _, pts, _ = drt_run(data, drt_settings(scene, samples=cap), reference)
    curves["SOBOL"] = pts
    log(f"  SOBOL: {len(pts)} steps, last {pts[-1][0]:.1f} s {pts[-1][1]:.1e}")

    _, pts, _ = drt_run(data, drt_settings(scene, samples=cap, use_adaptive_sampling=True, adaptive_threshold=0.0,
                                           adaptive_min_samples=NOISE_MIN_SAMPLES), reference)
    curves["SOBOL+NOISE"] = pts
    log(f"  SOBOL+NOISE: {[(round(p[0], 2), f'{p[1]:.1e}', round(p[3], 1)) for p in pts]}")

    pts = []
    for th in THRESHOLDS:
        res, steps, elapsed = drt_run(data, drt_settings(scene, samples=cap, use_adaptive_sampling=True,
                                                         adaptive_threshold=th), reference)
        pts.append((elapsed, steps[-1][1], steps[-1][2], res.stats["samples_mean"], th))
    curves["SOBOL+NOISE auto min"] = pts
    log(f"  SOBOL+NOISE auto min: {[(p[4], round(p[0], 2), f'{p[1]:.1e}', round(p[3], 1)) for p in pts]}")

    _, pts, _ = drt_run(data, drt_settings(scene, samples=cap, use_adaptive_sampling=True,
                                           adaptive_mode="CONTRAST"), reference)
    curves["SOBOL+CONTRAST"] = pts
    log(f"  SOBOL+CONTRAST: last {pts[-1][0]:.1f} s {pts[-1][1]:.1e}")

    t = time.perf_counter()
    cref_a, _ = cycles_run(scene, tmp, ref_samples, seed=12345)
    cref_b, _ = cycles_run(scene, tmp, ref_samples, seed=54321)
    # the mean of two seeds, and its variance from their difference: Var(mean) = E[(a - b)^2] / 4
    cycles_ref = ((cref_a + cref_b) / 2, (cref_a - cref_b) ** 2 / 4)
    log(f"  Cycles references 2 x {ref_samples} spp: {time.perf_counter() - t:.1f} s")
    _, overhead = cycles_run(scene, tmp, 1)
    pts = []
    for n in SWEEP:
        img, sec = cycles_run(scene, tmp, n)
        pts.append((max(sec - overhead, 1e-3), true_error(img, *cycles_ref)[1], None, n))
    curves["Cycles"] = pts
    pts = []
    for th in THRESHOLDS:
        img, sec = cycles_run(scene, tmp, cap, threshold=th)
        pts.append((max(sec - overhead, 1e-3), true_error(img, *cycles_ref)[1], None, None, th))
    curves["Cycles adaptive"] = pts
    log(f"  Cycles: {[(round(p[0], 2), f'{p[1]:.1e}') for p in curves['Cycles']]}; overhead {overhead:.2f} s")
    log(f"  Cycles adaptive: {[(p[4], round(p[0], 2), f'{p[1]:.1e}') for p in pts]}")

    plot_loglog(out_dir / f"{name}.png", [(k, [(p[0], p[1]) for p in sorted(curves[k])]) for k in CURVES],
                f"{name} {r.resolution_x}x{r.resolution_y}: true relMSE vs CPU s")
    (out_dir / f"{name}.json").write_text(json.dumps({"resolution": [r.resolution_x, r.resolution_y],
                                                      "reference_samples": ref_samples, "cap": cap,
                                                      "curves": curves}, indent=1))
    times = {k: [time_to(curves[k], lv) for lv in LEVELS] for k in CURVES}
    spp = {k: time_to([(p[3], p[1]) for p in curves[k] if p[3]], 1e-3) for k in CURVES}
    return {"times": times, "spp": spp}


def fmt(t):
    return "—" if t is None else f"{t:.2f}"


def ratio(s, a) -> str:
    return "—" if s is None or a is None else f"{s / a:.2f}x"


def table(results, width, ref_samples, cap, plots=".") -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    lines = [
        "# DRT benchmark: time to reach a relMSE",
        "",
        f"Machine: {cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}; "
        f"Python {platform.python_version()}, bpy {bpy.app.version_string}. Made by `make bench` "
        f"on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "",
        f"Scenes at width {width} px; DRT references {ref_samples} spp (SOBOL, another seed), Cycles "
        f"against its own reference (two seeds of {ref_samples} spp), each less its reference's variance; "
        f"sample cap {cap}. CPU seconds of the process (all threads; DRT: the less of {REPEAT} runs) to "
        "reach each relMSE (log-log interpolated between logged points; — = not reached); the ratio is "
        "Cycles' time (without adaptive sampling) over this curve's time at relMSE 1e-3 (above 1: faster "
        "than Cycles); spp is the mean samples per pixel at 1e-3. DRT times exclude export and BVH build, "
        "Cycles times exclude its 1-sample render time. SOBOL+NOISE is one progressive render (automatic "
        f"threshold, Min Samples {NOISE_MIN_SAMPLES}) read at every round; SOBOL+NOISE auto min and Cycles "
        f"adaptive are one render per noise threshold ({', '.join(f'{t:g}' for t in THRESHOLDS)}) with "
        "automatic minimum samples.",
        "",
        "The speed-up is SOBOL's time over SOBOL+NOISE's time to the same relMSE; the samples ratio "
        "is the same for the mean samples per pixel (what adaptive sampling saves before its own costs).",
        "",
        "| scene | SOBOL+NOISE speed-up over SOBOL at 1e-3 | at 1e-4 | samples ratio at 1e-3 "
        "| auto min: speed-up at 1e-3 |",
        "|---|---|---|---|---|",
    ]
    for name, res in results.items():
        t, n = res["times"], res["spp"]
        lines.append(f"| {name} | {ratio(t['SOBOL'][2], t['SOBOL+NOISE'][2])} | {ratio(t['SOBOL'][3], t['SOBOL+NOISE'][3])} "
                     f"| {ratio(n['SOBOL'], n['SOBOL+NOISE'])} | {ratio(t['SOBOL'][2], t['SOBOL+NOISE auto min'][2])} |")
    lines.append("")
    header = " | ".join(f"{lv:g}" for lv in LEVELS)
    for name, res in results.items():
        lines += [f"## {name}", "", f"| curve | {header} | Cycles / this at 1e-3 | spp at 1e-3 |",
                  "|---" * (len(LEVELS) + 3) + "|"]
        times = res["times"]
        for k in CURVES:
            spp = res["spp"][k]
            lines.append(f"| {k} | {' | '.join(fmt(v) for v in times[k])} | {ratio(times['Cycles'][2], times[k][2])} "
                         f"| {'—' if spp is None else f'{spp:.0f}'} |")
        lines += ["", f"![{name}]({plots}/{name}.png)", ""]
    return "\n".join(lines) + "\n"


def publish_table(text):
    """Write bench/RESULTS.md, keeping bench/throughput.py's section of it."""
    from bench.throughput import MARK_BEGIN, MARK_END

    path = ROOT / "bench" / "RESULTS.md"
    old = path.read_text() if path.exists() else ""
    kept = re.search(re.escape(MARK_BEGIN) + ".*?" + re.escape(MARK_END) + "\n?", old, re.S)
    path.write_text(text + ("\n" + kept.group(0) if kept else ""))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=48)
    parser.add_argument("--reference-samples", type=int, default=2048)
    parser.add_argument("--cap", type=int, default=1024)
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--out", default=str(ROOT / "bench" / "results"))
    parser.add_argument("--publish", action="store_true",
                        help="also write bench/RESULTS.md and copy the plots to bench/plots/ (committed)")
    args = parser.parse_args(argv)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    drt_engine.register()
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            print(f"{name}:", flush=True)
            results[name] = bench_scene(name, args.width, args.reference_samples, args.cap, out_dir, tmp)
    text = table(results, args.width, args.reference_samples, args.cap)
    (out_dir / "RESULTS.md").write_text(text)
    print(text)
    if args.publish:
        plots = ROOT / "bench" / "plots"
        plots.mkdir(exist_ok=True)
        for name in results:
            shutil.copyfile(out_dir / f"{name}.png", plots / f"{name}.png")
        publish_table(table(results, args.width, args.reference_samples, args.cap, "plots"))


if __name__ == "__main__":
    main()
