"""Emissive triangles sampled by solid angle (lights.spherical_triangle through
lights.triangles.sample_triangle): the density MIS is told equals the one sampled, the estimate
of irradiance equals the closed form, the map keeps stratified samples stratified, and near a
large emitter the noise falls against area sampling."""
from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from drt_engine.core.lights.emitter_tree import emitter_tree
from drt_engine.core.lights.spherical_triangle import MIN_SOLID_ANGLE, subtended
from drt_engine.core.lights.triangles import pdf_emissive_batch, sample_triangle, unoccluded_triangles_batch

TRIANGLE = np.array([[0.0, 0.0, 1.0], [2.0, 0.0, 1.5], [0.0, 1.5, 2.0]])


def tables(verts):
    """(vertices, triangles, ng, area, tree, rank) of one emissive triangle, as lights.collection keeps them."""
    e = np.cross(verts[1] - verts[0], verts[2] - verts[0])
    norm = np.linalg.norm(e)
    tree, _, rank = emitter_tree(np.asarray(verts, np.float64)[None], np.array([1.0]))
    return (np.ascontiguousarray(verts, np.float64), np.array([[0, 1, 2]], np.int64), (e / norm)[None],
            np.array([0.5 * norm]), tree, rank)


@numba.njit
def samples(verts, tris, ng, area, tree, rank, p, u):
    """sample_triangle's (wx, wy, wz, dist, pdf, b0, b1, cos_l) for each row of u (the one
    triangle picked for sure)."""
    out = np.zeros((len(u), 8))
    for j in range(len(u)):
        r = sample_triangle(verts, tris, ng, area, 1.0, 0, p[0], p[1], p[2], u[j, 0], u[j, 1])
        for k in range(8):
            out[j, k] = r[k]
    return out


@numba.njit
def omega_at(verts, tris, ng, p):
    return subtended(verts, tris[0, 0], tris[0, 1], tris[0, 2], ng[0, 0], ng[0, 1], ng[0, 2], p[0], p[1], p[2])


def stratified(side, rng):
    g = np.stack(np.meshgrid(np.arange(side), np.arange(side), indexing="ij"), -1).reshape(-1, 2)
    return (g + rng.random(g.shape)) / side


def irradiance(t, p, n, u):
    """Per sample: cos+ about n / pdf where the triangle is seen (emission 1)."""
    s = samples(*t, np.asarray(p, float), u)
    return np.maximum(s[:, :3] @ n, 0.0) / s[:, 4] * (s[:, 7] > 0)


NEAR = [(0.3, 0.2, 0.0), (0.5, 0.5, 1.2), (0.6, 0.4, 1.4)]
"""Points below, between the corners' heights and just off the plane of TRIANGLE: solid-angle sampled."""


@pytest.mark.parametrize("p", NEAR + [(10.0, 10.0, 0.0)], ids=["below", "beside", "close", "far (area)"])
def test_sampled_points_have_the_pdf_mis_is_told(p):
    t = tables(TRIANGLE)
    p = np.array(p)
    s = samples(*t, p, np.random.default_rng(1).random((500, 2)))
    assert (omega_at(t[0], t[1], t[2], p) > 0) == (np.linalg.norm(p) < 5)
    pdf = pdf_emissive_batch(*t, np.zeros(len(s), np.int64), np.tile(p, (len(s), 1)), s[:, :3], s[:, 3])
    assert np.allclose(pdf, s[:, 4], rtol=1e-12)
    # the sampled points lie on the triangle at the direction and distance returned
    b = np.column_stack([s[:, 5], s[:, 6], 1.0 - s[:, 5] - s[:, 6]])
    assert (b >= -1e-12).all()
    assert np.allclose(b @ TRIANGLE, p + s[:, :3] * s[:, 3:4], atol=1e-9)


@pytest.mark.parametrize("p", NEAR)
@pytest.mark.parametrize("n", [(0.0, 0.0, 1.0), (0.6, -0.3, 0.7)], ids=["up", "tilted"])
def test_estimate_of_irradiance_is_the_closed_form(p, n):
    t = tables(TRIANGLE)
    n = np.array(n) / np.linalg.norm(n)
    want = np.zeros((1, 3))
    unoccluded_triangles_batch(t[0], t[1], np.ones((1, 3)), np.array([0], np.int64), np.array([p], float), n[None], want)
    rng = np.random.default_rng(2)
    means = np.array([irradiance(t, p, n, rng.random((4096, 2))).mean() for _ in range(16)])
    err = means.std(ddof=1) / math.sqrt(len(means))
    assert abs(means.mean() - want[0, 0]) <= 5 * err + 1e-12 * want[0, 0], (means.mean(), want[0, 0], err)


