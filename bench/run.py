"""make bench: error against time for DRT's sampling strategies and for Cycles, per sample scene.

Both renderers get the same chances. For each scene (WIDTH px wide by default):
- references: DRT's (SOBOL, many samples, another seed) and Cycles' (the mean of two seeds);
  every error below is the true relMSE against the renderer's own reference, less the
  reference's own estimated variance;
- plain sampling on one sample-count grid (GRID_COUNTS) for both: DRT SOBOL one progressive
  render read where its samples per pixel reach a count of the grid (what a render capped there
  returns), Cycles one render per count; DRT GRID and JITTERED one render per count of PATTERN_COUNTS (their
  patterns depend on the count);
- adaptive sampling the same way for both: one render per noise threshold (THRESHOLDS) and per
  Min Samples (MIN_SAMPLES, 0 = each renderer's automatic rule), sample cap ``--cap``; the curve
  is the lower envelope of all those renders ("SOBOL+NOISE", "Cycles adaptive"), and the
  automatic Min Samples alone is its own curve ("... auto min": what a user who only ticks
  Adaptive Sampling and picks a threshold gets);
- DRT SOBOL + CONTRAST adaptive: one progressive render read at the same counts.
Every render runs once (best-of for neither): times are CPU seconds of this process, every
thread counted (both renderers run in it), which a shared machine disturbs far less than wall
time. DRT's are the renderer's own (scene export and BVH build excluded, the bench's error
measurements subtracted); Cycles' are those of the render less those of a 1-sample render of
the same scene (its sync and BVH build).

Writes bench/results/<scene>.png (log-log plot), bench/results/<scene>.json and
bench/results/RESULTS.md; with --publish also bench/RESULTS.md, the plots in bench/plots/ and
docs/adaptive-sampling.md's block ``bench-adaptive`` (bench/blocks.py).
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
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import drt_engine  # noqa: E402
from drt_engine.core.render.adaptive import true_error  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from drt_engine.core.render.report import plot_loglog  # noqa: E402
from drt_engine.core.settings import RenderSettings  # noqa: E402
from blocks import RESULTS_THROUGHPUT, write_block  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402

from tests.support.render_helpers import configure_cycles, read_channels  # noqa: E402  (the tests' Cycles set-up and EXR reader)

WIDTH = 256
LEVELS = (1e-2, 3e-3, 1e-3)
GRID_COUNTS = (4, 8, 16, 32, 64, 128, 256)
"""Samples per pixel of the plain-sampling points, the same for DRT and Cycles."""
PATTERN_COUNTS = (4, 16, 64)
"""Sample counts of DRT's GRID and JITTERED renders (one render each: kept few at 256 px)."""
THRESHOLDS = (0.02, 0.01, 0.005, 0.0025)
MIN_SAMPLES = (0, 4, 16)
"""Min Samples searched for both renderers' adaptive sampling; 0 = the renderer's automatic rule."""
CURVES = ("GRID", "JITTERED", "SOBOL", "SOBOL+NOISE", "SOBOL+NOISE auto min", "SOBOL+CONTRAST", "Cycles",
          "Cycles adaptive", "Cycles adaptive auto min")


def drt_settings(scene, **kw) -> RenderSettings:
    return settings(scene, **{"threads": 0, "passes": ("Combined", "Noise"), **kw})


def drt_run(data, settings, reference=None):
    """One DRT render: its result, (CPU seconds, true relMSE, estimated relMSE, mean spp, most spp in
    a pixel) at every logged step (true errors with a reference only) and the render's CPU seconds,
    the measuring excluded."""
    points = []
    spent = 0.0

    def progress(update):
        nonlocal spent
        if update.entry is not None and reference is not None:
            t = time.process_time()
            rel = true_error(update.passes()["Combined"][..., :3], *reference)[1]
            e = update.entry
            points.append((e["cpu"] - spent, rel, e["relmse"], e["spp_mean"], e["spp_max"]))
            spent += time.process_time() - t
        return True

    result = Renderer(data, settings).render(progress=progress)
    return result, points, result.stats["cpu"] - spent


def on_grid(points):
    """The steps of a progressive render whose most samples in a pixel is a count of GRID_COUNTS."""
    return [p for p in points if p[4] in GRID_COUNTS]


def cycles_run(scene, out_dir, samples, seed=0, threshold=None, min_samples=0):
    configure_cycles(scene, samples, seed, threshold)
    scene.cycles.adaptive_min_samples = min_samples
    scene.render.engine = "CYCLES"
    path = Path(out_dir) / "cycles.exr"
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    image_settings = scene.render.image_settings
    image_settings.media_type = "IMAGE"
    image_settings.file_format = "OPEN_EXR"
    image_settings.color_depth = "32"
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


def envelope(points):
    """The points no other point beats in both time and error (the lower envelope of a set of
    renders with different settings): the best a user who tried them all could get."""
    front = []
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if p[1] > 0 and (not front or p[1] < front[-1][1]):
            front.append(p)
    return front


