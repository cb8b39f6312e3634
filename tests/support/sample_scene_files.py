"""The sample scenes' .blend files, and how to build them afresh from their scripts.

The committed files are saved by Blender 5.0, whose files Blender 4.x cannot open ("not a blend
file"); tests that render a sample scene under 4.x open a copy built by the scene's script in that
Blender instead (the ``sample_scene`` fixture).
"""
import subprocess
import sys
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[2]
SCENES_DIR = ROOT / "sample_scenes"
SCENES = ("cornell_box", "glossy_spheres", "dof_row", "motion_blur")
OPENS_COMMITTED_FILES = bpy.app.version >= (5, 0, 0)


def build(name: str, target: Path) -> Path:
    """Run sample_scenes/build_NAME.py into ``target`` with this Python, as `make scenes` runs it."""
    proc = subprocess.run([sys.executable, str(SCENES_DIR / f"build_{name}.py"), str(target)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return target