def test_uniform_over_the_solid_angle():
    """Equal parts of the unit square land on equal solid angles: a chi-square over an 8 x 8
    grid of the square's cells, each cell's directions' solid angle measured by counting where
    iid samples of the whole triangle fall."""
    t = tables(TRIANGLE)
    p = np.array(NEAR[0])
    s = samples(*t, p, np.random.default_rng(3).random((200_000, 2)))
    assert np.ptp(s[:, 4]) == 0.0  # the pdf is 1 / omega everywhere
    # directions' distribution: split by the plane through p, corner 0 and the triangle's centroid
    centre = TRIANGLE.mean(axis=0) - p
    normal = np.cross(TRIANGLE[0] - p, centre)
    side = s[:, :3] @ normal > 0
    # the same split of the closed-form solid angle: the sub-triangle (0, 1, midpoint of 1-2)
    m = 0.5 * (TRIANGLE[1] + TRIANGLE[2])
    half = tables(np.array([TRIANGLE[0], TRIANGLE[1], m]))
    share = omega_at(half[0], half[1], half[2], p) / omega_at(t[0], t[1], t[2], p)
    hits = side.mean() if (TRIANGLE[1] - p) @ normal > 0 else 1 - side.mean()
    assert abs(hits - share) < 5 * math.sqrt(share * (1 - share) / len(s)), (hits, share)


def test_the_map_keeps_stratified_samples_stratified():
    """Arvo's map is continuous: stratified samples' estimate is far less noisy than iid ones'
    (a map that tore the square apart would lose that)."""
    t = tables(TRIANGLE)
    p, n = np.array(NEAR[0]), np.array([0.0, 0.0, 1.0])
    rng = np.random.default_rng(4)
    strat = [irradiance(t, p, n, stratified(32, rng)).mean() for _ in range(24)]
    iid = [irradiance(t, p, n, rng.random((1024, 2))).mean() for _ in range(24)]
    assert np.std(strat) < 0.2 * np.std(iid), (np.std(strat), np.std(iid))
    assert largest_step(t, p, 256) < 0.5 * largest_step(t, p, 32)  # no tear: steps shrink with the grid's


def largest_step(t, p, side):
    """The largest distance between the directions of neighbours on a (side + 1)^2 grid of the
    square (Arvo's map goes as sqrt(u1) near corner b: steps shrink as 1/sqrt(side) there)."""
    grid = np.stack(np.meshgrid(np.arange(side + 1), np.arange(side + 1), indexing="ij"), -1).reshape(-1, 2) / side
    d = samples(*t, p, grid)[:, :3].reshape(side + 1, side + 1, 3)
    return max(np.linalg.norm(np.diff(d, axis=0), axis=-1).max(), np.linalg.norm(np.diff(d, axis=1), axis=-1).max())


def test_near_a_large_emitter_the_noise_falls_against_area_sampling():
    t = tables(TRIANGLE)
    p, n = np.array(NEAR[0]), np.array([0.0, 0.0, 1.0])
    u = np.random.default_rng(5).random((20000, 2))
    solid = irradiance(t, p, n, u)
    su = np.sqrt(u[:, 0])
    b = np.column_stack([1 - su, u[:, 1] * su, su * (1 - u[:, 1])])
    d = b @ TRIANGLE - p
    r = np.linalg.norm(d, axis=1)
    area = np.maximum(d @ n, 0) / r * np.abs(d / r[:, None] @ t[2][0]) / r ** 2 * t[3][0]
    assert abs(area.mean() - solid.mean()) < 0.02 * solid.mean()
    assert solid.std() < 0.5 * area.std(), (solid.std(), area.std())


def test_tiny_solid_angles_fall_back_to_area_sampling():
    t = tables(TRIANGLE * 1e-4)
    assert omega_at(t[0], t[1], t[2], np.array([3e-5, 2e-5, 0.0])) > MIN_SOLID_ANGLE
    assert omega_at(t[0], t[1], t[2], np.array([3e-5, 2e-5, -0.05])) == 0.0
