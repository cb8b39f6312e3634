"""Procedural textures (core.shading.proctex) against values derived by hand or by a reference.

The hashes are checked against Bob Jenkins' lookup3.c ``hashword`` (initval 13, which
Cycles' hash_uint{,2,3,4} specialise) and against the PCG3D of "Hash Functions for GPU
Rendering" on signed ints, both compiled with gcc from their published C (the constants
below). Voronoi with randomness 0 puts every feature point on the integer lattice, where
F1, F2, distance to edge and the n-sphere radius have closed forms for each metric.
"""
from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from drt_engine.core.shading import proctex
from drt_engine.core.shading.proctex import hash as h
from drt_engine.core.shading.proctex.noise import snoise

N = 400


def _f(v, n=N):
    return np.full(n, float(v))


@pytest.fixture
def points():
    rng = np.random.default_rng(7)
    return rng.uniform(-4.0, 4.0, (N, 3)), rng.uniform(-4.0, 4.0, N)


def test_lookup3_matches_the_reference_c():
    assert h.hash_uint(0) == 2501500005
    assert h.hash_uint2(1, 2) == 272092061
    assert h.hash_uint3(1, 2, 3) == 3100736010
    assert h.hash_uint4(1, 2, 3, 4) == 92593857
    assert h.hash_uint4(-7, -3, 12, -1) == 1828441636  # negative cells wrap to 32 bits
    assert h.hash_f3(1.5, -2.0, 0.25) == pytest.approx(0.829849958, abs=1e-9)


def test_float_bits_are_ieee_float32():
    values = [0.0, -0.0, 1.0, -1.5, 3.1e-40, -1e-45, 123.456, 1e30, -2.0 ** -126, math.inf]
    values += list(np.random.default_rng(1).normal(0, 100, 50))
    for v in values:
        assert h.float_bits(v) == struct.unpack("<I", struct.pack("<f", v))[0], v


def test_pcg3_matches_the_reference_c():
    assert h.pcg3(-3, 5, -1)[0] == float(np.float32(1052296081)) * 2.0 ** -31
    assert h.pcg3(7, -2, 0)[0] == float(np.float32(1062343289)) * 2.0 ** -31


def test_perlin_noise_vanishes_on_the_lattice_and_stays_in_range():
    for dims in (1, 2, 3, 4):
        assert snoise(dims, 3.0, -2.0, 5.0, 1.0) == 0.0
    rng = np.random.default_rng(3)
    values = [snoise(3, *rng.uniform(-50, 50, 3), 0.0) for _ in range(2000)]
    assert max(abs(v) for v in values) <= 1.0 and np.std(values) > 0.1


def test_perlin_1d_by_hand():
    # perlin_1d(0.5): gradients of cells 0 and 1 from their hashes, faded at 0.5 (fade = 0.5)
    def grad(cell, x):
        k = h.hash_uint(cell) & 15
        return (-1.0 if k & 8 else 1.0) * (1 + (k & 7)) * x
    expected = 0.25 * (grad(0, 0.5) + 0.5 * (grad(1, -0.5) - grad(0, 0.5)))
    assert snoise(1, 0.5, 0.0, 0.0, 0.0) == pytest.approx(expected, abs=1e-12)


def test_fbm_with_zero_roughness_is_one_octave(points):
    vector, w = points
    one, _ = proctex.evaluate("noise", {"type": "FBM", "dims": 3, "normalize": True, "color": False},
                              [vector, w, _f(1), _f(0), _f(0.5), _f(2), _f(0), _f(1), _f(0)])
    many, _ = proctex.evaluate("noise", {"type": "FBM", "dims": 3, "normalize": True, "color": False},
                               [vector, w, _f(1), _f(6), _f(0), _f(2), _f(0), _f(1), _f(0)])
    direct = np.array([0.5 * snoise(3, *p, 0.0) + 0.5 for p in vector])
    np.testing.assert_allclose(one, direct, atol=1e-12)
    np.testing.assert_allclose(many, direct, atol=1e-12)


def _voronoi(feature, metric, dims, vector, w, exponent=1.0):
    return proctex.evaluate("voronoi", {"dims": dims, "feature": feature, "metric": metric, "normalize": False},
                            [vector, w, _f(1), _f(0), _f(0.5), _f(2), _f(1), _f(exponent), _f(0)])


@pytest.mark.parametrize("metric", ["EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI"])
def test_voronoi_on_the_lattice(points, metric):
    vector, w = points
    d = np.abs(vector - np.round(vector))
    expected = {"EUCLIDEAN": np.sqrt((d * d).sum(1)), "MANHATTAN": d.sum(1), "CHEBYCHEV": d.max(1),
                "MINKOWSKI": (d ** 3).sum(1) ** (1 / 3)}[metric]
    distance, _, position, _, _ = _voronoi("F1", metric, 3, vector, w, exponent=3.0)
    np.testing.assert_allclose(distance, expected, atol=1e-9)
    np.testing.assert_array_equal(position, np.round(vector))


