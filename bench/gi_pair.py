"""The README's Cycles | DRT pair with light bouncing off diffuse surfaces.

cornell_box rendered by Blender (``bpy.ops.render.render``) with DRT at diffuse bounces 0 (the
classic image) and 4, and with Cycles at 4, configured as the parity tests configure it
(tests.support.render_helpers.render: the same Light Paths and pixel filter, no denoising, no
adaptive sampling). Each result is read back from its linear EXR, whose Combined means go into the
caption, and saved through the scene's colour management as a PNG in docs/images/.
Writes README's block ``bench:gi-pair``.
Run: make gi-pair, or python bench/gi_pair.py [--width 256] [--samples 256]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import drt_engine  # noqa: E402
from blocks import write_block  # noqa: E402
from drt_engine.headless.cli import exit_now  # noqa: E402
from scenes import load  # noqa: E402
from tests.support.render_helpers import render  # noqa: E402

IMAGES = ROOT / "docs" / "images"
BOUNCES = 4
RENDERS = (("DRT", 0), ("DRT", BOUNCES), ("CYCLES", BOUNCES))
NAMES = {"DRT": "DRT", "CYCLES": "Cycles"}


def shot(scene, engine: str, bounces: int, samples: int, folder: Path) -> tuple[Path, np.ndarray]:
    """One render (the tests' ``render``: its EXR read back) as a PNG in docs/images/, and its linear
    Combined RGB."""
    scene.drt.diffuse_bounces = bounces  # Cycles' too: configure_cycles copies DRT's Light Paths
    scene.drt.use_denoising = False
    combined = render(scene, engine, samples, 0, folder, name=f"diffuse{bounces}").passes["Combined"]
    png = IMAGES / f"cornell_box_{engine.lower()}_diffuse{bounces}.png"
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # Blender 5.0+
        settings.media_type = "IMAGE"
    settings.file_format, settings.color_mode, settings.color_depth = "PNG", "RGB", "8"
    bpy.data.images["Render Result"].save_render(str(png), scene=scene)
    return png, combined[..., :3].astype(np.float64)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=256)
    parser.add_argument("--samples", type=int, default=256)
    args = parser.parse_args(argv)
    drt_engine.register()
    scene, _ = load("cornell_box", args.width)
    with tempfile.TemporaryDirectory() as folder:
        shots = {(engine, b): shot(scene, engine, b, args.samples, Path(folder)) for engine, b in RENDERS}
    drt, cycles = shots["DRT", BOUNCES][1].mean(), shots["CYCLES", BOUNCES][1].mean()
    classic = shots["DRT", 0][1].mean()
    labels = [f"{NAMES[e]}, diffuse bounces {b}" for e, b in RENDERS]
    text = "\n".join([
        "| " + " | ".join(labels) + " |",
        "|---" * len(labels) + "|",
        "| " + " | ".join(f"![cornell_box, {label}](docs/images/{shots[key][0].name})"
                          for key, label in zip(RENDERS, labels)) + " |",
        "",
        f"cornell_box at {scene.render.resolution_x}x{scene.render.resolution_y}, {args.samples} samples per "
        f"pixel, no denoising, each saved through the scene's colour management (`make gi-pair`). "
        f"Mean of the linear Combined RGB: DRT {drt:.4f} and Cycles {cycles:.4f} at diffuse bounces {BOUNCES} "
        f"({drt / cycles - 1:+.2%}); DRT {classic:.4f} at 0, where the ceiling sees no light and the walls "
        f"no colour from each other.",
    ])
    write_block("gi-pair", text)
    print(text)


if __name__ == "__main__":
    main()
    exit_now(0)  # the bpy 4.2 module crashes in Python's teardown
