"""Emissive-triangle sampling (solid angle or area, lights.spherical_triangle) at its limits:
grazing, tiny, huge, far-from-origin and sliver triangles (zero-area ones emit no power and are never picked), points in the triangle's
plane, at a corner and on an edge's line, with the square's corners and edges as random numbers.
Every sample is finite, lies on the triangle, and its pdf is pdf_emissive's."""
from __future__ import annotations

import numpy as np
import pytest

from drt_engine.core.lights.emitter_tree import emitter_tree
from drt_engine.core.lights.triangles import pdf_emissive_batch
from tests.core.test_spherical_triangle import omega_at, samples, tables

BASE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.9, 0.0]])

CASES = {
    "above": (BASE, (0.3, 0.3, 0.5)),
    "grazing (1e-9 off the plane, beside)": (BASE, (1.5, 0.3, 1e-9)),
    "grazing (1e-9 off the plane, over it)": (BASE, (0.3, 0.3, 1e-9)),
    "in the plane, outside": (BASE, (2.0, 1.0, 0.0)),
    "in the plane, inside": (BASE, (0.3, 0.3, 0.0)),
    "at a corner": (BASE, (0.0, 0.0, 0.0)),
    "on an edge's line": (BASE, (3.0, 0.0, 1e-12)),
    "tiny (1e-8) and near": (BASE * 1e-8, (3e-9, 3e-9, 5e-9)),
    "tiny (1e-8) and far": (BASE * 1e-8, (0.0, 0.0, 10.0)),
    "huge (1e6)": (BASE * 1e6, (3e5, 3e5, 1.0)),
    "far from the origin (1e7)": (BASE + 1e7, (1e7 + 0.3, 1e7 + 0.3, 1e7 + 0.5)),
    "sliver (1e-9 wide)": (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-9, 0.0]]), (0.5, 0.2, 0.3)),
}

EDGES = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0], [0.5, 0.0], [0.0, 0.5], [1.0, 0.5], [0.5, 1.0],
                  [1e-300, 1e-300], [1.0 - 1e-16, 1.0 - 1e-16]])


@pytest.mark.parametrize("name", CASES)
def test_samples_are_finite_on_the_triangle_with_pdf_emissives_density(name):
    verts, p = CASES[name]
    verts, p = np.asarray(verts, float), np.array(p)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.cross(verts[1] - verts[0], verts[2] - verts[0])
        n = e / np.linalg.norm(e) if np.linalg.norm(e) > 0 else np.array([0.0, 0.0, 1.0])
    tree, _, rank = emitter_tree(verts[None], np.array([1.0]))
    t = (verts, np.array([[0, 1, 2]], np.int64), n[None], np.array([0.5 * np.linalg.norm(e)]), tree, rank)
    u = np.concatenate([EDGES, np.random.default_rng(6).random((400, 2))])
    s = samples(*t, p, u)
    assert np.isfinite(s).all(), name
    assert np.isfinite(omega_at(t[0], t[1], t[2], p))
    b = np.column_stack([s[:, 5], s[:, 6], 1.0 - s[:, 5] - s[:, 6]])
    assert (b >= -1e-12).all() and (b <= 1 + 1e-12).all()
    scale = np.abs(verts - p).max()
    on = b @ verts
    assert np.allclose(on, p + s[:, :3] * s[:, 3:4], atol=1e-9 * scale)
    pdf = pdf_emissive_batch(*t, np.zeros(len(s), np.int64), np.tile(p, (len(s), 1)), s[:, :3], s[:, 3])
    assert np.allclose(pdf, s[:, 4], rtol=1e-12, atol=0)
    lit = s[:, 7] > 0
    assert (s[lit, 4] > 0).all()


def test_the_cases_use_both_samplers():
    used = {name: omega_at(*tables(np.asarray(v, float))[:3], np.array(p)) > 0 for name, (v, p) in CASES.items()
}
    assert used["above"] and used["huge (1e6)"] and used["far from the origin (1e7)"] and used["tiny (1e-8) and near"]
    assert not used["in the plane, outside"] and not used["tiny (1e-8) and far"]
