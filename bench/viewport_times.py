"""docs/viewport.md's figures, from what the GUI test measured (out/ui/viewport_times.json).

``make test-blender`` drives Blender 4.3.2's GUI under Xvfb (tests/real_blender/in_blender/
gui_driver.py: the 3D view maximised, 50 orbit steps and 20 edits on the Cornell box) and
writes each step's time to the first new image drawn, to the first full-resolution image,
and Blender's resident memory after it. This prints the table; ``--publish`` also writes it
into docs/viewport.md between its markers, so the figures there are the ones measured, not typed.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from statistics import mean, median

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench.blocks import write_block  # noqa: E402
TIMES = ROOT / "out" / "ui" / "viewport_times.json"


def _seconds(values) -> str:
    found = [v for v in values if v is not None]
    if not found:
        return "none"
    return f"{median(found):.2f} s (worst {max(found):.2f} s)"


def table(times: dict) -> str:
    width, height = times["region"]
    rows = [f"Measured by `make test-blender` in Blender 4.3.2's GUI (Xvfb, Mesa's software OpenGL, the "
            f"machine's 2 cores shared with other work), Cornell box, kernels compiled before the "
            f"timed steps, a {width}x{height} region, "
            f"{times['preview_samples']} viewport samples; median (worst):", "",
            "| step | first new image | first full-resolution image |", "|---|---|---|"]
    groups = {"orbit step (3 degrees)": times["orbits"]}
    for kind in sorted({e["kind"] for e in times["edits"]}):
        groups[f"edit: {kind}"] = [e for e in times["edits"] if e["kind"] == kind]
    for name, steps in groups.items():
        rows.append(f"| {name} ({len(steps)}) | {_seconds(s['first_image_s'] for s in steps)} "
                    f"| {_seconds(s['full_resolution_s'] for s in steps)} |")
    steps = times["orbits"] + times["edits"]
    anon, rss = [s["anon_mb"] for s in steps], [s["rss_mb"] for s in steps]
    rows += ["", f"Blender's anonymous resident memory over the {len(steps)} steps: {mean(anon[:10]):.0f} MB "
             f"over the first ten, {mean(anon[-10:]):.0f} MB over the last ten (all resident memory: "
             f"{mean(rss[:10]):.0f} and {mean(rss[-10:]):.0f} MB). One redraw of Blender's window took "
             f"{times['window_redraw_s']:.2f} s here (software OpenGL): an image is on screen at the "
             "first redraw after the worker publishes it."]
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--times", type=Path, default=TIMES)
    parser.add_argument("--publish", action="store_true", help="write the table into docs/viewport.md")
    args = parser.parse_args()
    if not args.times.is_file():
        sys.exit(f"error: {args.times} does not exist: run make test-blender first")
    text = table(json.loads(args.times.read_text()))
    print(text)
    if args.publish:
        write_block("viewport-times", text)


if __name__ == "__main__":
    main()
