"""The README's Cycles | DRT pair with light bouncing off diffuse surfaces.

cornell_box rendered by Blender (``bpy.ops.render.render``) with DRT at diffuse bounces 0 (the
classic image) and 4, and with Cycles at 4, configured as the parity tests configure it
(tests.support.render_helpers.configure_cycles: the same Light Paths and pixel filter, no
denoising, no adaptive sampling). Each result is saved through the scene's colour management as a
PNG in docs/images/ and as a linear EXR, whose Combined means go into the caption.
Writes README's block ``bench:gi-pair``.
Run: python bench/gi_pair.py [--width 256] [--samples 256]
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
from tests.support.render_helpers import configure_cycles, read_channels  # noqa: E402

IMAGES = ROOT / "docs" / "images"
BOUNCES = 4
RENDERS = (("DRT", 0), ("DRT", BOUNCES), ("CYCLES", BOUNCES))


def render(scene, engine: str, bounces: int, samples: int, folder: Path) -> tuple[Path, np.ndarray]:
    """The PNG of one render in docs/images/ and its linear Combined RGB."""
    scene.drt.diffuse_bounces = bounces
    scene.drt.samples = samples
    scene.drt.use_adaptive_sampling = False
    scene.drt.use_denoising = False
    scene.drt.seed = 0
    configure_cycles(scene, samples, 0)
    scene.render.engine = engine
    bpy.ops.render.render(scene=scene.name)
    result = bpy.data.images["Render Result"]
    png = IMAGES / f"cornell_box_{engine.lower()}_diffuse{bounces}.png"
    exr = folder / f"{engine}_{bounces}.exr"
    settings = scene.render.image_settings
    settings.file_format, settings.color_mode, settings.color_depth = "PNG", "RGB", "8"
    result.save_render(str(png), scene=scene)
    settings.file_format, settings.color_mode, settings.color_depth = "OPEN_EXR", "RGBA", "32"
    result.save_render(str(exr), scene=scene)
    channels = read_channels(exr)
    return png, np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=256)
    parser.add_argument("--samples", type=int, default=256)
    args = parser.parse_args(argv)
    drt_engine.register()
    scene, _ = load("cornell_box", args.width)
    scene.render.image_settings.media_type = "IMAGE"
    with tempfile.TemporaryDirectory() as folder:
        shots = {(engine, b): render(scene, engine, b, args.samples, Path(folder)) for engine, b in RENDERS}
    drt, cycles = shots["DRT", BOUNCES][1].mean(), shots["CYCLES", BOUNCES][1].mean()
    classic = shots["DRT", 0][1].mean()
    cells = [f"![cornell_box, {'DRT' if e == 'DRT' else 'Cycles'}, diffuse bounces {b}](docs/images/{p.name})"
             for (e, b), (p, _) in shots.items()]
    text = "\n".join([
        f"| DRT, diffuse bounces 0 | DRT, diffuse bounces {BOUNCES} | Cycles, diffuse bounces {BOUNCES} |",
        "|---|---|---|",
        "| " + " | ".join(cells) + " |",
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
