"""Rays per second of DRT's own Embree binding (core/geometry/embree.py: ``intersect_batch`` and
``occluded_batch``, one rtcIntersect1/rtcOccluded1 call per ray from a compiled kernel) against
embreex's ``EmbreeScene.run`` (``output=1`` for closest hits, ``OCCLUDED``) on the same library:
1M incoherent rays (tests/core/test_embree.py's shell-to-cube rays) on a ~32k-triangle UV sphere,
one thread, kernels warm, in rays per CPU second of the calling thread (robust to other load on the
machine), best of 5 runs taken in turn.
Run: python bench/embree_binding.py (prints; writes nothing).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drt_engine.core.geometry import embree  # noqa: E402
from tests.core.test_embree import _embreex, _random_rays  # noqa: E402
from tests.support.scenes import uv_sphere  # noqa: E402

N = 1_000_000


def best_rates(*runs) -> list[float]:
    seconds = [[] for _ in runs]
    for _ in range(5):
        for run, taken in zip(runs, seconds):
            start = time.thread_time()
            run()
            taken.append(time.thread_time() - start)
    return [N / min(taken) for taken in seconds]


def main() -> None:
    mesh = uv_sphere(radius=1.0, segments=128, rings=128)
    vertices, triangles = mesh.vertices.astype(np.float32), mesh.triangles.astype(np.int32)
    origins, directions = _random_rays(np.random.default_rng(0), N)
    theirs = _embreex(vertices, triangles)
    ours = embree.TriangleScene(vertices, triangles)
    embree.intersect(ours, origins[:10], directions[:10])  # compile (or load) the kernels
    embree.occluded(ours, origins[:10], directions[:10])
    print(f"{len(triangles)} triangles, {N} incoherent rays, one thread; M rays per CPU second (best of 5)")
    print(f"{'query':<18}{'DRT kernel':>12}{'embreex run':>13}{'ratio':>8}")
    for query, drt, other in (
        ("closest hit", lambda: embree.intersect(ours, origins, directions),
         lambda: theirs.run(origins, directions, output=1)),
        ("occluded", lambda: embree.occluded(ours, origins, directions),
         lambda: theirs.run(origins, directions, query="OCCLUDED")),
    ):
        a, b = best_rates(drt, other)
        print(f"{query:<18}{a / 1e6:>12.2f}{b / 1e6:>13.2f}{a / b:>8.2f}")


if __name__ == "__main__":
    main()
