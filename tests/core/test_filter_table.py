"""The pixel filter's fast table lookup is linear interpolation of its inverse CDF, exactly."""
import numpy as np
import pytest

from drt_engine.core.film.film import PixelFilter


@pytest.mark.parametrize("kind", ["BOX", "GAUSSIAN", "BLACKMAN_HARRIS"])
@pytest.mark.parametrize("width", [0.5, 1.5, 4.0])
def test_offset_equals_np_interp_of_the_table(kind, width):
    f = PixelFilter(kind, width)
    rng = np.random.default_rng(11)
    u = np.concatenate([np.arange(1 << 20) / (1 << 20), rng.random(1 << 18), f._cdf[:-1],
                        np.nextafter(f._cdf[1:], 0.0), [0.0, 1.0 - 2.0**-53]])
    assert np.array_equal(f.offset(u), np.interp(u, f._cdf, f._x))
