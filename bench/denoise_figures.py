"""docs/denoising.md's measured blocks.

``bench:denoise`` (default): the compositor's Denoise node, from what tests/blender/test_denoise.py
measured (out/ui/denoise.json):

    .venv/bin/python -m pytest tests/blender/test_denoise.py && .venv/bin/python bench/denoise_figures.py

``bench:denoise-calibration`` (``--calibration``, ``make bench-denoise``): DRT's built-in denoising
(``use_denoising``, core.render.denoise) on sample scenes at a few sample counts and seeds. For each
render: the true relMSE of the noisy and of the denoised image against a high-sample reference (less
the reference's own estimated variance), and DRT's estimates of both; beside them, from the same
film, the estimate as it was before each half was denoised with its own half's features (the three
denoisings guided by the features of all the samples) and the time that took.
References are cached in bench/results/ (denoise_reference_<scene>_<w>x<h>_<spp>.npz); the
measurements go to bench/denoise_calibration.json (committed) and the block.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
MEASURED = ROOT / "out" / "ui" / "denoise.json"
MAPS = ROOT / "bench" / "plots" / "denoise_cornell_box.png"
CALIBRATION = ROOT / "bench" / "denoise_calibration.json"
NOISE_SCALING = ROOT / "bench" / "denoise_noise_scaling.json"
RESULTS = ROOT / "bench" / "results"

SCENES = ("cornell_box", "dof_row", "glossy_spheres", "motion_blur")
WIDTH = 256
SAMPLES = (16, 32, 64)
SEEDS = (1, 2)
REFERENCE_SAMPLES = 1024
TARGET = 1e-3
"""The target error of the time-to-error runs (seed 1, at most TARGET_CAP samples, no adaptive sampling)."""
TARGET_CAP = 1024


def block(m: dict) -> str:
    return "\n".join([
        "| image | relMSE vs reference |", "|---|---|",
        f"| {m['samples']} samples, noisy | {m['relmse_noisy']:.2e} |",
        f"| {m['samples']} samples, Denoise node (Image + Denoising Albedo + Denoising Normal) "
        f"| {m['relmse_denoised']:.2e} |",
        "",
        f"The denoised image is {m['ratio']:.1f} times closer ({m['scene']}, {m['resolution']}x{m['resolution']} px, "
        f"reference {m['reference_samples']} samples, Blender {m['blender']}; images in `out/ui/denoise_*.png`).",
    ])


def reference(name, data, settings_for):
    """The scene's high-sample image and its estimated variance, cached per scene, size and samples."""
    from drt_engine.core.render.render import Renderer
    from references import cached_reference

    w, h = data.camera.window_size
    settings = settings_for(samples=REFERENCE_SAMPLES, seed=1 << 20, passes=("Combined", "Noise"))
    return cached_reference(RESULTS / f"denoise_reference_{name}_{w}x{h}_{REFERENCE_SAMPLES}.npz",
                            Renderer(data, settings).render)


