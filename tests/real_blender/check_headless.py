"""Debian's Blender 4.3.2 renders with the installed extension from the command line, as
render farms do (``blender -b FILE -E DRT -o ... -f 1``), and gets the bpy-wheel image.

Both sides render the same file (saved by 4.3) with the same seed and samples; they
differ in Blender (4.3 / 5.0), Python (3.13 / 3.11) and NumPy (2.2 / 1.26), so the images
are compared statistically rather than bit for bit.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import IGNIS_SCENES, REPO, SAMPLE_SCENES

NAMES = SAMPLE_SCENES + tuple(f"ignis_{name}" for name in IGNIS_SCENES)
MEMORY_GROWTH_MB = 8.0
"""Largest growth of Blender's resident memory from one animation frame to the next."""


def read_rgb(path: Path) -> np.ndarray:
    """The RGB of an EXR's Combined (single-layer R, G, B or multilayer *.Combined.R...)."""
    image = oiio.ImageInput.open(str(path))
    assert image is not None, oiio.geterror()
    try:
        spec = image.spec()
        pixels = image.read_image(format="float").reshape(spec.height, spec.width, spec.nchannels)
    finally:
        image.close()
    names = list(spec.channelnames)
    index = [next(i for i, n in enumerate(names) if n == c or n.endswith(f"Combined.{c}")) for c in "RGB"]
    return pixels[..., index]


def blender_output_problems(output: str) -> list[str]:
    """Lines of Blender's output that report a failure (reports are printed on stdout)."""
    return [line for line in output.splitlines() if "ERROR" in line or "Error:" in line or "DRT internal" in line]


@pytest.mark.parametrize("name", NAMES)
def test_command_line_render_matches_the_bpy_wheel(installed, scenes, name, tmp_path):
    if name not in scenes:
        pytest.skip("the Ignis scenes are not there (set DRT_IGNIS_SCENES)")
    env, blend = installed, scenes[name]
    out = env.work / "headless" / f"{name}_"
    output = env.blender("-b", env.inside(blend), "-E", "DRT", "-o", env.inside(out), "-F", "OPEN_EXR", "-f", "1")
    assert not blender_output_problems(output), output
    frame = Path(f"{out}0001.exr")
    assert frame.is_file(), output
    real = read_rgb(frame)

    wheel_file = tmp_path / f"{name}.exr"
    subprocess.run([sys.executable, "-m", "drt_engine", "render", str(blend), "-o", str(wheel_file)],
                   cwd=REPO, check=True, capture_output=True, text=True)
    wheel = read_rgb(wheel_file)

    assert real.shape == wheel.shape
    assert np.isfinite(real).all()
    mean = float(wheel.mean())
    assert mean > 0.0, "the bpy-wheel render is black"
    # Same seed and samples: the images agree up to floating-point noise, which may flip a
    # few samples (another reflection, another light sample) in a few pixels, not the image.
    assert abs(float(real.mean()) - mean) <= 0.01 * mean
    difference = np.abs(real - wheel)
    assert float(difference.mean()) <= 0.01 * mean
    assert float(np.mean(difference > 0.05 * mean + 1e-4)) <= 0.02


def test_animation_writes_every_frame_without_growing(installed, scenes):
    """``-s 1 -e 3 -a`` on the motion-blur scene: three frames written, memory flat."""
    env = installed
    out = env.work / "animation" / "frame_"
    log = env.work / "animation.log"
    output = env.blender("-b", env.inside(scenes["motion_blur"]), "--python", env.script("memory_log.py"),
                         "-E", "DRT", "-o", env.inside(out), "-F", "PNG", "-s", "1", "-e", "3", "-a",
                         "--", env.inside(log))
    assert not blender_output_problems(output), output
    for frame in (1, 2, 3):
        assert Path(f"{out}{frame:04d}.png").is_file(), output
    lines = log.read_text().splitlines()
    assert lines[0] == "motion_blur True"
    memory = {int(f): float(mb) for f, mb in (line.split() for line in lines[1:])}
    assert sorted(memory) == [1, 2, 3], lines
    # The first frame pays for imports and one-off allocations; after it, nothing may pile up.
    assert memory[3] - memory[2] <= MEMORY_GROWTH_MB, memory
