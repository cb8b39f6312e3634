"""The soft-shadow scene of issue 13: a plane, a sphere and a cube under one rectangular area light
(built in tests/core/scenes.py, whose core tests render it too).

Most of its pixels are lit floor that converges fast; the error sits in the penumbrae, so
it shows whether adaptive sampling moves samples there with its default settings.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _core_test_scenes():
    """tests/core/scenes.py (the core tests' scene helpers), loaded by path: bench/scenes.py has its name."""
    spec = importlib.util.spec_from_file_location("core_test_scenes", ROOT / "tests" / "core" / "scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_helpers = _core_test_scenes()
soft_shadow_scene = _helpers.soft_shadow_scene