def bench_scene(name, width, ref_samples, cap, out_dir, tmp, diffuse_bounces=0):
    scene, data = load(name, width)
    scene.drt.diffuse_bounces = diffuse_bounces  # both renderers' (configure_cycles gives Cycles DRT's)
    r = scene.render
    curves = {}
    log = print

    t = time.perf_counter()
    ref = Renderer(data, drt_settings(scene, samples=ref_samples, seed=1 << 20)).render()
    reference = (ref.passes["Combined"][..., :3].astype(np.float64), ref.passes["Noise"].astype(np.float64) ** 2)
    log(f"  DRT reference {ref_samples} spp: {time.perf_counter() - t:.1f} s, est. relMSE {ref.stats['relmse']:.2e}")

    counts = [n for n in GRID_COUNTS if n <= cap]
    for pattern in ("GRID", "JITTERED"):
        pts = []
        for n in PATTERN_COUNTS:
            res, _, cpu = drt_run(data, drt_settings(scene, samples=n, sampling_pattern=pattern))
            _, rel = true_error(res.passes["Combined"][..., :3], *reference)
            pts.append((cpu, rel, res.stats.get("relmse"), res.stats["samples_mean"], n))
        curves[pattern] = pts
        log(f"  {pattern}: {[(round(p[0], 2), f'{p[1]:.1e}') for p in pts]}")

    _, pts, _ = drt_run(data, drt_settings(scene, samples=cap), reference)
    curves["SOBOL"] = on_grid(pts)
    log(f"  SOBOL: {[(round(p[0], 2), f'{p[1]:.1e}') for p in curves['SOBOL']]}")

    pts = []
    for th in THRESHOLDS:
        for m in MIN_SAMPLES:
            res, _, cpu = drt_run(data, drt_settings(scene, samples=cap, use_adaptive_sampling=True,
                                                     adaptive_threshold=th, adaptive_min_samples=m))
            _, rel = true_error(res.passes["Combined"][..., :3], *reference)
            pts.append((cpu, rel, res.stats.get("relmse"), res.stats["samples_mean"], None, th, m))
    curves["SOBOL+NOISE"] = envelope(pts)
    curves["SOBOL+NOISE auto min"] = [p for p in pts if p[6] == 0]
    log(f"  SOBOL+NOISE: {[(p[5], p[6], round(p[0], 2), f'{p[1]:.1e}', round(p[3], 1)) for p in pts]}")

    _, pts, _ = drt_run(data, drt_settings(scene, samples=cap, use_adaptive_sampling=True,
                                           adaptive_mode="CONTRAST"), reference)
    curves["SOBOL+CONTRAST"] = on_grid(pts)
    log(f"  SOBOL+CONTRAST: {[(round(p[0], 2), f'{p[1]:.1e}') for p in curves['SOBOL+CONTRAST']]}")

    t = time.perf_counter()
    cref_a, _ = cycles_run(scene, tmp, ref_samples, seed=12345)
    cref_b, _ = cycles_run(scene, tmp, ref_samples, seed=54321)
    # the mean of two seeds, and its variance from their difference: Var(mean) = E[(a - b)^2] / 4
    cycles_ref = ((cref_a + cref_b) / 2, (cref_a - cref_b) ** 2 / 4)
    log(f"  Cycles references 2 x {ref_samples} spp: {time.perf_counter() - t:.1f} s")
    _, overhead = cycles_run(scene, tmp, 1)
    pts = []
    for n in counts:
        img, sec = cycles_run(scene, tmp, n)
        pts.append((max(sec - overhead, 1e-3), true_error(img, *cycles_ref)[1], None, n, n))
    curves["Cycles"] = pts
    pts = []
    for th in THRESHOLDS:
        for m in MIN_SAMPLES:
            img, sec = cycles_run(scene, tmp, cap, threshold=th, min_samples=m)
            pts.append((max(sec - overhead, 1e-3), true_error(img, *cycles_ref)[1], None, None, None, th, m))
    curves["Cycles adaptive"] = envelope(pts)
    curves["Cycles adaptive auto min"] = [p for p in pts if p[6] == 0]
    log(f"  Cycles: {[(round(p[0], 2), f'{p[1]:.1e}') for p in curves['Cycles']]}; overhead {overhead:.2f} s")
    log(f"  Cycles adaptive: {[(p[5], p[6], round(p[0], 2), f'{p[1]:.1e}') for p in pts]}")

    plot_loglog(out_dir / f"{name}.png", [(k, [(p[0], p[1]) for p in sorted(curves[k])]) for k in CURVES],
                f"{name} {r.resolution_x}x{r.resolution_y}: true relMSE vs CPU s", size=(760, 420))
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


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{cpu}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the end, "
            f"{platform.system()} {platform.release()}; Python {platform.python_version()}, "
            f"bpy {bpy.app.version_string}")


