"""Render farm bench (not a test): what a Dask task costs beyond its render, and what N machines gain.

In one run, on this machine:
(a) one process: ``python -m drt_engine render`` of a sample scene on every core (wall time of
    the whole process, and the engine's render time, from its report);
(b) the same render with ``--workers 2`` (a LocalCluster of 2 worker processes, 1 thread each):
    wall time, and from the merged report's ``stats.farm`` every task's seconds on its worker,
    rendering, and from submission to its part's arrival at the client, the cluster start and
    the shipping of the .blend;
(c) a part's pixel-proportional costs at 1920x1080 (write, read, add into the film, pickle
    size), in this process;
(d) from these, a model of the speed-up on N machines (one worker each), written into
    docs/render-farms.md between the farm markers, the raw figures into bench/FARM.json.

    .venv/bin/python bench/farm.py [--size 96 --samples 256]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from drt_engine.core.film import parts  # noqa: E402
from drt_engine.core.film.film import Film  # noqa: E402

from blocks import replace_between  # noqa: E402

SCENE = ROOT / "sample_scenes" / "cornell_box.blend"
PAGE = ROOT / "docs" / "render-farms.md"
MARK_BEGIN, MARK_END = "<!-- farm: begin -->", "<!-- farm: end -->"
NETWORK = 1e9 / 8  # bytes per second: the model assumes 1 Gbit/s between the machines
MODEL_MACHINES = (1, 2, 4, 8, 16, 64)
FRAME_4K = (3840, 2160, 1024)
ANIMATION = (1920, 1080, 128, 240)  # width, height, samples, frames


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cli(folder: Path, name: str, *args) -> tuple[float, float, dict]:
    """Run the CLI; (wall seconds, CPU seconds of it and every process it started, its .drt.json)."""
    out = folder / f"{name}.exr"
    began, cpu = time.perf_counter(), children_cpu()
    proc = subprocess.run([sys.executable, "-m", "drt_engine", "render", str(SCENE), "-o", str(out), *map(str, args)],
                          cwd=ROOT, capture_output=True, text=True, timeout=3600)
    wall, cpu = time.perf_counter() - began, children_cpu() - cpu
    if proc.returncode:
        raise SystemExit(f"{name} failed: {proc.stderr.strip()}")
    return wall, cpu, json.loads(out.with_name(f"{name}.drt.json").read_text())


def part_costs(width=1920, height=1080) -> dict:
    """CPU seconds per megapixel to write, read and add a Combined-only part, and its bytes per pixel."""
    n = width * height
    rng = np.random.default_rng(0)
    film = Film(width, height, ("Combined",))
    film.count[:] = 4
    film.count_a[:] = 2
    film.sums["Combined"][:] = rng.random((n, 4))
    film.sum_a[:] = rng.random((n, 3))
    settings_header = {"blend": "", "frame": 1, "view_layer": "ViewLayer", "fingerprint": "", "report": {}}
    from drt_engine.core.settings import RenderSettings

    part = parts.from_film(film, RenderSettings(samples=8, sample_end=4), settings_header)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "part.exr"
        began = time.process_time()
        parts.write(path, part)
        written = time.process_time()
        back = parts.read(path)
        read = time.process_time()
        file_bytes = path.stat().st_size
    target = Film(width, height, ("Combined",))
    began_add = time.process_time()
    parts.add(target, back)
    added = time.process_time()
    mp = n / 1e6
    return {"write_s_per_mp": (written - began) / mp, "read_s_per_mp": (read - written) / mp,
            "add_s_per_mp": (added - began_add) / mp, "pickle_bytes_per_px": len(pickle.dumps(back)) / n,
            "file_bytes_per_px": file_bytes / n}


def model(m: dict) -> dict:
    """Speed-ups on N machines, one worker each, from the measured figures.

    A task costs its share of the render (this machine's measured samples per CPU second, on
    every core), the worker overhead (child process, bpy, opening the file, export, preparation:
    its measured CPU seconds, on one core), and
    its part's write and read on the worker (per pixel, measured in (c)). The client receives
    and adds the parts one after another: bytes at NETWORK, then the add (measured). One machine
    without a farm pays the render plus one CLI process's overhead (measured). A frame is split
    into N ranges; an animation is one task per frame, in ceil(frames / N) rounds, its parts
    received while later frames render.
    """
    rate = m["single"]["samples_per_cpu_s"] * m["cores"]  # every core of an idle machine
    worker = m["farm"]["worker_overhead_cpu_s"]
    fixed = m["farm"]["connect_s"] + m["farm"]["ship_s"]
    alone = m["single"]["cpu_s"] - m["single"]["render_cpu_s"]
    p = m["parts"]

    def on_worker(px):
        return worker + px / 1e6 * (p["write_s_per_mp"] + p["read_s_per_mp"])

    def at_client(px):
        return px * p["pickle_bytes_per_px"] / NETWORK + px / 1e6 * p["add_s_per_mp"]

    w, h, spp = FRAME_4K
    render = w * h * spp / rate
    frame = {n: (render + alone) / (fixed + render / n + on_worker(w * h) + n * at_client(w * h))
             for n in MODEL_MACHINES}
    aw, ah, aspp, frames = ANIMATION
    px = aw * ah
    per_frame = px * aspp / rate
    animation = {n: frames * (per_frame + alone)
                 / (fixed + max(math.ceil(frames / n) * (per_frame + on_worker(px)), frames * at_client(px))
                    + at_client(px))
                 for n in MODEL_MACHINES}
    return {"frame_render_s": render, "frame": frame, "animation_frame_s": per_frame, "animation": animation,
            "worker_s": worker, "fixed_s": fixed, "alone_s": alone}


def measure(size: int, samples: int) -> dict:
    threads = os.cpu_count() or 1
    common = ["--samples", samples, "--seed", 1, "--resolution", f"{size}x{size}"]
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        wall, cpu, single = cli(folder, "single", *common, "--engine-threads", threads)
        farm_wall, farm_cpu, farm = cli(folder, "farm", *common, "--workers", 2)
    tasks = farm["stats"]["farm"]["tasks"]
    stats = single["stats"]
    return {
        "scene": SCENE.name, "size": size, "samples": samples, "cores": threads,
        "load": [load, os.getloadavg()[0]],
        "single": {"wall_s": wall, "cpu_s": cpu, "render_s": stats["elapsed"], "render_cpu_s": stats["cpu"],
                   "samples_per_cpu_s": size * size * samples / stats["cpu"]},
        "farm": {"workers": 2, "wall_s": farm_wall, "cpu_s": farm_cpu, "connect_s": farm["stats"]["farm"]["connect"],
                 "ship_s": farm["stats"]["farm"]["ship"], "tasks": tasks,
                 "worker_overhead_cpu_s": float(np.mean([t["cpu"] - t["render_cpu"] for t in tasks])),
                 "return_overhead_s": float(np.mean([t["returned"] - t["task"] for t in tasks])),
                 "merge_s": float(sum(t["merge"] for t in tasks))},
        "parts": part_costs(),
        "same_estimate": farm["stats"]["relmse"] / stats["relmse"],
    }


def _load_words(m: dict) -> str:
    """What the load average says about the wall times."""
    if max(m["load"]) > m["cores"]:
        return "other jobs shared the cores, so wall times are stretched and the CPU seconds are the figures to go by"
    return "nothing else ran, so wall times are the machine's own"


def section(m: dict) -> str:
    f, s = m["farm"], m["single"]
    mod = m["model"]
    rows = "\n".join(f"| {t['range'][0]}:{t['range'][1]} | {t['task']:.1f} | {t['render']:.1f} | {t['cpu']:.1f} | "
                     f"{t['render_cpu']:.1f} | {t['cpu'] - t['render_cpu']:.1f} | {t['returned'] - t['task']:.2f} |"
                     for t in f["tasks"])
    w, h, spp = FRAME_4K
    aw, ah, aspp, frames = ANIMATION
    model_rows = "\n".join(f"| {n} | {mod['frame'][n]:.1f}x | {mod['animation'][n]:.1f}x |" for n in MODEL_MACHINES)
    p = m["parts"]
    return f"""Measured by `bench/farm.py` on this machine ({m['cores']} cores; load average {m['load'][0]:.0f} at the start and
{m['load'][1]:.0f} at the end: {_load_words(m)}): `{m['scene']}` at {m['size']}x{m['size']}, {m['samples']} samples.
2 local workers took {f['wall_s'] / s['wall_s']:.2f} times the wall time of 1 process (cluster start and each task's
overhead below against a render of {s['render_s']:.1f} s).

