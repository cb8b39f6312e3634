"""Measures what adaptive sampling's defaults and error estimate are worth, against references.

``gain``: per scene, a uniform SOBOL render and an adaptive one with the default settings
(Adaptive Sampling ticked, nothing else changed) at the scene's own sample count, several
seeds; the true relMSE of each against a 2048-sample reference; the ratio is uniform's
relMSE, interpolated log-log in CPU time at the adaptive render's end, over adaptive's,
pooled over the seeds (mean relMSE). Also the soft-shadow scene (tests/support/scenes.py)
under a time limit, both renders given the same limit and a cap they cannot reach (if the
adaptive render ends sooner, every pixel under the threshold, uniform is read at its time).

``calibration``: at every logged step of uniform and default-adaptive renders, the
estimated relMSE (``adaptive.image_error``) against the true one, each averaged over the
seeds at the k-th step; and renders with ``target_error`` set, their true relMSE at the stop.
``--diffuse-bounces N`` measures it with light bouncing off diffuse surfaces (its own results,
references and docs block ``adaptive-calibration-gi``).

Writes bench/results/adaptive_<what>.json; ``--publish`` also writes the table into docs/adaptive-sampling.md's
block ``adaptive-<what>`` (bench/blocks.py) and the measurements to bench/adaptive_<what>.json
(committed).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import numpy as np  # noqa: E402

from drt_engine.core.render.adaptive import true_error  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from drt_engine.core.settings import RenderSettings  # noqa: E402
from blocks import write_block  # noqa: E402
from references import cached_reference  # noqa: E402

OUT = ROOT / "bench" / "results"
REFERENCE_SAMPLES = 2048
TARGETS = (3e-3, 1e-3)


def reference(name, data, base):
    """The scene's 2048-sample reference and its estimated variance, cached per scene, size and
    diffuse bounces."""
    w, h = data.camera.window_size
    settings = RenderSettings(samples=REFERENCE_SAMPLES, seed=1 << 20, **{**base, "passes": ("Combined", "Noise")})
    return cached_reference(OUT / f"reference_{name}_{w}x{h}{_gi(base.get('diffuse_bounces', 0))}.npz",
                            Renderer(data, settings).render)


def _gi(bounces: int) -> str:
    """The file and block suffix of measurements with diffuse bounces."""
    return f"_diffuse{bounces}" if bounces else ""


def steps(data, settings, truth):
    """(CPU s, mean spp, estimated relMSE, true relMSE, stopped) at every logged step of one render."""
    out = []
    spent = 0.0

    def progress(update):
        nonlocal spent
        if update.entry is not None:
            t = time.process_time()
            rel = true_error(update.passes()["Combined"][..., :3], *truth)[1]
            e = update.entry
            out.append([e["cpu"] - spent, e["spp_mean"], e["relmse"], rel, e.get("stopped")])
            spent += time.process_time() - t
        return True

    result = Renderer(data, settings).render(progress=progress)
    if out and result.stats["stopped_by"] and not out[-1][4]:
        out[-1][4] = result.stats["stopped_by"]
    return out


def log_interp(points, t):
    """relMSE of a (time, relMSE) curve at time t, log-log between its points (clamped at its ends)."""
    pts = sorted((a, b) for a, b in points if a > 0 and b > 0)
    ts, es = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.exp(np.interp(math.log(t), ts, es)))


def sample_scenes(width, names, diffuse_bounces=0):
    import drt_engine
    from scenes import load

    drt_engine.register()
    for name in names:
        scene, data = load(name, width)
        base = dict(max_depth=scene.drt.max_depth, filter_type=scene.drt.filter_type,
                    filter_size=scene.render.filter_size, threads=0,
                    **({"diffuse_bounces": diffuse_bounces} if diffuse_bounces else {}))
        yield name, data, base, scene.drt.samples


def gain_row(name, data, base, samples, seeds, time_limit=0.0, min_samples=0, threshold=None):
    truth = reference(name, data, base)
    uniform, adaptive = [], []
    for seed in seeds:
        common = dict(base, samples=samples, seed=seed, time_limit=time_limit)
        uniform.append(steps(data, RenderSettings(**common), truth))
        chosen = {} if threshold is None else {"adaptive_threshold": threshold}
        adaptive.append(steps(data, RenderSettings(**common, use_adaptive_sampling=True, adaptive_min_samples=min_samples,
                                                   **chosen), truth))
    # uniform's error at the CPU time adaptive took, seed by seed: the same time when both run to the
    # limit, and a fair one when adaptive sampling ends sooner (every pixel under the threshold)
    u = float(np.mean([log_interp([(p[0], p[3]) for p in su], sa[-1][0]) for su, sa in zip(uniform, adaptive)]))
    a = float(np.mean([s[-1][3] for s in adaptive]))
    row = {"scene": name if threshold is None else f"{name}, threshold {threshold:g}", "samples": samples,
           "time_limit": time_limit, "seeds": len(seeds),
           "uniform_relmse": u, "adaptive_relmse": a, "gain": u / a,
           "adaptive_cpu": float(np.mean([s[-1][0] for s in adaptive])),
           "adaptive_spp_mean": float(np.mean([s[-1][1] for s in adaptive])),
           "uniform_spp_mean": float(np.mean([s[-1][1] for s in uniform])),
           "stopped_by": sorted({s[-1][4] for s in adaptive if s[-1][4]})}
    print(json.dumps(row), flush=True)
    return row


def gain(args):
    rows = [gain_row(*scene, seeds=range(args.seeds), min_samples=args.min_samples)
            for scene in sample_scenes(args.width, args.scenes)]
    from tests.support.scenes import soft_shadow_scene

    data, base = soft_shadow_scene(args.soft_width)
    for threshold in args.soft_thresholds:  # None: the default threshold
        rows.append(gain_row("soft_shadow", data, base, 4096, range(args.seeds), time_limit=args.time_limit,
                             min_samples=args.min_samples, threshold=threshold))
    return rows


def calibration_rows(name, data, base, samples, seeds, cap):
    truth = reference(name, data, base)
    rows = []
    for label, extra in (("uniform", {}), ("adaptive", {"use_adaptive_sampling": True})):
        runs = [steps(data, RenderSettings(**base, samples=cap, seed=seed, **extra), truth) for seed in seeds]
        for k in range(min(len(r) for r in runs)):
            est = float(np.mean([r[k][2] for r in runs]))
            true = float(np.mean([r[k][3] for r in runs]))
            rows.append({"scene": name, "run": label, "step": k, "spp_mean": float(np.mean([r[k][1] for r in runs])),
                         "estimated": est, "true": true, "ratio": est / true})
            print(json.dumps(rows[-1]), flush=True)
    for target in TARGETS:
        runs = [steps(data, RenderSettings(**base, samples=1 << 16, seed=seed, target_error=target,
                                           use_adaptive_sampling=True), truth) for seed in seeds]
        true = float(np.mean([r[-1][3] for r in runs]))
        rows.append({"scene": name, "run": "target", "target": target, "true": true, "ratio": true / target,
                     "spp_mean": float(np.mean([r[-1][1] for r in runs])),
                     "stopped_by": sorted({r[-1][4] for r in runs if r[-1][4]})})
        print(json.dumps(rows[-1]), flush=True)
    return rows


def calibration(args):
    rows = []
    for name, data, base, samples in sample_scenes(args.width, args.scenes, args.diffuse_bounces):
        rows += calibration_rows(name, data, base, samples, range(args.seeds), args.cap)
    return rows


def gain_table(rows) -> str:
    lines = ["| scene | samples / time limit | adaptive: CPU s, mean spp, stopped by | true relMSE, uniform at that "
             "CPU time | adaptive (defaults) | gain |", "|---|---|---|---|---|---|"]
    for r in rows:
        budget = f"{r['time_limit']:g} s limit" if r["time_limit"] else f"{r['samples']} spp"
        lines.append(f"| {r['scene']} | {budget} | {r['adaptive_cpu']:.2f}, {r['adaptive_spp_mean']:.1f}, "
                     f"{', '.join(r['stopped_by'])} | {r['uniform_relmse']:.2e} | {r['adaptive_relmse']:.2e} "
                     f"| {r['gain']:.2f}x |")
    return "\n".join(lines)


def calibration_table(rows) -> str:
    lines = ["| scene | run | estimated / true relMSE, each logged step (min-max) | steps |",
             "|---|---|---|---|"]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for run in ("uniform", "adaptive"):
            ratios = [r["ratio"] for r in rows if r["scene"] == scene and r["run"] == run]
            if ratios:
                lines.append(f"| {scene} | {run} | {min(ratios):.2f}-{max(ratios):.2f} | {len(ratios)} |")
    lines += ["", "| scene | target relMSE | true relMSE at the stop | true / target | mean spp | stopped by |",
              "|---|---|---|---|---|---|"]
    for r in rows:
        if r["run"] == "target":
            lines.append(f"| {r['scene']} | {r['target']:g} | {r['true']:.2e} | {r['ratio']:.2f} | {r['spp_mean']:.0f} "
                         f"| {', '.join(r['stopped_by'])} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=("gain", "calibration"))
    parser.add_argument("--width", type=int, default=64)
    parser.add_argument("--soft-width", type=int, default=160)
    parser.add_argument("--time-limit", type=float, default=6.0)
    parser.add_argument("--cap", type=int, default=256)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=("cornell_box", "glossy_spheres", "dof_row", "motion_blur"))
    parser.add_argument("--min-samples", type=int, default=0, help="adaptive Min Samples (0: automatic, the default)")
    parser.add_argument("--soft-thresholds", type=float, nargs="*", default=[None],
                        help="noise thresholds of the soft-shadow rows (default: the default threshold only)")
    parser.add_argument("--diffuse-bounces", type=int, default=0, help="calibration with light bouncing off diffuse "
                        "surfaces (its own results and docs block)")
    parser.add_argument("--publish", action="store_true", help="also write docs/adaptive-sampling.md's block and bench/adaptive_<what>.json")
    parser.add_argument("--publish-only", action="store_true", help="publish the last run's results without rendering")
    parser.add_argument("--append", action="store_true", help="add this run's rows to the last run's saved results "
                        "(scenes run one process each)")
    args = parser.parse_args(argv)
    gi = _gi(getattr(args, "diffuse_bounces", 0))
    saved = OUT / f"adaptive_{args.what}{gi}.json"
    if args.publish_only:
        found = json.loads(saved.read_text())
        args, rows = argparse.Namespace(**{"diffuse_bounces": 0, **found["args"]}), found["rows"]
        args.publish = True
    else:
        rows = gain(args) if args.what == "gain" else calibration(args)
        if args.append:
            rows = json.loads(saved.read_text())["rows"] + rows
        OUT.mkdir(parents=True, exist_ok=True)
        saved.write_text(json.dumps({"args": vars(args), "rows": rows,
                                     "made": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}, indent=1))
    text = gain_table(rows) if args.what == "gain" else calibration_table(rows)
    print(text)
    if args.publish:
        (ROOT / "bench" / f"adaptive_{args.what}{gi}.json").write_text(saved.read_text())
        made = json.loads(saved.read_text()).get("made") or time.strftime(
            "%Y-%m-%d %H:%M UTC", time.gmtime(saved.stat().st_mtime))
        if args.what == "gain":
            setup = (f"the sample scenes at {args.width} px wide, the soft-shadow scene at {args.soft_width} px "
                     f"under a {args.time_limit:g} s limit")
        else:
            setup = (f"{args.width} px wide, uniform and adaptive renders to {args.cap} spp, target-error stops"
                     + (f", diffuse bounces {args.diffuse_bounces}" if args.diffuse_bounces else ""))
        command = f"{args.what}" + (f" --diffuse-bounces {args.diffuse_bounces}" if args.diffuse_bounces else "")
        write_block(f"adaptive-{args.what}" + ("-gi" if gi else ""),
                    f"Measured by `python bench/adaptive_study.py {command}` on {made}: "
                    f"{setup}, {args.seeds} seeds pooled, references {REFERENCE_SAMPLES} spp.\n\n{text}")


if __name__ == "__main__":
    main()
