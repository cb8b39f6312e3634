"""make bench-instances: a floor strewn with collection instances of one pebble, DRT against Cycles.

Each render runs in a fresh process (``--child ENGINE COUNT``) that builds the scene with bpy (a
60 m plane, a 1,280-triangle ico-sphere pebble instanced COUNT times on a jittered grid, a sun and
an area light, 160x120, 16 samples, 2 threads, Cycles without denoising or adaptive sampling) and
renders it with ``bpy.ops.render.render`` as a user's F12 would: whole render time (export and BVH
build included) and the growth of the peak resident memory (VmHWM, tests/support/memory.py) over the process's before
the render. Engines alternate, best of ``--repeat`` each; the load average is printed beside.
Target (issue 22): DRT's time at most 1.5x Cycles', memory growing with the instances' count, not
their triangles. Writes the bench:instances block of docs/performance.md.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import random
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 1.5
COUNTS = (1000, 10000)


def build(engine: str, count: int) -> None:
    """The pebble-strewn floor in an empty bpy scene, set up for ``engine``."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=60)
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.2)
    pebble = bpy.context.object
    pebble.scale = (1.0, 0.7, 0.5)
    pebbles = bpy.data.collections.new("pebbles")
    pebbles.objects.link(pebble)
    scene.collection.objects.unlink(pebble)
    rng, side = random.Random(1), int(math.ceil(math.sqrt(count)))
    for i in range(count):
        empty = bpy.data.objects.new(f"pebble {i}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", pebbles
        empty.location = ((i % side) / side * 40 - 20 + rng.uniform(-0.1, 0.1), (i // side) / side * 40 - 20, 0.05)
        empty.rotation_euler = (0.0, 0.0, rng.uniform(0.0, 2 * math.pi))
        scene.collection.objects.link(empty)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location, camera.rotation_euler = (0, -25, 12), (math.radians(65), 0, 0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.rotation_euler, sun.data.energy = (0.6, 0.2, 0.0), 3.0
    area = bpy.data.objects.new("area", bpy.data.lights.new("area", "AREA"))
    area.location, area.data.energy, area.data.size = (0, 0, 8), 2000.0, 4.0
    for light in (sun, area):
        scene.collection.objects.link(light)
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 160, 120, 100
    r.engine, r.threads_mode, r.threads = engine, "FIXED", 2
    scene.cycles.samples, scene.cycles.use_denoising, scene.cycles.use_adaptive_sampling = 16, False, False
    scene.cycles.device = "CPU"
    if engine == "DRT":
        scene.drt.samples = 16


def child(engine: str, count: int) -> None:
    sys.path.insert(0, str(ROOT))
    import bpy
    import drt_engine
    from tests.support.memory import peak_resident_mb
    drt_engine.register()
    build(engine, count)
    bpy.context.view_layer.update()
    before = peak_resident_mb()
    start = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - start
    peak = peak_resident_mb()
    print("RESULT " + json.dumps({"seconds": seconds, "grew_mb": peak - before}), flush=True)


def run(engine: str, count: int) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", engine, str(count)], capture_output=True, text=True)
    lines = [line for line in out.stdout.splitlines() if line.startswith("RESULT ")]
    if out.returncode or not lines:
        raise SystemExit(f"{engine} with {count} instances failed:\n{out.stderr[-2000:]}")
    return json.loads(lines[-1][7:])


def block(rows: dict, loads: list, repeat: int) -> str:
    lines = [f"Instances (bench/instances.py: a floor with N instances of a 1,280-triangle pebble, 160x120, 16 spp, "
             f"2 threads, whole F12 render in a fresh process, best of {repeat}; load average "
             f"{min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} cores):", "",
             "| instances | triangles | DRT s | Cycles s | DRT / Cycles | DRT memory growth MB | Cycles MB |",
             "|---:|---:|---:|---:|---:|---:|---:|"]
    for count, (drt, cycles) in rows.items():
        ratio = drt["seconds"] / cycles["seconds"]
        mark = "" if ratio <= TARGET else f" (target {TARGET})"
        lines.append(f"| {count:,} | {count * 1280 + 2:,} | {drt['seconds']:.2f} | {cycles['seconds']:.2f} | "
                     f"{ratio:.2f}{mark} | {drt['grew_mb']:.0f} | {cycles['grew_mb']:.0f} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", nargs=2, metavar=("ENGINE", "COUNT"))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--counts", type=int, nargs="*", default=COUNTS)
    parser.add_argument("--no-publish", action="store_true")
    args = parser.parse_args(argv)
    if args.child:
        return child(args.child[0], int(args.child[1]))
    run("DRT", 10)  # compile or load the kernels once, outside the timed runs
    rows, loads = {}, []
    for count in args.counts:
        best = {}
        for _ in range(args.repeat):
            for engine in ("DRT", "CYCLES"):
                loads.append(os.getloadavg()[0])
                got = run(engine, count)
                print(f"{engine:6s} {count:6d} instances: {got['seconds']:.2f} s, +{got['grew_mb']:.0f} MB", flush=True)
                if engine not in best or got["seconds"] < best[engine]["seconds"]:
                    best[engine] = got
        rows[count] = (best["DRT"], best["CYCLES"])
    text = block(rows, loads, args.repeat)
    print(text)
    if not args.no_publish:
        sys.path.insert(0, str(ROOT / "bench"))
        from blocks import write_block
        write_block("instances", text)


if __name__ == "__main__":
    main()
