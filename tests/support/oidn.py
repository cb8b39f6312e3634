"""The OpenImageDenoise library the bpy module in this venv ships, found without importing bpy
(tests/core stay bpy-free): ``bpy/lib/libOpenImageDenoise.so.2`` beside the bpy package."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest


def bpy_oidn_library() -> Path | None:
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.origin:
        return None
    folder = Path(spec.origin).parent / "lib"
    found = sorted(folder.glob("libOpenImageDenoise.so*")) + sorted(folder.glob("OpenImageDenoise.dll")) \
        + sorted(folder.glob("libOpenImageDenoise*.dylib"))
    found = [p for p in found if "_core" not in p.name and "_device" not in p.name]
    return found[0] if found else None


def require_oidn() -> Path:
    """The library's path, or skip the test where the bpy module ships none."""
    path = bpy_oidn_library()
    if path is None:
        pytest.skip("no bpy module with OpenImageDenoise in this environment")
    return path