def settings_text(width, ref_samples, cap) -> str:
    return (f"Scenes at width {width} px; references {ref_samples} spp (DRT: SOBOL, another seed; Cycles: "
            f"two seeds), each renderer against its own, less the reference's variance; sample cap {cap}; "
            f"plain sampling at {', '.join(map(str, GRID_COUNTS))} spp for both (DRT GRID and JITTERED at "
            f"{', '.join(map(str, PATTERN_COUNTS))}); adaptive sampling one render "
            f"per noise threshold ({', '.join(f'{t:g}' for t in THRESHOLDS)}) and Min Samples "
            f"({', '.join('auto' if m == 0 else str(m) for m in MIN_SAMPLES)}) for both, the curve the "
            "lower envelope of them all (\"auto min\": automatic Min Samples only). One run per setting for "
            "both; CPU seconds of the process (all threads), DRT without export and BVH build, Cycles less "
            "its 1-sample render.")


SUMMARY = (("SOBOL+NOISE", "SOBOL"), ("SOBOL+NOISE auto min", "SOBOL"), ("Cycles adaptive", "Cycles"),
           ("Cycles adaptive auto min", "Cycles"))


def summary(results) -> list[str]:
    """Per scene: each adaptive curve's speed-up over its renderer's plain sampling, and DRT's best
    time over Cycles' best, at relMSE 1e-3 (3e-3 in brackets)."""
    lines = ["| scene | " + " | ".join(f"{a} over {b}" for a, b in SUMMARY) + " | DRT best / Cycles best, time |",
             "|---" * (len(SUMMARY) + 2) + "|"]
    for name, res in results.items():
        t = res["times"]
        cells = [f"{ratio(t[b][2], t[a][2])} ({ratio(t[b][1], t[a][1])})" for a, b in SUMMARY]
        best = {}
        for side in ("DRT", "Cycles"):
            found = [t[k][2] for k in CURVES if k.startswith("Cycles") == (side == "Cycles") and t[k][2]]
            best[side] = min(found) if found else None
        cells.append(ratio(best["DRT"], best["Cycles"]).rstrip("x"))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def table(results, width, ref_samples, cap, plots=".") -> str:
    lines = ["# DRT benchmark: time to reach a relMSE", "",
             f"Made by `make bench` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}.", "",
             settings_text(width, ref_samples, cap) + " Times to each relMSE are log-log interpolated between "
             "points (— = not reached); the ratio is Cycles' time without adaptive sampling over this curve's "
             "time at 1e-3 (above 1: faster than Cycles); spp is the mean samples per pixel at 1e-3.", "",
             "Speed-ups at relMSE 1e-3 (at 3e-3 in brackets):", ""] + summary(results) + [""]
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


def adaptive_block(results, width, ref_samples, cap) -> str:
    """docs/adaptive-sampling.md's adaptive benchmark paragraph: where it was made, with what, and the speed-ups."""
    return "\n".join([f"Made by `make bench` on {time.strftime('%Y-%m-%d', time.gmtime())} ({machine()}). "
                      + settings_text(width, ref_samples, cap), "", "Speed-up at relMSE 1e-3 (at 3e-3 in "
                      "brackets), each adaptive curve over its own renderer's plain sampling:", ""]
                     + summary(results))


def publish_table(text):
    """Write bench/RESULTS.md, keeping bench/throughput.py's section of it."""
    path = ROOT / "bench" / "RESULTS.md"
    old = path.read_text() if path.exists() else ""
    begin, end = RESULTS_THROUGHPUT
    kept = re.search(re.escape(begin) + ".*?" + re.escape(end) + "\n?", old, re.S)
    path.write_text(text + ("\n" + kept.group(0) if kept else ""))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=WIDTH)
    parser.add_argument("--reference-samples", type=int, default=1024)
    parser.add_argument("--cap", type=int, default=GRID_COUNTS[-1])
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--out", default=str(ROOT / "bench" / "results"))
    parser.add_argument("--diffuse-bounces", type=int, default=0, help="light bouncing off diffuse surfaces, in both "
                        "renderers (not published: --out another folder)")
    parser.add_argument("--publish", action="store_true", help="also write bench/RESULTS.md, the plots in "
                        "bench/plots/ and docs/adaptive-sampling.md's adaptive benchmark block (committed)")
    args = parser.parse_args(argv)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    drt_engine.register()
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            print(f"{name}:", flush=True)
            results[name] = bench_scene(name, args.width, args.reference_samples, args.cap, out_dir, tmp,
                                        args.diffuse_bounces)
    text = table(results, args.width, args.reference_samples, args.cap)
    (out_dir / "RESULTS.md").write_text(text)
    print(text)
    if args.publish:
        plots = ROOT / "bench" / "plots"
        plots.mkdir(exist_ok=True)
        for name in results:
            shutil.copyfile(out_dir / f"{name}.png", plots / f"{name}.png")
        publish_table(table(results, args.width, args.reference_samples, args.cap, "plots"))
        write_block("bench-adaptive", adaptive_block(results, args.width, args.reference_samples, args.cap))


if __name__ == "__main__":
    main()
