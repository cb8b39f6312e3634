"""Measures what the ratio estimator (shadow_estimator RATIO, core.integrator.ratio) is worth against Monte Carlo.

Per scene (the soft-shadow scene of tests/support/scenes.py and the four sample scenes), renders
with MONTE_CARLO and with RATIO at a few sample counts and seeds, one thread each; for each, the
true relMSE against a converged DRT Monte Carlo reference (less the reference's own estimated
variance) and the CPU time of the render (kernels compiled beforehand). Efficiency is
1 / (relMSE x CPU time), the relMSE pooled over the seeds (mean) and the time summed; the
table gives RATIO's efficiency over MONTE_CARLO's, its relMSE and time ratios, and RATIO's
bias: the relative difference of its image mean from the reference's.

References are cached in bench/results/ (ratio_reference_<scene>_<w>x<h>.npz). Writes
bench/results/ratio_estimator.json; ``--publish`` also writes the table into docs/ratio-estimator.md's block
``ratio`` (bench/blocks.py) and the measurements to bench/ratio_estimator.json (committed).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import numpy as np  # noqa: E402

from drt_engine.core.render.adaptive import RELMSE_EPSILON, true_error  # noqa: E402
from drt_engine.core.film.ratio_sums import RATIO  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from drt_engine.core.settings import RenderSettings  # noqa: E402
from blocks import write_block  # noqa: E402
from references import cached_reference  # noqa: E402

OUT = ROOT / "bench" / "results"
ESTIMATORS = ("MONTE_CARLO", "RATIO")


def reference(name, data, base, samples):
    """The scene's converged Monte Carlo image and its estimated variance, cached per scene and size."""
    w, h = data.camera.window_size
    settings = RenderSettings(samples=samples, seed=1 << 20, shadow_estimator="MONTE_CARLO",
                              **{**base, "passes": ("Combined", "Noise"), "threads": 0})
    return cached_reference(OUT / f"ratio_reference_{name}_{w}x{h}_{samples}.npz", Renderer(data, settings).render)


REGIONS = ("no closed-form light", "light wholly seen", "light hidden", "penumbra")


def regions(data, run) -> np.ndarray:
    """Per pixel, which of REGIONS it is in, from the ratio estimator's sums of a 64-sample render:
    no sample saw a light the ratio takes (D = 0), every sample saw all of it (N = D), none (N = 0)."""
    renderer = Renderer(data, RenderSettings(samples=64, seed=99, shadow_estimator="RATIO", **run))
    renderer.render()
    w, h = data.camera.window_size
    if RATIO not in renderer.film.sums:
        return np.zeros((h, w), int)
    ndu = renderer.film.sums[RATIO].reshape(h, w, -1)
    n, d = ndu[..., 0:3].sum(axis=2), ndu[..., 3:6].sum(axis=2)
    return np.where(d == 0, 0, np.where(np.isclose(n, d, rtol=1e-9), 1, np.where(n == 0, 2, 3)))


def region_shares(image, truth, region) -> dict:
    """Each region's share of the image's true relMSE (terms as ``true_error``'s)."""
    ref, var = truth
    terms = (((image - ref) ** 2 - var) / (ref ** 2 + RELMSE_EPSILON)).sum(axis=2)
    total = terms.sum()
    return {name: float(terms[region == r].sum() / total) for r, name in enumerate(REGIONS)}


def measure(name, data, base, spps, seeds, ref_samples) -> dict:
    """Per estimator and sample count: pooled true relMSE, summed CPU seconds, image-mean bias, and
    where in the image the error is (``region_shares``, of the first seed)."""
    truth = reference(name, data, base, ref_samples)
    run = {**base, "passes": ("Combined",), "threads": 1}
    for estimator in ESTIMATORS:  # compile and warm the kernels of both before timing
        Renderer(data, RenderSettings(samples=2, shadow_estimator=estimator, **run)).render()
    region = regions(data, run)
    row = {"scene": name, "size": list(data.camera.window_size), "reference_samples": ref_samples, "runs": {},
           "pixels": {name: int((region == r).sum()) for r, name in enumerate(REGIONS)}}
    for spp in spps:
        for estimator in ESTIMATORS:
            relmse, cpu, means = [], 0.0, []
            for seed in seeds:
                start = time.process_time()
                res = Renderer(data, RenderSettings(samples=spp, seed=seed, shadow_estimator=estimator,
                                                    **run)).render()
                cpu += time.process_time() - start
                image = res.passes["Combined"][..., :3].astype(float)
                relmse.append(true_error(image, *truth)[1])
                means.append(image.mean())
                if len(means) == 1:
                    shares = region_shares(image, truth, region)
            entry = {"relmse": float(np.mean(relmse)), "cpu": cpu, "error_shares": shares,
                     "bias": float(np.mean(means) / truth[0].mean() - 1.0),
                     "plan": res.stats["plan_summary"]}
            entry["efficiency"] = 1.0 / (entry["relmse"] * cpu)
            row["runs"][f"{estimator}@{spp}"] = entry
            print(name, estimator, spp, entry, flush=True)
    return row


