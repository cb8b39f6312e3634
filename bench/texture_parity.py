"""Measure DRT's procedural textures against Cycles and write the figures into docs/shader-node-parity.md.

Renders tests/support/procedural_scenes.py's grid (one tile per texture and mode), lit
scene and Box-projected image with DRT (seed 0) and Cycles (seeds 0 and 1) at 64 samples, as the parity test does,
writes docs/texture_parity.json, and replaces docs/shader-node-parity.md's block between the markers below with
a table of each case's worst 4x4-block difference from Cycles beside Cycles' own between its
two seeds. Run from the repository root: .venv/bin/python bench/texture_parity.py
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

import drt_engine  # noqa: E402
from bench.blocks import replace_between  # noqa: E402
from tests.support import procedural_scenes as ps  # noqa: E402

MARK_BEGIN, MARK_END = "<!-- texture parity: begin -->", "<!-- texture parity: end -->"
JSON_PATH = ROOT / "docs" / "texture_parity.json"
PAGE = ROOT / "docs" / "shader-node-parity.md"
BOX_BLENDS = (0.0, 0.3)


def measure() -> dict:
    with tempfile.TemporaryDirectory() as out:
        grid = ps.grid_tiles(ps.grid_scene(), len(ps.CASES), out, "grid")
        cases = {case.name: ps.tile_figures(grid, i) for i, case in enumerate(ps.CASES)}
        lit = ps.parity_renders(ps.lit_scene(), out, "lit")
        cases["Lit scene (Voronoi x Noise ground, Brick and Wave sphere; sun and point light)"] = ps.parity(
            *(r.rgb for r in lit))
        for blend in BOX_BLENDS:
            box = ps.parity_renders(ps.box_scene(blend=blend), out, f"box-{blend}")
            cases[f"Image Texture, Box projection, blend {blend}"] = ps.parity(*(r.rgb for r in box))
    return {"blender": bpy.app.version_string, "samples": ps.SAMPLES, "tile_px": ps.TILE, "cases": cases}


def table(figures: dict) -> str:
    rows = [f"Measured by `bench/texture_parity.py` (Blender {figures['blender']}, {figures['samples']} samples, "
            f"{figures['tile_px']}-pixel tiles): the worst 4x4-block difference of DRT from Cycles, beside "
            "Cycles' own worst between two seeds; a case passes at 1.5x that plus 0.002.", "",
            "| texture and mode | DRT vs Cycles | Cycles vs Cycles | within |", "|---|---|---|---|"]
    rows += [row(name, f) for name, f in figures["cases"].items()]
    return "\n".join(rows) + "\n"


def row(name: str, f) -> str:
    """A case's table row: its figures, or the words standing in for them."""
    if isinstance(f, str):
        return f"| {name} | {f} | | |"
    return f"| {name} | {f['worst']:.4f} | {f['cycles_seeds']:.4f} | {'yes' if f['ok'] else '**no**'} |"


def publish(figures: dict, json_path: Path, marks: tuple[str, str], page_table: str, page: Path = PAGE) -> None:
    """Write the figures' JSON and the ``page``'s block, and say how many cases missed the limit."""
    json_path.write_text(json.dumps(figures, indent=1) + "\n")
    replace_between(page, *marks, page_table)
    failed = [name for name, f in figures["cases"].items() if not isinstance(f, str) and not f["ok"]]
    print(f"{len(figures['cases'])} cases, {len(failed)} outside the limit" + (f": {failed}" if failed else ""))


def main() -> None:
    drt_engine.register()
    figures = measure()
    publish(figures, JSON_PATH, (MARK_BEGIN, MARK_END), table(figures))


if __name__ == "__main__":
    main()
