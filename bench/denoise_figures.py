"""docs/denoising.md's block ``bench:denoise`` from what tests/blender/test_denoise.py measured (out/ui/denoise.json).

    .venv/bin/python -m pytest tests/blender/test_denoise.py && .venv/bin/python bench/denoise_figures.py
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
MEASURED = ROOT / "out" / "ui" / "denoise.json"


def block(m: dict) -> str:
    return "\n".join([
        "| image | relMSE vs reference |", "|---|---|",
        f"| {m['samples']} samples, noisy | {m['relmse_noisy']:.2e} |",
        f"| {m['samples']} samples, Denoise node (Image + Denoising Albedo + Denoising Normal) "
        f"| {m['relmse_denoised']:.2e} |",
        "",
        f"The denoised image is {m['ratio']:.1f} times closer ({m['scene']}, {m['resolution']}x{m['resolution']} px, "
        f"reference {m['reference_samples']} samples, Blender {m['blender']}; images in `out/ui/denoise_*.png`).",
    ])


def main() -> None:
    from bench.blocks import write_block

    write_block("denoise", block(json.loads(MEASURED.read_text())))


if __name__ == "__main__":
    main()
