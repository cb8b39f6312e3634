"""Measured blocks of the docs pages, written by the scripts that measure them, so no figure there
is typed by hand.

A block sits between two marker comments (``<!-- bench:NAME -->`` and ``<!-- /bench:NAME -->``, or a
script's own pair); the script that measures it replaces everything in between and nothing else.
"""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = {  # bench:NAME block -> the docs page (or the README) that holds it
    "gi-pair": ROOT / "README.md",
    "zip-sizes": DOCS / "install.md",
    "throughput": DOCS / "performance.md",
    "preview-times": DOCS / "performance.md",
    "instances": DOCS / "performance.md",
    "render-time": DOCS / "performance.md",
    "adaptive-calibration": DOCS / "adaptive-sampling.md",
    "adaptive-calibration-gi": DOCS / "adaptive-sampling.md",
    "adaptive-gain": DOCS / "adaptive-sampling.md",
    "bench-adaptive": DOCS / "adaptive-sampling.md",
    "ratio": DOCS / "ratio-estimator.md",
    "viewport-times": DOCS / "viewport.md",
    "viewport-denoise": DOCS / "viewport.md",
    "denoise": DOCS / "denoising.md",
    "denoise-calibration": DOCS / "denoising.md",
    "denoise-feature-noise": DOCS / "denoising.md",
    "denoise-noise-scaling": DOCS / "denoising.md",
}
RESULTS_THROUGHPUT = ("<!-- throughput: begin -->", "<!-- throughput: end -->")
"""bench/throughput.py's section of bench/RESULTS.md, which bench/run.py keeps when it rewrites the file."""


def replace_between(path: Path, begin: str, end: str, text: str) -> None:
    """Put ``text`` on lines of its own between the markers ``begin`` and ``end`` of ``path``;
    both must be there already."""
    old = path.read_text()
    if begin not in old or end not in old:
        raise SystemExit(f"{path.relative_to(ROOT)} has no {begin} ... {end} block")
    block = f"{begin}\n{text.strip()}\n{end}"
    path.write_text(re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: block, old, flags=re.S))


def write_block(name: str, text: str) -> None:
    """Replace the block ``bench:name`` of its docs page (``PAGES``) with ``text``."""
    replace_between(PAGES[name], f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->", text)