def measure() -> dict:
    import bpy

    import drt_engine
    import scenes as bench_scenes
    from drt_engine.blender.oidn import oidn_library
    from drt_engine.core.film import denoiser
    from drt_engine.core.render.adaptive import true_error
    from drt_engine.core.render.render import Renderer
    from drt_engine.core.settings import NOISY_IMAGE

    drt_engine.register()
    library = oidn_library()
    if library is None:
        raise SystemExit("this Blender has no OpenImageDenoise library")
    oidn = denoiser.load(library)
    rows, targets = [], []
    for name in SCENES:
        scene, data = bench_scenes.load(name, WIDTH)

        def settings_for(**kw):
            return bench_scenes.settings(scene, threads=0, use_adaptive_sampling=False, **kw)

        ref, ref_var = reference(name, data, settings_for)
        for spp in SAMPLES:
            for seed in SEEDS:
                start = time.perf_counter()
                renderer = Renderer(data, settings_for(samples=spp, seed=seed, use_denoising=True), denoiser=oidn)
                result = renderer.render()
                seconds = time.perf_counter() - start
                noisy, denoised = result.passes[NOISY_IMAGE][..., :3], result.passes["Combined"][..., :3]
                shared, shared_seconds = shared_features(renderer.film, oidn)
                row = {"scene": name, "samples": spp, "seed": seed, "load": os.getloadavg()[0],
                       "true_noisy": true_error(noisy, ref, ref_var)[1], "est_noisy": result.stats["relmse"],
                       "true_denoised": true_error(denoised, ref, ref_var)[1],
                       "est_denoised": result.stats["relmse_denoised"],
                       "est_denoised_noise": result.stats["relmse_denoised_noise"],
                       "est_shared": shared["relmse"], "est_shared_noise": shared["relmse_noise"],
                       "render_seconds": seconds, "denoise_seconds": result.stats["denoising"]["seconds"],
                       "shared_seconds": shared_seconds}
                print(row, flush=True)
                rows.append(row)
        for use_denoising in (False, True):
            start = time.perf_counter()
            result = Renderer(data, settings_for(samples=TARGET_CAP, seed=1, target_error=TARGET,
                                                 use_denoising=use_denoising),
                              denoiser=oidn if use_denoising else None).render()
            seconds = time.perf_counter() - start
            key = "relmse_denoised" if use_denoising else "relmse"
            row = {"scene": name, "use_denoising": use_denoising, "seconds": seconds,
                   "samples": result.stats["samples"], "stopped_by": result.stats["stopped_by"],
                   "estimate": result.stats[key],
                   "true": true_error(result.passes["Combined"][..., :3], ref, ref_var)[1],
                   "denoise_seconds": result.stats["denoising"]["seconds"] if use_denoising else 0.0,
                   "denoised_steps": sum("relmse_denoised" in entry for entry in result.log),
                   "load": os.getloadavg()[0]}
            print(row, flush=True)
            targets.append(row)
    return {"width": WIDTH, "reference_samples": REFERENCE_SAMPLES, "seeds": list(SEEDS),
            "blender": bpy.app.version_string, "machine": platform.machine(), "rows": rows,
            "prefilter": "ACCURATE", "quality": "HIGH", "target": TARGET, "target_rows": targets}


def maps(name="cornell_box", samples=16, seed=1, path=MAPS) -> None:
    """PNG of four panels, top row first: the noisy render, the denoised one, the estimated
    relative squared error of the denoised image per pixel, and its true one against the
    reference. The error maps are pooled over 9x9 pixels (the estimate per pixel is a difference
    of noisy squares) and drawn on one log scale, 1e-6 black to 1e-2 white."""
    import bpy
    import numpy as np
    import OpenImageIO as oiio

    import drt_engine
    import scenes as bench_scenes
    from drt_engine.blender.oidn import oidn_library
    from drt_engine.core.film import denoiser
    from drt_engine.core.film.denoising import ALBEDO, NORMAL, PASSES
    from drt_engine.core.render.adaptive import RELMSE_EPSILON, box_mean
    from drt_engine.core.render.denoise import error_terms, noisy_images
    from drt_engine.core.render.render import Renderer
    from drt_engine.core.settings import NOISY_IMAGE

    if not hasattr(bpy.types.Scene, "drt"):  # --calibration measured in this process: registered already
        drt_engine.register()
    oidn = denoiser.load(oidn_library())
    scene, data = bench_scenes.load(name, WIDTH)

    def settings_for(**kw):
        return bench_scenes.settings(scene, threads=0, use_adaptive_sampling=False, **kw)

    ref, ref_var = reference(name, data, settings_for)
    renderer = Renderer(data, settings_for(samples=samples, seed=seed, use_denoising=True), denoiser=oidn)
    result = renderer.render()
    film, (h, w) = renderer.film, ref.shape[:2]
    full, half_a, half_b = noisy_images(film)
    denoised = result.passes["Combined"][..., :3]
    da, db = (oidn.denoise(x.reshape(h, w, 3), guide[ALBEDO], guide[NORMAL])
              for x, guide in zip((half_a, half_b), film.half_images(PASSES)))
    _, error, weight = error_terms(denoised, da, db, half_a, half_b, film.count, film.count_a)
    estimated = (error * weight).mean(axis=1)
    true = (((denoised - ref) ** 2 - ref_var) / (ref ** 2 + RELMSE_EPSILON)).reshape(-1, 3).mean(axis=1)
    scale = 1.0 / max(float(np.percentile(ref, 99)), 1e-6)

    def tone(image):
        linear = np.clip(image * scale, 0.0, 1.0)
        return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)

    def heat(values):
        pooled = box_mean(values, h, w, 4).reshape(h, w)
        level = np.clip((np.log10(np.maximum(pooled, 1e-12)) + 6.0) / 4.0, 0.0, 1.0)
        return np.repeat(level[..., None], 3, axis=2)

    gap = np.full((h, 2, 3), 0.5)
    panels = [tone(result.passes[NOISY_IMAGE][..., :3]), tone(denoised), heat(estimated), heat(true)]
    rows = np.concatenate([p for panel in panels for p in (panel, gap)][:-1], axis=1)[::-1]  # top row first
    pixels = np.ascontiguousarray((rows * 255 + 0.5).astype(np.uint8))
    path.parent.mkdir(parents=True, exist_ok=True)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, "uint8"))
    out.write_image(pixels)
    out.close()
    print(f"wrote {path.relative_to(ROOT)}: estimated relMSE {estimated.mean():.3g}, true {true.mean():.3g}")


