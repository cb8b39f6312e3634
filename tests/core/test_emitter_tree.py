"""The emissive triangles' tree (lights.emitter_tree): the walk's chance is the one a BSDF ray is
told, the chances at any point sum to 1 and none is 0, a triangle's chance does not depend on the
order the mesh lists its faces in, and near an emissive sphere the irradiance estimate keeps its
mean and loses most of its variance against choosing triangles by power alone."""
from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from drt_engine.core.lights.emitter_tree import emitter_tree, leaf_chance, pick_emitter
from drt_engine.core.lights.triangles import sample_triangle, unoccluded_triangles_batch


def _soup(n, seed=0, scale=1.0, offset=0.0):
    rng = np.random.default_rng(seed)
    corners = rng.random((n, 3, 3)) * 5.0 * scale + offset
    return corners, rng.random(n) + 0.01


def _chances(tree, rank, p):
    return np.array([leaf_chance(tree, rank[i], *p) for i in range(len(rank))])


@pytest.mark.parametrize("n", [1, 2, 3, 16, 17, 100])
def test_the_walk_takes_each_triangle_with_the_chance_it_reports(n):
    corners, power = _soup(n)
    tree, order, rank = emitter_tree(corners, power)
    p = np.array([0.3, -2.0, 1.0])
    chances = _chances(tree, rank, p)
    assert abs(chances.sum() - 1.0) < 1e-12 and (chances > 0).all()
    counts = np.zeros(n)
    for u in (np.arange(20_000) + 0.5) / 20_000:
        leaf, chance = pick_emitter(tree, *p, u)
        assert leaf < n and chance == pytest.approx(chances[order[leaf]], rel=1e-12)
        counts[order[leaf]] += 1
    assert np.abs(counts / counts.sum() - chances).max() < 2e-4  # stratified numbers: each share within its rounding


@pytest.mark.parametrize("scale, offset", [(1.0, 0.0), (1e-8, 0.0), (1e6, 0.0), (1.0, 1e7)],
                         ids=["unit", "tiny", "huge", "far from the origin"])
def test_every_triangle_keeps_a_chance_everywhere(scale, offset):
    corners, power = _soup(300, 1, scale, offset)
    tree, _, rank = emitter_tree(corners, power)
    centre = corners.reshape(-1, 3).mean(axis=0)
    for p in (centre, corners[7, 0], centre + 1e3 * scale, centre - 1e-3 * scale):
        chances = _chances(tree, rank, p)
        assert np.isfinite(chances).all() and (chances > 0).all() and abs(chances.sum() - 1.0) < 1e-9
    assert pick_emitter(tree, *centre, 0.0)[0] < 300 and pick_emitter(tree, *centre, 1.0 - 2.0 ** -53)[0] < 300


def test_a_triangles_chance_does_not_depend_on_the_order_of_the_faces():
    corners, power = _soup(200, 2)
    tree, _, rank = emitter_tree(corners, power)
    shuffle = np.random.default_rng(3).permutation(200)
    tree2, _, rank2 = emitter_tree(corners[shuffle], power[shuffle])
    p = np.array([1.0, 2.0, -3.0])
    assert np.array_equal(_chances(tree, rank, p)[shuffle], _chances(tree2, rank2, p))


def _sphere(segments=32, rings=16, radius=0.25, centre=(0.0, 0.0, 0.6)):
    """A UV sphere's triangles (corners, outward normals, areas)."""
    theta, phi = np.linspace(0, np.pi, rings + 1), np.linspace(0, 2 * np.pi, segments + 1)
    grid = np.stack([np.sin(theta)[:, None] * np.cos(phi), np.sin(theta)[:, None] * np.sin(phi),
                     np.cos(theta)[:, None] * np.ones_like(phi)], axis=-1) * radius + np.array(centre)
    quads = [(grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]) for i in range(rings)
             for j in range(segments)]
    tris = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    e = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    keep = np.linalg.norm(e, axis=1) > 1e-12  # the poles' slivers
    return tris[keep], e[keep] / np.linalg.norm(e[keep], axis=1)[:, None], 0.5 * np.linalg.norm(e[keep], axis=1)


@numba.njit
def _irradiance(vertices, triangles, ng, area, tree, order, cdf, power_share, p, n, u, u_pick, by_tree):
    """Per sample, the unoccluded irradiance at p about n from one emissive triangle sample of
    emission 1: the triangle taken down the tree, or by power alone (``cdf``)."""
    out = np.zeros(len(u))
    for j in range(len(u)):
        if by_tree:
            leaf, chance = pick_emitter(tree, p[0], p[1], p[2], u_pick[j])
            i = order[leaf]
        else:
            i = min(np.searchsorted(cdf, u_pick[j], side="right"), len(cdf) - 1)
            chance = power_share[i]
        wx, wy, wz, _, pdf, _, _, cos_l = sample_triangle(vertices, triangles, ng, area, chance, i, p[0], p[1], p[2],
                                                          u[j, 0], u[j, 1])
        if cos_l > 0 and pdf > 0:
            out[j] = max(wx * n[0] + wy * n[1] + wz * n[2], 0.0) / pdf
    return out


def test_near_an_emissive_sphere_the_estimate_keeps_its_mean_and_sheds_variance():
    """A floor point under an emissive sphere of 0.25 at height 0.6 (the IES parity scene's): the
    tree favours the near side, unoccluded here as the closed form counts it."""
    tris, ng, area = _sphere()
    vertices = np.ascontiguousarray(tris.reshape(-1, 3))
    triangles = np.arange(len(vertices), dtype=np.int64).reshape(-1, 3)
    tree, order, _ = emitter_tree(tris, area)
    share = area / area.sum()
    p, n = np.array([0.4, 0.1, 0.0]), np.array([0.0, 0.0, 1.0])
    want = np.zeros((1, 3))
    unoccluded_triangles_batch(vertices, triangles, np.ones((len(tris), 3)), np.arange(len(tris), dtype=np.int64),
                               p[None], n[None], want)
    rng = np.random.default_rng(4)
    u, u_pick = rng.random((200_000, 2)), rng.random(200_000)
    by_tree, by_power = (_irradiance(vertices, triangles, ng, area, tree, order, np.cumsum(share), share, p, n, u,
                                     u_pick, flag) for flag in (True, False))
    for est in (by_tree, by_power):
        assert abs(est.mean() - want[0, 0]) < 5 * est.std() / math.sqrt(len(est)), (est.mean(), want[0, 0])
    print("variance, tree / power alone:", by_tree.var() / by_power.var())
    assert by_tree.var() < 0.7 * by_power.var()