def sample_scenes(width, names):
    import drt_engine
    from scenes import load, settings

    drt_engine.register()
    for name in names:
        scene, data = load(name, width)
        s = settings(scene)
        yield name, data, dict(max_depth=s.max_depth, filter_type=s.filter_type, filter_size=s.filter_size)


def table(rows, spps) -> str:
    head = ("| scene | spp | relMSE MC | relMSE ratio | CPU time ratio/MC | efficiency ratio/MC | ratio bias "
            "(image mean) | MC error share: wholly lit / penumbra / other | ratio's |")
    lines = [head, "|---|---|---|---|---|---|---|---|---|"]

    def shares(entry):
        s = entry["error_shares"]
        lit, pen = s["light wholly seen"], s["penumbra"]
        return f"{100 * lit:.0f}% / {100 * pen:.0f}% / {100 * (1 - lit - pen):.0f}%"

    for row in rows:
        for spp in spps:
            mc, ra = row["runs"][f"MONTE_CARLO@{spp}"], row["runs"][f"RATIO@{spp}"]
            lines.append(f"| {row['scene']} | {spp} | {mc['relmse']:.2e} | {ra['relmse']:.2e} | "
                         f"{ra['cpu'] / mc['cpu']:.2f} | **{ra['efficiency'] / mc['efficiency']:.2f}x** | "
                         f"{100 * ra['bias']:+.3f}% | {shares(mc)} | {shares(ra)} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=96, help="sample scenes' width in pixels")
    parser.add_argument("--soft-width", type=int, default=128, help="soft-shadow scene's width in pixels")
    parser.add_argument("--spp", type=int, nargs="+", default=[4, 16, 64])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--reference-samples", type=int, default=1024)
    parser.add_argument("--scenes", nargs="*", default=["cornell_box", "glossy_spheres", "dof_row", "motion_blur"])
    parser.add_argument("--publish", action="store_true", help="write docs/ratio-estimator.md's block and bench/ratio_estimator.json")
    args = parser.parse_args(argv)
    from tests.support.scenes import soft_shadow_scene

    seeds = range(args.seeds)
    data, base = soft_shadow_scene(args.soft_width)
    base = {k: v for k, v in base.items() if k != "threads"}
    rows = [measure("soft_shadow", data, base, args.spp, seeds, args.reference_samples)]
    rows += [measure(name, data, base, args.spp, seeds, args.reference_samples)
             for name, data, base in sample_scenes(args.width, args.scenes)]
    result = {"setup": {"width": args.width, "soft_width": args.soft_width, "spp": args.spp, "seeds": args.seeds,
                        "reference_samples": args.reference_samples, "threads": 1}, "rows": rows}
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "ratio_estimator.json").write_text(json.dumps(result, indent=1))
    text = table(rows, args.spp)
    print(text)
    if args.publish:
        (ROOT / "bench" / "ratio_estimator.json").write_text(json.dumps(result, indent=1))
        setup = (f"`make bench-ratio` (bench/ratio_estimator.py): the soft-shadow scene at {args.soft_width} px "
                 f"wide, the sample scenes at {args.width} px, one thread, {args.seeds} seeds pooled, against "
                 f"DRT Monte Carlo references of {args.reference_samples} samples; efficiency = "
                 "1 / (relMSE x CPU time).")
        write_block("ratio", setup + "\n\n" + text)


if __name__ == "__main__":
    main()
