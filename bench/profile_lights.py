"""Where a render's time goes, for the light stages: cProfile of Renderer.render on each sample
scene (160 px wide, 16 spp, one thread), printing the whole render time and the cumulative time
spent in the light modules (their outermost calls, so nested calls count once). Times are CPU
seconds of this process (the machine is shared: wall time measures the neighbours too).

Usage: python bench/profile_lights.py [scene ...]
"""
from __future__ import annotations

import cProfile
import pstats
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import drt_engine  # noqa: E402
from drt_engine.core.render.render import Renderer  # noqa: E402
from scenes import SCENES, load, settings  # noqa: E402

MODULES = ("core/lights/collection.py", "core/lights/environment.py")
TOP = 6


def module_time(stats: pstats.Stats, module: str) -> float:
    """Cumulative time of the module's functions called from outside it (no double counting)."""
    total = 0.0
    for (file, _line, _name), (_cc, _nc, _tt, ct, callers) in stats.stats.items():
        if not file.endswith(module):
            continue
        outside = sum(c[3] for (cf, _l, _n), c in callers.items() if not cf.endswith(module))
        total += outside if callers else ct
    return total


def main(names):
    drt_engine.register()
    for name in names or SCENES:
        scene, data = load(name, 160)
        renderer = Renderer(data, settings(scene, samples=16, threads=1))
        renderer.render()  # warm: kernels compiled or loaded, tables built
        renderer = Renderer(data, settings(scene, samples=16, threads=1))
        start = time.process_time()
        renderer.render()
        cpu = time.process_time() - start
        profile = cProfile.Profile(time.process_time)
        renderer = Renderer(data, settings(scene, samples=16, threads=1))
        profile.runcall(renderer.render)
        stats = pstats.Stats(profile)
        parts = ", ".join(f"{m.split('/')[-1]} {module_time(stats, m):.3f} s" for m in MODULES)
        print(f"{name:15s} render {cpu:.2f} s (profiled {stats.total_tt:.2f} s, "
              f"{stats.total_calls} calls); {parts}", flush=True)
        ours = [(ct, f"{file.split('/')[-1]}:{fn}") for (file, _l, fn), (_c, _n, _t, ct, _) in stats.stats.items()
                if file.endswith(MODULES)]
        for ct, where in sorted(ours, reverse=True)[:TOP]:
            print(f"    {ct:7.3f} s  {where}")


if __name__ == "__main__":
    main(sys.argv[1:])
