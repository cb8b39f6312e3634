"""Numerics suite: the sample scenes' helpers (scene_helpers) on the path, DRT registered."""
import sys
from pathlib import Path

import pytest

SAMPLE_SCENES = Path(__file__).resolve().parents[2] / "sample_scenes"
if str(SAMPLE_SCENES) not in sys.path:
    sys.path.insert(0, str(SAMPLE_SCENES))


@pytest.fixture(scope="session")
def drt():
    """DRT registered in this bpy session (imports bpy only for the cases that need Blender)."""
    import drt_engine
    from drt_engine.blender.engine import DRTRenderEngine

    if not DRTRenderEngine.is_registered:
        drt_engine.register()
    yield
