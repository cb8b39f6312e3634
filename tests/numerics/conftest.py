"""Numerics suite: the core's hand-made scenes, the Blender and sample-scene helpers on the path, DRT registered."""
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parents[1]
for folder in (TESTS / "core", TESTS / "blender", TESTS / "numerics", TESTS.parent / "sample_scenes"):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))


@pytest.fixture(scope="session")
def drt():
    """DRT registered in this bpy session (imports bpy only for the cases that need Blender)."""
    import drt_engine
    from drt_engine.blender.engine import DRTRenderEngine

    if not DRTRenderEngine.is_registered:
        drt_engine.register()
    yield
