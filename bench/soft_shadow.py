"""The soft-shadow scene of issue 13: a plane, a sphere and a cube under one rectangular area light.

Most of its pixels are lit floor that converges fast; the error sits in the penumbrae, so
it shows whether adaptive sampling moves samples there with its default settings.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Mesh, SceneData  # noqa: E402


def _core_test_scenes():
    """tests/core/scenes.py (the core tests' scene helpers), loaded by path: bench/scenes.py has its name."""
    spec = importlib.util.spec_from_file_location("core_test_scenes", ROOT / "tests" / "core" / "scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_helpers = _core_test_scenes()
look_at, plane, translation, uv_sphere = _helpers.look_at, _helpers.plane, _helpers.translation, _helpers.uv_sphere


def cube(center, half, material):
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * half + center
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return Mesh("cube", corners, tris, [material] * len(tris))


def soft_shadow_scene(width=160):
    """The scene at ``width`` x 3/4 width pixels, and the settings it renders with (box filter 1.5)."""
    height = width * 3 // 4
    mats = [Material("floor", [Closure("DIFFUSE", color=(0.6, 0.6, 0.6))]),
            Material("sphere", [Closure("DIFFUSE", color=(0.7, 0.3, 0.2))]),
            Material("cube", [Closure("DIFFUSE", color=(0.2, 0.4, 0.7))])]
    meshes = [plane(20.0), uv_sphere(0.8, (-0.9, 0.0, 0.8), material=1), cube(np.array([1.1, 0.4, 0.6]), 0.6, 2)]
    half = 0.45
    camera = Camera(look_at((0.0, -6.0, 4.0), (0.0, 0.3, 0.4))[None], (-half, half, -half * height / width,
                                                                      half * height / width), (width, height))
    light_matrix = translation(0.5, -0.5, 4.0)
    light = Light("AREA", light_matrix, radiance=np.full(3, 15.0), shape="RECTANGLE", size_x=2.0, size_y=1.0)
    scene = SceneData(camera, meshes, [Instance(i, np.eye(4)) for i in range(len(meshes))], mats, [light])
    scene.world.radiance = np.full(3, 0.02)
    return scene, dict(max_depth=8, filter_type="BLACKMAN_HARRIS", filter_size=1.5, threads=0)
