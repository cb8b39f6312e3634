"""Sample values: stratification per pattern, determinism, decorrelation."""
import numpy as np
import pytest

from drt_engine.core.sampling.sampler import Sampler


def cells_hit(u, n):
    c = np.minimum((u * n).astype(int), n - 1)
    return len(np.unique(c[:, 0] * n + c[:, 1]))


@pytest.mark.parametrize("pattern", ["SOBOL", "JITTERED", "GRID"])
@pytest.mark.parametrize("dim", [0, 2, 10, 40])
def test_every_2d_pair_is_stratified(pattern, dim):
    s = Sampler(pattern, 64, seed=3)
    px = np.full(64, 1234)
    u = s.get2d(px, np.arange(64), dim)
    assert cells_hit(u, 8) == 64  # one sample in each of the 8x8 strata
    assert ((u >= 0) & (u < 1)).all()


def test_sobol_prefixes_are_stratified():
    s = Sampler("SOBOL", 256, seed=1)
    for n in (4, 16, 64):
        u = s.get2d(np.full(n, 7), np.arange(n), 6)
        k = int(np.sqrt(n))
        assert cells_hit(u, k) == n


def test_values_are_a_pure_function_of_their_arguments():
    a = Sampler("SOBOL", 16, seed=5).get(np.arange(100), np.arange(100) % 16, 9)
    b = Sampler("SOBOL", 16, seed=5).get(np.arange(100)[::-1], (np.arange(100) % 16)[::-1], 9)[::-1]
    assert np.array_equal(a, b)
    c = Sampler("SOBOL", 16, seed=6).get(np.arange(100), np.arange(100) % 16, 9)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("pattern", ["SOBOL", "JITTERED"])
def test_dimensions_and_pixels_are_decorrelated(pattern):
    s = Sampler(pattern, 16, seed=0)
    px = np.repeat(np.arange(2000), 16)
    sm = np.tile(np.arange(16), 2000)
    a, b = s.get(px, sm, 0), s.get(px, sm, 7)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.02
    # neighbouring pixels do not share their sample sets
    assert abs(np.corrcoef(s.get(px[:-16], sm[:-16], 4), s.get(px[16:], sm[16:], 4))[0, 1]) < 0.02
    assert abs(s.get(px, sm, 11).mean() - 0.5) < 0.005


def test_grid_rounds_up_to_a_square():
    assert Sampler("GRID", 10).samples == 16
    assert Sampler("JITTERED", 10).samples == 10