def test_voronoi_f2_edge_and_radius_on_the_lattice(points):
    vector, w = points
    d = np.abs(vector - np.round(vector))
    # second nearest lattice point: step the axis closest to its cell's middle across
    f2 = np.sqrt((d * d).sum(1) - (d * d).max(1) + (1 - d.max(1)) ** 2)
    np.testing.assert_allclose(_voronoi("F2", "EUCLIDEAN", 3, vector, w)[0], f2, atol=1e-9)
    np.testing.assert_allclose(_voronoi("DISTANCE_TO_EDGE", "EUCLIDEAN", 3, vector, w)[0], 0.5 - d.max(1),
                               atol=1e-9)
    np.testing.assert_allclose(_voronoi("N_SPHERE_RADIUS", "EUCLIDEAN", 3, vector, w)[4], 0.5, atol=1e-12)
    d1 = np.abs(w - np.round(w))
    np.testing.assert_allclose(_voronoi("F1", "EUCLIDEAN", 1, vector, w)[0], d1, atol=1e-12)
    np.testing.assert_allclose(_voronoi("F1", "EUCLIDEAN", 1, vector, w)[3], np.round(w), atol=1e-12)


def test_voronoi_cell_colour_is_the_cell_hash(points):
    vector, w = points
    _, color, _, _, _ = proctex.evaluate(
        "voronoi", {"dims": 3, "feature": "F1", "metric": "EUCLIDEAN", "normalize": False},
        [vector, w, _f(1), _f(0), _f(0.5), _f(2), _f(1), _f(1), _f(0)])
    cells = np.round(vector).astype(int)
    np.testing.assert_array_equal(color, [h.pcg3(*c) for c in cells])


def test_gradient_types_by_hand():
    v = np.array([[0.25, 0.5, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, 0.0, 0.0]])
    fac = {kind: proctex.evaluate("gradient", {"type": kind}, [v])[1] for kind in
           ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "RADIAL", "SPHERICAL", "QUADRATIC_SPHERE")}
    np.testing.assert_allclose(fac["LINEAR"], [0.25, 0.0, 0.0, 0.6])
    np.testing.assert_allclose(fac["QUADRATIC"], [0.0625, 0.0, 0.0, 0.36])
    np.testing.assert_allclose(fac["EASING"][3], 3 * 0.36 - 2 * 0.216)
    np.testing.assert_allclose(fac["DIAGONAL"], [0.375, 0.0, 0.5, 0.3])
    np.testing.assert_allclose(fac["RADIAL"][2], 0.75)
    np.testing.assert_allclose(fac["SPHERICAL"][1:3], 0.0, atol=1e-12)  # unit vectors: exactly 0
    np.testing.assert_allclose(fac["QUADRATIC_SPHERE"][3], (0.999999 - 0.6) ** 2)


def test_wave_bands_sine_by_hand():
    v = np.array([[0.1, 0.7, -0.3]])
    fac = proctex.evaluate("wave", {"type": "BANDS", "bands": "X", "rings": "X", "profile": "SIN"},
                           [v, _f(2, 1), _f(0, 1), _f(2, 1), _f(1, 1), _f(0.5, 1), _f(0.3, 1)])[1]
    x = (0.1 * 2 + 0.000001) * 0.999999
    assert fac[0] == pytest.approx(0.5 + 0.5 * math.sin(20 * x + 0.3 - math.pi / 2), abs=1e-12)


def test_magic_depth_zero_by_hand():
    v = np.array([[0.3, -0.2, 0.5]])
    color, fac = proctex.evaluate("magic", {"depth": 0}, [v, _f(1, 1), _f(0, 1)])
    x, y, z = 0.3, -0.2, 0.5
    expected = [0.5 - math.sin((x + y + z) * 5), 0.5 - math.cos((-x + y - z) * 5), 0.5 + math.cos((-x - y + z) * 5)]
    np.testing.assert_allclose(color[0], expected, atol=1e-12)
    assert fac[0] == pytest.approx(np.mean(expected))


def test_white_noise_is_the_hash_of_the_float32_bits():
    v = np.array([[0.25, -1.5, 3.0]])
    value, color = proctex.evaluate("white_noise", {"dims": 3}, [v, _f(0.0, 1)])
    assert value[0] == h.hash_f3(0.25, -1.5, 3.0)
    assert tuple(color[0]) == h.hash_to_color(3, 0.25, -1.5, 3.0, 0.0)


