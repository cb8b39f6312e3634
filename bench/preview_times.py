"""Material preview times in the bpy wheel: Blender's own preview renders (icon and large
preview, ``bpy.ops.wm.previews_ensure``, the engine's ``is_preview`` path) of the Cornell
box's materials, kernels cached, and where each render's time goes: every material's previews
are rendered WARM_ROUNDS times (the first compiles or loads the kernels), then once more, measured.

    .venv/bin/python bench/preview_times.py [--label NAME] [--publish]

Appends a run to bench/preview_times.json under ``--label``; ``--publish`` writes docs/performance.md's
block ``bench:preview-times`` from every label in that file.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
RESULTS = ROOT / "bench" / "preview_times.json"
WARM_ROUNDS = 3


def measure() -> dict:
    import bpy

    import drt_engine
    from drt_engine.blender import engine as engine_module
    from drt_engine.core.render import prepared as prepared_module
    from drt_engine.core.render import render as render_module

    drt_engine.register()
    bpy.ops.wm.open_mainfile(filepath=str(ROOT / "sample_scenes" / "cornell_box.blend"), load_ui=False)
    bpy.context.scene.render.engine = "DRT"
    stages: dict = {}
    renders = []

    def timed(owner, name, stage):
        original = getattr(owner, name)

        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                stages[stage] = stages.get(stage, 0.0) + time.perf_counter() - start
        setattr(owner, name, wrapper)

    import drt_engine.blender.export as export_package
    timed(export_package, "export_scene", "export")
    timed(prepared_module.PreparedScene, "__init__", "prepare")
    timed(render_module.Renderer, "render", "trace")
    render = engine_module.DRTRenderEngine.render

    def logged(self, depsgraph):
        stages.clear()
        start = time.perf_counter()
        render(self, depsgraph)
        renders.append({"size": self.resolution_x, "seconds": time.perf_counter() - start,
                        **{k: round(v, 4) for k, v in stages.items()}})
    engine_module.DRTRenderEngine.render = logged

    materials = [m for m in bpy.data.materials if m.users and not m.name.startswith("Floor")]
    for _ in range(WARM_ROUNDS + 1):
        renders.clear()
        for material in materials:
            material.preview_ensure().reload()
        bpy.ops.wm.previews_ensure()
    sizes = sorted({r["size"] for r in renders})
    out = {"blender": bpy.app.version_string, "materials": [m.name for m in materials], "warm_rounds": WARM_ROUNDS}
    for name, size in zip(("icon", "large"), sizes):
        mine = [r for r in renders if r["size"] == size]
        out[name] = {"size": size, "renders": len(mine),
                     "median_seconds": round(statistics.median(r["seconds"] for r in mine), 3),
                     "max_seconds": round(max(r["seconds"] for r in mine), 3),
                     "median_stages": {k: round(statistics.median(r.get(k, 0.0) for r in mine), 3)
                                       for k in ("export", "prepare", "trace")}}
    return out


def block(runs: dict) -> str:
    lines = ["| code | icon (px) median / max s | export / prepare / trace s | large (px) median / max s "
             "| export / prepare / trace s |", "|---|---|---|---|---|"]
    for label, run in runs.items():
        cells = []
        for kind in ("icon", "large"):
            r = run[kind]
            st = r["median_stages"]
            cells += [f"{r['size']}: {r['median_seconds']:.2f} / {r['max_seconds']:.2f}",
                      f"{st['export']:.2f} / {st['prepare']:.2f} / {st['trace']:.2f}"]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    first = next(iter(runs.values()))
    lines.append("")
    lines.append(f"Blender {first['blender']} (bpy wheel), previews of the Cornell box's materials "
                 f"({', '.join(first['materials'])}), each rendered once after {first['warm_rounds']} warm-up rounds; "
                 "written by `bench/preview_times.py` on a 2-core machine shared with other jobs.")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--label", default="current")
    parser.add_argument("--publish", action="store_true")
    args = parser.parse_args()
    runs = json.loads(RESULTS.read_text()) if RESULTS.exists() else {}
    runs[args.label] = measure()
    RESULTS.write_text(json.dumps(runs, indent=2) + "\n")
    print(json.dumps(runs[args.label], indent=2))
    if args.publish:
        from bench.blocks import write_block
        write_block("preview-times", block(runs))


if __name__ == "__main__":
    main()
