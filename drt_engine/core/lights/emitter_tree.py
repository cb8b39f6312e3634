"""Emissive triangles chosen per shading point down a binary tree, each branch by its power over
its squared distance: Cycles' light tree, with bounding spheres and no orientation cones.

Chosen by power alone, the triangles of an emissive object close to a surface are taken as often
from its far side, which the object hides and which lies further away, as from the side facing the
surface. The tree holds the triangles in the order of a Morton curve through their centroids, a
complete binary tree over it (heap order: node h's children are 2h and 2h + 1, the leaves, one
triangle each, from ``size``), each node the centre and squared radius of a sphere around its
triangles' corners and their power. A branch's weight is never 0 while it holds power (its squared
distance is at least its squared radius), so every triangle keeps a chance wherever it could
light a point, and ``leaf_chance`` walks the same branches to give a BSDF ray the density sampled.
Emission is two-sided: no branch is left out for facing away.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel

CX, CY, CZ, RADIUS2, POWER = range(5)
"""Columns of a node row: its sphere's centre and squared radius, its triangles' power."""
BELOW_ONE = 1.0 - 2.0 ** -53
"""The largest random number below 1: a walk's number stays in [0, 1) as it is rescaled."""


def emitter_tree(corners: np.ndarray, power: np.ndarray):
    """(tree, order, rank) for emissive triangles with world ``corners`` (n, 3, 3) and ``power``
    (> 0): ``tree`` (2 size, 5) in heap order, row 0 unused, leaf ``size + k`` the triangle
    ``order[k]`` (empty leaves past n hold no power); ``rank`` each triangle's k."""
    n = len(power)
    size = 1 << max(n - 1, 0).bit_length()
    order = np.argsort(_morton(corners.mean(axis=1)), kind="stable") if n > 1 else np.arange(n)
    low, high = np.zeros((2 * size, 3)), np.zeros((2 * size, 3))
    tree = np.zeros((2 * size, 5))
    leaves = slice(size, size + n)
    low[leaves], high[leaves] = corners[order].min(axis=1), corners[order].max(axis=1)
    tree[leaves, POWER] = power[order]
    empty = np.ones(2 * size, bool)
    empty[leaves] = False
    level = size
    while level > 1:  # each parent from its two children, a level at a time
        parents = np.arange(level // 2, level)
        left, right = 2 * parents, 2 * parents + 1
        both = ~empty[left] & ~empty[right]
        low[parents] = np.where(both[:, None], np.minimum(low[left], low[right]), np.where(empty[left, None],
                                                                                            low[right], low[left]))
        high[parents] = np.where(both[:, None], np.maximum(high[left], high[right]), np.where(empty[left, None],
                                                                                               high[right], high[left]))
        tree[parents, POWER] = tree[left, POWER] + tree[right, POWER]
        empty[parents] = empty[left] & empty[right]
        level //= 2
    tree[:, :3] = 0.5 * (low + high)
    tree[:, RADIUS2] = (0.25 * (high - low) ** 2).sum(axis=1)
    rank = np.empty(n, np.int64)
    rank[order] = np.arange(n)
    return tree, order.astype(np.int64), rank


def _morton(points: np.ndarray) -> np.ndarray:
    """30-bit Morton codes of ``points`` in their bounding box (10 bits per axis)."""
    low, high = points.min(axis=0), points.max(axis=0)
    cells = ((points - low) / np.maximum(high - low, 1e-300) * 1023.0).astype(np.int64).clip(0, 1023)
    code = np.zeros(len(points), np.int64)
    for bit in range(10):
        for axis in range(3):
            code |= ((cells[:, axis] >> bit) & 1) << (3 * bit + axis)
    return code


@kernel(inline="always")
def _weight(tree, h, px, py, pz):
    dx, dy, dz = px - tree[h, CX], py - tree[h, CY], pz - tree[h, CZ]
    return tree[h, POWER] / max(dx * dx + dy * dy + dz * dz, tree[h, RADIUS2], 1e-300)


@kernel(inline="always")
def pick_emitter(tree, px, py, pz, u):
    """(k, chance): the leaf k (``order[k]`` the triangle) a walk down ``tree`` takes from p with
    the random number u, and the chance of that walk."""
    size = len(tree) // 2
    h, chance = 1, 1.0
    while h < size:
        wl, wr = _weight(tree, 2 * h, px, py, pz), _weight(tree, 2 * h + 1, px, py, pz)
        p = wl / (wl + wr)
        if u < p or wr == 0.0:
            h, u, chance = 2 * h, min(u / p, BELOW_ONE), chance * p
        else:
            h, u, chance = 2 * h + 1, min((u - p) / (1.0 - p), BELOW_ONE), chance * (1.0 - p)
    return h - size, chance


@kernel(inline="always")
def leaf_chance(tree, k, px, py, pz):
    """The chance ``pick_emitter`` takes leaf k from p."""
    size = len(tree) // 2
    h, out, depth = 1, 1.0, 0
    while (1 << depth) < size:
        depth += 1
    for level in range(depth - 1, -1, -1):
        side = (k >> level) & 1
        wl, wr = _weight(tree, 2 * h, px, py, pz), _weight(tree, 2 * h + 1, px, py, pz)
        out *= (wr if side else wl) / (wl + wr)
        h = 2 * h + side
    return out