| run | wall (s) | CPU, all processes (s) | rendering, wall (s) | rendering, CPU (s) |
|---|---|---|---|---|
| 1 process, {m['cores']} threads | {s['wall_s']:.1f} | {s['cpu_s']:.1f} | {s['render_s']:.1f} | {s['render_cpu_s']:.1f} |
| `--workers 2` (1 thread each), 2 tasks | {f['wall_s']:.1f} | {f['cpu_s']:.1f} | see the tasks | |

| task (samples) | on the worker, wall (s) | rendering, wall (s) | task CPU (s) | rendering CPU (s) | overhead CPU (s) | scheduling and return, wall (s) |
|---|---|---|---|---|---|---|
{rows}

The LocalCluster started and every worker was checked in {f['connect_s']:.1f} s; the .blend reached
every worker in {f['ship_s']:.2f} s; adding the parts took {f['merge_s'] * 1000:.1f} ms.
A task's overhead is its child process starting Python, bpy and DRT, opening the .blend, exporting it
and preparing the render (BVH, lights, compiled kernels from the cache), then writing the part; it does
not depend on the sample count. A part costs, in CPU seconds per megapixel, {p['write_s_per_mp']:.2f} s to
write, {p['read_s_per_mp']:.2f} s to read and {p['add_s_per_mp']:.2f} s to add, and
{p['pickle_bytes_per_px']:.0f} bytes a pixel over the network (Combined only; 8 bytes more a pixel for each
further pass channel). The merged estimated relMSE is {m['same_estimate']:.9f} times the single render's.

Model (`bench/farm.py`'s `model`): speed-up over one machine of this kind rendering alone, one worker per
machine, from the CPU seconds above (a render's CPU seconds spread over the {m['cores']} cores, the overheads
run on one core) and 1 Gbit/s between machines. A {w}x{h} frame at {spp} samples
({mod['frame_render_s'] / 3600:.1f} h on one machine) split into N ranges; a {frames}-frame animation at
{aw}x{ah}, {aspp} samples ({mod['animation_frame_s'] / 60:.1f} min a frame), one task per frame.
Per task {mod['worker_s']:.1f} s of overhead; one render alone {mod['alone_s']:.1f} s.

| machines | {w}x{h} frame | {frames}-frame animation |
|---|---|---|
{model_rows}
"""


def publish(text: str) -> None:
    replace_between(PAGE, MARK_BEGIN, MARK_END, text)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--samples", type=int, default=256)
    args = parser.parse_args()
    m = measure(args.size, args.samples)
    m["model"] = model(m)
    (ROOT / "bench" / "FARM.json").write_text(json.dumps(m, indent=1))
    publish(section(m))
    print(section(m))


if __name__ == "__main__":
    main()
