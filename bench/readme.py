"""Blocks of README.md that the bench scripts write, so no figure there is typed by hand.

A block sits between ``<!-- bench:NAME -->`` and ``<!-- /bench:NAME -->``; the script that
measures it replaces everything in between and nothing else.
"""
from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def write_block(name: str, text: str, path: Path = README) -> None:
    """Replace the block ``name`` of ``path`` with ``text``; its markers must be there already."""
    begin, end = f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->"
    old = path.read_text()
    if begin not in old or end not in old:
        raise SystemExit(f"{path.name} has no {begin} ... {end} block")
    block = f"{begin}\n{text.strip()}\n{end}"
    path.write_text(re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: block, old, flags=re.S))
