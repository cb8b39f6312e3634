"""CPU nanoseconds per light sample through Lights.sample, one light kind at a time, on a wave
of 65,536 shading points (the API render.py calls, so the same script times any version).

Usage: python bench/light_sampling_speed.py
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drt_engine.core.render.render import Renderer  # noqa: E402
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World  # noqa: E402
from drt_engine.core.settings import RenderSettings  # noqa: E402
from tests.support.scenes import look_at, plane, top_camera, translation  # noqa: E402

N = 65_536
REPEAT = 20
DOWN = look_at((0.3, 0.2, 1.2), (0.1, 0.0, 0.0))
KINDS = {
    "point (delta)": Light("POINT", translation(0, 0, 1), intensity=np.ones(3), radius=0.0),
    "point (sphere)": Light("POINT", translation(0, 0, 1), intensity=np.ones(3), radius=0.1, soft_falloff=False),
    "point (soft disk)": Light("POINT", translation(0, 0, 1), intensity=np.ones(3), radius=0.1),
    "spot (soft disk)": Light("SPOT", DOWN, intensity=np.ones(3), radius=0.1),
    "sun (angle)": Light("SUN", DOWN, irradiance=np.ones(3), angle=0.1),
    "rectangle": Light("AREA", DOWN, radiance=np.ones(3), size_x=0.5, size_y=0.3),
    "ellipse (spread)": Light("AREA", DOWN, radiance=np.ones(3), shape="ELLIPSE", size_x=0.5, size_y=0.3, spread=1.0),
    "world (uniform)": None,
    "emissive triangles": "emissive",
}


def lights_of(light):
    mats = [Material("white", [Closure("DIFFUSE", color=(0.5,) * 3)]),
            Material("glow", [Closure("EMISSION", emission=(1.0,) * 3)])]
    meshes, instances = [plane()], [Instance(0, np.eye(4))]
    if light == "emissive":
        meshes.append(plane(1.0, z=1.0, material=1))
        instances.append(Instance(1, np.eye(4)))
    scene = SceneData(top_camera(), meshes, instances, mats, [light] if isinstance(light, Light) else [],
                      World(np.full(3, 1.0 if light is None else 0.0)))
    return Renderer(scene, RenderSettings(samples=1, threads=1)).lights


def main():
    rng = np.random.default_rng(1)
    pos = np.column_stack([rng.uniform(-1, 1, N), rng.uniform(-1, 1, N), np.zeros(N)])
    normal = np.tile([0.0, 0.0, 1.0], (N, 1))
    u, u_pick = rng.random((N, 2)), rng.random(N)
    for name, light in KINDS.items():
        lights = lights_of(light)
        lights.sample(0, pos, normal, u, u_pick)  # compiled or loaded
        start = time.process_time()
        for _ in range(REPEAT):
            lights.sample(0, pos, normal, u, u_pick)
        ns = (time.process_time() - start) / (REPEAT * N) * 1e9
        print(f"{name:20s} {ns:6.1f} ns per sample", flush=True)


if __name__ == "__main__":
    main()