def shared_features(film, oidn) -> tuple[dict, float]:
    """The denoising and estimate as DRT made them before each half had its own features: the
    albedo and normal of all the samples prefiltered once (Accurate) and guiding the whole image and
    both halves, five OIDN runs: (the estimate as ``denoised_error`` gives it, wall-clock seconds).
    The whole image's denoising is the same either way; only the halves' differ."""
    from drt_engine.core.film.denoising import ALBEDO, NORMAL, PASSES
    from drt_engine.core.render.denoise import denoised_error, noisy_images

    start = time.perf_counter()
    shape = (film.height, film.width, 3)
    with oidn.filters() as filters:
        features = film.images(PASSES)
        albedo, normal = filters.clean_features(features[ALBEDO], features[NORMAL])
        noisy = [image.reshape(shape) for image in noisy_images(film)]
        full, half_a, half_b = (filters.denoise(image, albedo, normal, prefilter="NONE") for image in noisy)
    estimate = denoised_error(full, half_a, half_b, noisy[1], noisy[2], film.count, film.count_a)
    return estimate, time.perf_counter() - start


def feature_noise_block(m: dict) -> str:
    """Per scene and sample count, the estimate / true with the halves' own features (DRT) and with
    the features of all the samples shared by the three denoisings (before), from the same renders."""
    lines = ["| scene | spp | est. / true, each half its own features (DRT) | features shared (before) "
             "| its noise part, own / shared | denoising time, own / shared |", "|---|---|---|---|---|---|"]
    groups: dict = {}
    for row in m["rows"]:
        groups.setdefault((row["scene"], row["samples"]), []).append(row)
    for (scene, spp), rows in groups.items():
        own = ", ".join(f"{r['est_denoised'] / r['true_denoised']:.2f}" for r in rows)
        shared = ", ".join(f"{r['est_shared'] / r['true_denoised']:.2f}" for r in rows)
        noise = ", ".join(f"{r['est_denoised_noise'] / r['true_denoised']:.2f} / "
                          f"{r['est_shared_noise'] / r['true_denoised']:.2f}" for r in rows)
        own_s = sum(r["denoise_seconds"] for r in rows) / len(rows)
        shared_s = sum(r["shared_seconds"] for r in rows) / len(rows)
        lines.append(f"| {scene} | {spp} | {own} | {shared} | {noise} | {own_s:.2f} s / {shared_s:.2f} s |")
    lines += ["", f"The same renders as above (seeds {', '.join(map(str, m['seeds']))}), each denoised both ways; "
              f"denoising time is wall clock of nine OIDN runs (own) and five (shared), {_loads(m['rows'])}."]
    return "\n".join(lines)


