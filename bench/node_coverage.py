"""Write the list of the shader nodes DRT evaluates and leaves out into docs/shader-nodes.md.

The list comes from drt_engine.blender.export.coverage, which reads the export's own handlers,
so it says what the warnings say. Run from the repository root with the Blender the docs are for
(the bpy wheel make test uses): .venv/bin/python bench/node_coverage.py
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

from bench.blocks import replace_between  # noqa: E402
from drt_engine.blender.export import coverage  # noqa: E402

MARK_BEGIN, MARK_END = "<!-- node coverage: begin -->", "<!-- node coverage: end -->"
PAGE = ROOT / "docs" / "shader-nodes.md"


def block() -> str:
    names = coverage.shader_node_types()
    done = coverage.evaluated()
    left = coverage.left_out()

    def listed(kinds):
        return ", ".join(sorted(coverage.label(k) for k in kinds))

    return "\n".join([
        f"Written by `bench/node_coverage.py` from the export's handlers (Blender {bpy.app.version_string}, "
        f"{len(names)} shader node types):", "",
        f"- **Evaluated** ({len([n for n in names if n in done])}): {listed(n for n in names if n in done)}.",
        f"- **Walked through:** {listed(coverage.STRUCTURE)}.",
        f"- **Left out, named in the warning where used** ({len(left)}): {listed(left)}. A closure renders "
        "default grey, any other node leaves the socket it feeds its own value; a volume shader and a world's "
        "AOV Output fed by a texture are named too.",
        f"- **Not rendered by Cycles either:** {listed(n for n in coverage.NOT_IN_CYCLES if n in names)}.", ""])


def read_block() -> str:
    text = PAGE.read_text()
    return text[text.index(MARK_BEGIN) + len(MARK_BEGIN) + 1:text.index(MARK_END)]


def main() -> None:
    replace_between(PAGE, MARK_BEGIN, MARK_END, block())
    print(f"{len(coverage.left_out())} shader node types left out")


if __name__ == "__main__":
    main()
