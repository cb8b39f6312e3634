"""Cold and warm start of DRT: the first render after an install (kernels compiled, or loaded from
those the Linux zip ships) and the first render of a later session (kernels loaded from the cache),
each in a fresh process.

``python bench/startup.py [--scene cornell_box] [--width 64] [--samples 1]``: points
NUMBA_CACHE_DIR at an empty temporary folder, renders once (cold), then again in a new
process with the same folder (warm); then, where ``make extension`` built the Linux zip with
kernels for these sources and this Python, renders with a cache folder holding only those, as
the installed extension's first render finds it (shipped). Each process reports the import of
the core, the first render (prepare + trace) and a second render of the same scene in the same
process; the first render minus the second is the start-up cost (compiling, or loading kernels).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ZIPS = ROOT / "dist"

SCRIPT = """
import sys, time
sys.path[:0] = [{root!r}, {root!r} + '/bench']
t0 = time.perf_counter()
from drt_engine.core.base import jit
from drt_engine.core.render.render import Renderer
imported = time.perf_counter() - t0
first_run = jit.first_run()
import drt_engine
from scenes import load, settings
drt_engine.register()
scene, data = load({scene!r}, {width})
s = settings(scene, samples={samples}, threads=1)
times = []
for _ in range(2):
    t = time.perf_counter()
    Renderer(data, s).render()
    times.append(time.perf_counter() - t)
print("STARTUP", imported, times[0], times[1], first_run, jit.first_run())
"""


def run(cache: str, scene: str, width: int, samples: int) -> dict:
    """One fresh process: import seconds, first and second render seconds, first_run before/after."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    code = SCRIPT.format(root=str(ROOT), scene=scene, width=width, samples=samples)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    _, imported, first, second, before, after = next(x for x in out.splitlines() if x.startswith("STARTUP")).split()
    return {"import": float(imported), "first": float(first), "second": float(second),
            "first_run": before == "True", "first_run_after": after == "True"}


def shipped_kernels(cache: Path) -> bool:
    """Put the Linux zip's kernels for these sources and this Python into ``cache`` as the installed
    extension copies them; False where there are none."""
    sys.path.insert(0, str(ROOT))
    from drt_engine.core.base import jit

    folder = f"kernels/{jit.cache_dir().name}/"
    for path in ZIPS.glob("drt_engine-*-linux_x64.zip"):
        with zipfile.ZipFile(path) as z:
            members = [m for m in z.namelist() if m.startswith(folder)]
            if members:
                z.extractall(cache.parent, members)
                (cache.parent / "kernels").rename(cache)
                return True
    return False


def measure(scene="cornell_box", width=64, samples=1) -> dict:
    """{"cold": run, "warm": run, "shipped": run or None} with an empty kernel cache, then the cache
    the cold run filled, then one holding only the shipped kernels."""
    with tempfile.TemporaryDirectory(prefix="drt-kernels-") as cache:
        cold = run(cache, scene, width, samples)
        warm = run(cache, scene, width, samples)
    with tempfile.TemporaryDirectory(prefix="drt-shipped-") as top:
        cache = Path(top) / "cache"
        shipped = run(str(cache), scene, width, samples) if shipped_kernels(cache) else None
    return {"cold": cold, "warm": warm, "shipped": shipped}


def describe(result: dict) -> str:
    lines = []
    for name in ("cold", "warm", "shipped"):
        r = result.get(name)
        if r is None:
            lines.append(f"{name}: no kernels for these sources in dist/'s Linux zip (make extension)")
            continue
        lines.append(f"{name}: import {r['import']:.2f} s, first render {r['first']:.2f} s, second {r['second']:.2f} s, "
                     f"start-up {r['first'] - r['second']:.2f} s (first run: {r['first_run']})")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell_box")
    parser.add_argument("--width", type=int, default=64)
    parser.add_argument("--samples", type=int, default=1)
    args = parser.parse_args(argv)
    print(describe(measure(args.scene, args.width, args.samples)))


if __name__ == "__main__":
    main()