def noise_scaling(samples=16, seeds=range(1, 7), width=64) -> dict:
    """Whether the noise OIDN leaves falls as 1 / samples, as the halves' difference assumes
    (core.render.denoise): per test scene, the variance of the denoised image across seeds at
    ``samples`` and at half as many (the size of a half), relMSE-weighted against a 512-sample
    render, and the estimate's noise part beside the first."""
    import numpy as np

    from drt_engine.core.film import denoiser
    from drt_engine.core.render.adaptive import RELMSE_EPSILON
    from drt_engine.core.render.render import Renderer
    from drt_engine.core.settings import RenderSettings
    from tests.support.oidn import require_oidn
    from tests.support.scenes import defocused_checker_scene, soft_shadow_scene

    oidn = denoiser.load(require_oidn())
    rows = []
    for name, make in (("defocused_checker", defocused_checker_scene), ("soft_shadow", soft_shadow_scene)):
        scene, base = make(width)
        ref = Renderer(scene, RenderSettings(**{**base, "samples": 512, "seed": 99})).render().passes["Combined"]
        weight = 1.0 / (ref[..., :3].astype(float) ** 2 + RELMSE_EPSILON)
        row = {"scene": name, "samples": samples, "seeds": len(seeds), "load": os.getloadavg()[0]}
        for n, key in ((samples, "full"), (samples // 2, "half")):
            results = [Renderer(scene, RenderSettings(**{**base, "samples": n, "seed": seed, "use_denoising": True}),
                                denoiser=oidn).render() for seed in seeds]
            images = np.array([r.passes["Combined"][..., :3].astype(float) for r in results])
            row[f"variance_{key}"] = float((images.var(axis=0, ddof=1) * weight).mean())
            if key == "full":
                row["estimated_noise"] = float(np.mean([r.stats["relmse_denoised_noise"] for r in results]))
        print(row, flush=True)
        rows.append(row)
    return {"rows": rows, "width": width}


def noise_scaling_block(m: dict) -> str:
    lines = ["| scene | variance at half the samples / at all (1 / samples: 2) | estimated noise part / variance |",
             "|---|---|---|"]
    lines += [f"| {r['scene']} | {r['variance_half'] / r['variance_full']:.2f} "
              f"| {r['estimated_noise'] / r['variance_full']:.2f} |" for r in m["rows"]]
    r = m["rows"][0]
    lines += ["", f"Denoised renders of tests/support/scenes.py at {m['width']} px wide, {r['samples']} and "
              f"{r['samples'] // 2} samples, {r['seeds']} seeds each; variance across the seeds, relMSE-weighted "
              f"({_loads(m['rows'])}; `bench/denoise_figures.py --noise-scaling`, `bench/denoise_noise_scaling.json`)."]
    return "\n".join(lines)


def calibration_block(m: dict) -> str:
    """One line per scene and sample count, the figures averaged over the seeds (est. / true: its range)."""
    lines = ["| scene | spp | noisy relMSE (est. / true) | denoised relMSE | denoised / noisy | "
             "denoised est. / true, per seed | its noise part / true | denoising time |",
             "|---|---|---|---|---|---|---|---|"]
    groups: dict = {}
    for row in m["rows"]:
        groups.setdefault((row["scene"], row["samples"]), []).append(row)
    ratios, noise_ratios = [], []
    for (scene, spp), rows in groups.items():
        mean = {k: sum(r[k] for r in rows) / len(rows)
                for k in ("true_noisy", "est_noisy", "true_denoised", "denoise_seconds")}
        per_seed = [r["est_denoised"] / r["true_denoised"] for r in rows]
        noise_part = [r["est_denoised_noise"] / r["true_denoised"] for r in rows]
        ratios += per_seed
        noise_ratios += noise_part
        lines.append(f"| {scene} | {spp} | {mean['true_noisy']:.2e} ({mean['est_noisy'] / mean['true_noisy']:.2f}) "
                     f"| {mean['true_denoised']:.2e} | {mean['true_denoised'] / mean['true_noisy']:.2f} "
                     f"| {', '.join(f'{r:.2f}' for r in per_seed)} | {', '.join(f'{r:.2f}' for r in noise_part)} "
                     f"| {mean['denoise_seconds']:.2f} s |")
    lines += ["", f"{len(m['rows'])} renders at {m['width']} px wide, seeds {', '.join(map(str, m['seeds']))}, "
              f"against {m['reference_samples']}-sample references; prefilter {m['prefilter'].title()}, quality "
              f"{m['quality'].title()}, Blender {m['blender']}'s OpenImageDenoise on the CPU. The denoised estimate "
              f"read {min(ratios):.2f} to {max(ratios):.2f} of the true error (1 is exact); its noise part alone, "
              f"the halves' denoised difference, {min(noise_ratios):.2f} to {max(noise_ratios):.2f}. Denoising time "
              f"is the finished image's nine OIDN runs (the whole image and each half, each after its own albedo "
              f"and normal are prefiltered), wall clock on a machine shared with other work ({_loads(m['rows'])}). "
              f"Measurements: `bench/denoise_calibration.json`."]
    if m.get("target_rows"):
        lines += ["", f"Time to a relMSE of {m['target']:g} with Target Error {m['target']:g} (seed 1, no adaptive "
                  f"sampling; with Denoise on the target applies to the denoised image, and a step is denoised, "
                  f"nine OIDN runs, only when its noisy estimate times the last denoised / noisy ratio is under "
                  f"the target: `denoise.Schedule`):", "",
                  "| scene | samples off / on | time off | time on (of it denoising, steps denoised) | off / on "
                  "| estimated relMSE on | true relMSE on | load |", "|---|---|---|---|---|---|---|---|"]
        rows = {(r["scene"], r["use_denoising"]): r for r in m["target_rows"]}
        faster = []
        for scene in dict.fromkeys(r["scene"] for r in m["target_rows"]):
            off, on = rows[scene, False], rows[scene, True]
            faster.append(off["seconds"] / on["seconds"])
            lines.append(f"| {scene} | {off['samples']} / {on['samples']} | {off['seconds']:.1f} s "
                         f"| {on['seconds']:.1f} s ({on['denoise_seconds']:.1f} s, {on['denoised_steps']}) "
                         f"| {faster[-1]:.1f}x | {on['estimate']:.2e} | {on['true']:.2e} "
                         f"| {off['load']:.1f}, {on['load']:.1f} |")
        bare = [rows[sc, False]["seconds"] / (rows[sc, True]["seconds"] - rows[sc, True]["denoise_seconds"])
                for sc in dict.fromkeys(r["scene"] for r in m["target_rows"])]
        lines += ["", f"Denoising reached the target {', '.join(f'{x:.1f}' for x in faster)} times as fast; without "
                  f"its OIDN runs the same renders would have been {', '.join(f'{x:.1f}' for x in bare)} times as "
                  f"fast: the denoisings themselves are what holds it back on this machine. Load: the 1-minute load "
                  f"average after each run, on 2 cores."]
    return "\n".join(lines)


def _loads(rows) -> str:
    """The 1-minute load averages the rows were measured under, on the machine's 2 cores."""
    loads = [r["load"] for r in rows if "load" in r]
    return f"load average {min(loads):.1f} to {max(loads):.1f} on 2 cores" if loads else "load not recorded"


def main() -> None:
    from blocks import write_block

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calibration", action="store_true",
                        help="measure DRT's built-in denoising and its error estimate (make bench-denoise)")
    parser.add_argument("--maps", action="store_true",
                        help="only draw bench/plots/denoise_cornell_box.png (noisy, denoised, estimated and true error)")
    parser.add_argument("--publish-only", action="store_true",
                        help="rewrite the calibration block from bench/denoise_calibration.json without rendering")
    parser.add_argument("--noise-scaling", action="store_true",
                        help="measure how the noise OIDN leaves falls with the samples")
    args = parser.parse_args()
    if args.noise_scaling:
        NOISE_SCALING.write_text(json.dumps(noise_scaling(), indent=1) + "\n")
        write_block("denoise-noise-scaling", noise_scaling_block(json.loads(NOISE_SCALING.read_text())))
        return
    if args.maps:
        maps()
        return
    if args.calibration or args.publish_only:
        if not args.publish_only:
            CALIBRATION.write_text(json.dumps(measure(), indent=1) + "\n")
            maps()
        measured = json.loads(CALIBRATION.read_text())
        write_block("denoise-calibration", calibration_block(measured))
        write_block("denoise-feature-noise", feature_noise_block(measured))
        return
    write_block("denoise", block(json.loads(MEASURED.read_text())))


if __name__ == "__main__":
    main()
