"""Cost per call of the closed-form unoccluded irradiance (``unoccluded``, core/lights/kinds.py) per light kind,
and its worst relative error against the reference cubature of tests/core/test_unoccluded.py.

Cost: ``unoccluded`` over a batch of random shading points under each light with random
normals (about a third of them horizon-clipped), kernels warm, best of 5 runs, in ns per call
(one point, one light); emissive triangles per triangle. Error: the worst over the test's
cases of |closed form - cubature| / cubature, per kind.
Run: python bench/unoccluded_cost.py (prints a table; writes nothing).
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drt_engine.core.lights.table import light_table  # noqa: E402
from drt_engine.core.scene import Light  # noqa: E402
from drt_engine.core.lights.collection import _unoccluded_rows  # noqa: E402
from drt_engine.core.lights.triangles import unoccluded_triangles_batch  # noqa: E402
from tests.core import test_unoccluded as t  # noqa: E402

N = 200_000


def lights():
    down = (0.0, 0.0, 1.0)
    return {
        "rectangle": t.area_light("RECTANGLE", (0.0, 0.0, 1.0), down, 1.0, 0.6),
        "disk (whole)": t.area_light("DISK", (0.0, 0.0, 1.0), down, 0.6, 0.6),
        "ellipse": t.area_light("ELLIPSE", (0.0, 0.0, 1.0), down, 1.2, 0.5),
        "sphere": t.sphere(0.2, False, (0.0, 0.0, 1.0)),
        "soft falloff disk": t.sphere(0.2, True, (0.0, 0.0, 1.0)),
        "point (delta)": t.sphere(0.0, True, (0.0, 0.0, 1.0)),
        "spot (delta)": Light("SPOT", t.frame((0.0, 0.0, 1.0), down), intensity=np.ones(3), spot_size=1.5),
        "sun (angle 0.5)": Light("SUN", t.frame((0, 0, 0), (0.2, 0.1, 1.0)), irradiance=np.ones(3), angle=0.5),
        "sun (delta)": Light("SUN", t.frame((0, 0, 0), (0.2, 0.1, 1.0)), irradiance=np.ones(3)),
    }


def points_and_normals(rng):
    pos = np.column_stack([rng.uniform(-1.5, 1.5, N), rng.uniform(-1.5, 1.5, N), np.zeros(N)])
    n = rng.normal(size=(N, 3))
    n[:, 2] = np.abs(n[:, 2]) + 0.3  # mostly facing up, a share of them clipping the light
    return pos, n / np.linalg.norm(n, axis=1, keepdims=True)


def best_of(fn, runs=5):
    fn()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def cost():
    rng = np.random.default_rng(1)
    pos, normal = points_and_normals(rng)
    out, rows = np.zeros((N, 3)), np.zeros(N, np.int64)
    print(f"{'kind':22s} ns per call")
    for name, light in lights().items():
        table = light_table([light])
        seconds = best_of(lambda: _unoccluded_rows(table, rows, pos, normal, out))
        print(f"{name:22s} {seconds / N * 1e9:8.1f}")
    verts, tris, emission = t.TRIANGLES
    ids = np.array([0, 1], np.int64)
    seconds = best_of(lambda: unoccluded_triangles_batch(verts, tris, emission, ids, pos, normal, out))
    print(f"{'emissive triangle':22s} {seconds / N / len(ids) * 1e9:8.1f}")


def worst_errors():
    worst = {}

    def note(kind, got, want):
        worst[kind] = max(worst.get(kind, 0.0), abs(got - want) / want)

    for shape in ("RECTANGLE", "ELLIPSE"):
        for centre, w, sx, sy, p, n, _ in t.AREA_CASES.values():
            light = t.area_light(shape, centre, w, sx, sy)
            note(shape.lower(), t.closed(light, p, n)[0] / light.radiance[0], t.plane_reference(light, p, n))
    for soft in (False, True):
        for r, centre, p, n, _ in t.CAP_CASES.values():
            d = np.asarray(centre) - np.asarray(p)
            dist = np.linalg.norm(d)
            sin_s = r / math.hypot(dist, r) if soft else r / dist
            light = t.sphere(r, soft, centre)
            note("soft falloff disk" if soft else "sphere", t.closed(light, p, n)[0] / light.intensity[0],
                 t.cap_reference(d, sin_s, n, 1.0 / (math.pi * r * r)))
    for angle, toward, n, _ in t.SUN_CASES.values():
        light = Light("SUN", t.frame((0, 0, 0), toward), irradiance=np.ones(3), angle=angle)
        half = angle / 2
        note("sun", t.closed(light, (5.0, 1.0, 0.0), n)[0],
             t.cap_reference(toward, math.sin(half), n, 1.0 / (math.pi * math.sin(half) ** 2)))
    verts, tris, emission = t.TRIANGLES
    for p, n in (((0.1, 0.2, 0.0), (0.0, 0.0, 1.0)), ((0.1, 0.2, 0.0), (-0.9, -0.2, 0.3)),
                 ((0.1, 0.2, 2.0), (0.2, 0.1, -1.0))):
        out = np.zeros((1, 3))
        unoccluded_triangles_batch(verts, tris, np.ones_like(emission), np.array([0], np.int64),
                                   np.array([p], float), t.unit(n)[None], out)
        note("emissive triangle", out[0, 0], t.triangle_reference(0, p, n))
    print(f"\n{'kind':22s} worst relative error against cubature")
    for kind, err in worst.items():
        print(f"{kind:22s} {err:9.2e}")


if __name__ == "__main__":
    cost()
    worst_errors()