def test_brick_mortar_and_tint_by_hand():
    c1, c2, mortar = np.array([[1.0, 0.0, 0.0]] * 2), np.array([[0.0, 1.0, 0.0]] * 2), np.zeros((2, 3))
    v = np.array([[0.0, 0.0, 0.0], [0.0, 0.125, 0.0]])  # a mortar corner, a brick's middle
    color, fac = proctex.evaluate("brick", {"offset": 0.5, "offset_frequency": 2, "squash": 1.0,
                                            "squash_frequency": 2},
                                  [v, c1, c2, mortar, _f(1, 2), _f(0.02, 2), _f(0, 2), _f(0, 2), _f(0.5, 2),
                                   _f(0.25, 2)])
    assert fac[0] == 1.0 and np.all(color[0] == 0.0)
    # row 0 is offset by half a brick, so x = 0 is the middle of its brick 0
    n = ((0 << 16) + (0 & 0xFFFF) + 1013) & 0x7FFFFFFF
    n = (n >> 13) ^ n
    nn = (n * ((n * n * 60493 + 19990303) & 0xFFFFFFFF) + 1376312589) & 0x7FFFFFFF
    tint = 0.5 * nn / 1073741824.0
    assert fac[1] == 0.0
    np.testing.assert_allclose(color[1], [1 - tint, tint, 0.0], atol=1e-12)


def test_box_weights_pick_a_face_and_blend_to_one():
    from drt_engine.core.shading.nodes import box_weights
    faces = np.array([[0.9, 0.1, 0.2], [-0.1, -0.8, 0.3], [0.2, 0.1, -0.7]])
    np.testing.assert_array_equal(box_weights(faces, 0.0), np.eye(3))
    centre = np.full((1, 3), 1 / np.sqrt(3))
    np.testing.assert_allclose(box_weights(centre, 0.5), [[1 / 3, 1 / 3, 1 / 3]])
    normals = np.random.default_rng(4).normal(size=(500, 3))
    for blend in (0.0, 0.2, 0.7, 1.0):
        w = box_weights(normals, blend)
        np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
        assert (w >= 0).all()
    # between the x and y faces (z small), blend 1: x's weight is |x| / (|x| + |y|) stretched over [0, 1]
    w = box_weights(np.array([[0.6, 0.4, 0.0]]), 1.0)
    np.testing.assert_allclose(w, [[0.6, 0.4, 0.0]])


def test_shader_programs_evaluate_the_texture_ops():
    """A program of coordinate -> Voronoi (as the export compiles a node) gives the kernel's values."""
    from drt_engine.core.scene import Program
    from drt_engine.core.shading.nodes import DirectionContext, Evaluator
    dirs = np.random.default_rng(8).normal(size=(50, 3))
    program = Program()
    coord = program.add("coord", name="generated")
    consts = [program.add("const", value=v) for v in (0.0, 4.0, 1.5, 0.5, 2.0, 1.0, 1.0, 0.8)]
    voronoi = program.add("voronoi", [(coord, 0)] + [(c, 0) for c in consts], dims=3, feature="F1",
                          metric="EUCLIDEAN", normalize=True)
    out = Evaluator(program, DirectionContext(dirs), [])((voronoi, 1))
    expected = proctex.evaluate("voronoi", {"dims": 3, "feature": "F1", "metric": "EUCLIDEAN", "normalize": True},
                                [dirs, *(np.full(50, v) for v in (0.0, 4.0, 1.5, 0.5, 2.0, 1.0, 1.0, 0.8))])[1]
    np.testing.assert_array_equal(out, expected)
    assert out.std() > 0.05


@pytest.mark.parametrize("dims", [2, 3])
def test_gabor_is_finite_and_in_range_for_extreme_inputs(dims):
    """Phase in [0, 1], intensity >= 0 and every output finite, far from the origin, at zero
    scale, frequency and orientation vector, and for out-of-range anisotropy."""
    from drt_engine.core.shading.proctex.gabor import gabor_texture
    rng = np.random.default_rng(5)
    n = 400
    vector = np.concatenate([rng.normal(size=(n - 4, 3)) * 3.0, [[1e7, -3e6, 2e5], [0, 0, 0], [-1e-30, 5, 7],
                                                                  [0.5, 0.5, 0.5]]])
    scale = np.where(np.arange(n) % 7 == 0, 0.0, 4.0)
    frequency = np.where(np.arange(n) % 5 == 0, 0.0, 2.0)
    anisotropy = rng.uniform(-0.5, 1.5, n)
    orientation = rng.uniform(-4, 4, n)
    direction = np.where((np.arange(n) % 3 == 0)[:, None], 0.0, rng.normal(size=(n, 3)))
    value, phase, intensity = gabor_texture(dims, vector, scale, frequency, anisotropy, orientation, direction)
    assert np.isfinite(value).all() and np.isfinite(phase).all() and np.isfinite(intensity).all()
    assert (phase >= 0).all() and (phase <= 1).all() and (intensity >= 0).all()
    assert value[scale > 0].std() > 0.01  # a pattern, not a constant
