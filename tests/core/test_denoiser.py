"""The OpenImageDenoise binding (core.film.denoiser) on synthetic images whose clean version is known.

A smooth gradient times exponential noise per pixel (relative standard error 1, as a few samples
of a rare bright path give) is what OIDN is trained to remove; the clean gradient itself is what
it must leave alone.
"""
from pathlib import Path

import numpy as np
import pytest

from drt_engine.core.errors import DenoiserError, DRTError
from drt_engine.core.film import denoiser
from tests.support.oidn import require_oidn

H = W = 96


def relmse(image, reference):
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 1e-2)))


def gradient():
    y, x = np.mgrid[0:H, 0:W] / float(H)
    return np.stack([0.2 + 0.6 * x, 0.3 + 0.3 * y, 0.5 + 0.0 * x], -1)


def features():
    return np.full((H, W, 3), 0.8), np.broadcast_to([0.0, 0.0, 1.0], (H, W, 3))


@pytest.fixture(scope="module")
def oidn():
    return denoiser.load(require_oidn())


@pytest.mark.parametrize("prefilter", denoiser.PREFILTERS)
def test_noisy_image_comes_far_closer_to_its_clean_version(oidn, prefilter):
    clean = gradient()
    noisy = clean * np.random.default_rng(3).exponential(1.0, (H, W, 1))
    albedo, normal = features()
    out = oidn.denoise(noisy, albedo, normal, prefilter=prefilter)
    assert out.shape == (H, W, 3) and out.dtype == np.float32 and np.isfinite(out).all()
    before, after = relmse(noisy, clean), relmse(out, clean)
    assert after < before / 100, (before, after)  # measured: 0.95 -> 6e-4 to 9e-4


def test_a_clean_image_stays_nearly_as_it_was(oidn):
    clean = gradient()
    out = oidn.denoise(clean, *features())
    assert relmse(out, clean) < 1e-4  # measured 4e-6


def test_colour_alone_and_rgba_input(oidn):
    """Without features, and from an RGBA pass (its alpha ignored)."""
    clean = gradient()
    noisy = np.concatenate([clean * np.random.default_rng(4).exponential(1.0, (H, W, 1)), np.ones((H, W, 1))], -1)
    assert relmse(oidn.denoise(noisy), clean) < relmse(noisy[..., :3], clean) / 30


def test_filters_kept_over_calls_give_what_fresh_filters_give(oidn):
    """A render's or the viewport's Filters set each filter up once and copy new images into its
    buffers: every image, of either size, prefiltered or not, comes out as a one-off call makes it."""
    rng = np.random.default_rng(5)
    albedo, normal = features()
    calls = [(gradient() * rng.exponential(1.0, (H, W, 1)), albedo, normal, prefilter, "HIGH")
             for prefilter in ("ACCURATE", "NONE", "ACCURATE")]
    calls.append((rng.exponential(1.0, (H // 2, W, 3)), None, None, "NONE", "BALANCED"))
    calls.append((gradient() * rng.exponential(1.0, (H, W, 1)), albedo, normal, "ACCURATE", "HIGH"))
    with oidn.filters() as filters:
        kept = [filters.denoise(*call) for call in calls]
        assert len(filters._kept) == 4  # albedo, normal, the guided image, the image alone
    for call, image in zip(calls, kept):
        assert np.array_equal(image, oidn.denoise(*call))
    assert not filters._kept  # released on leaving the block


def test_quality_values_are_oidns(oidn):
    """OIDN reads back the value each quality name sets (oidn.h: FAST 4, BALANCED 5, HIGH 6)."""
    assert {q: oidn.filter_quality(q) for q in denoiser.QUALITIES} == {"FAST": 4, "BALANCED": 5, "HIGH": 6}
    from drt_engine.core.settings import DENOISING_QUALITIES

    assert set(denoiser.QUALITIES) == set(DENOISING_QUALITIES)


def test_a_missing_library_is_one_line_drt_error(tmp_path):
    with pytest.raises(DenoiserError) as info:
        denoiser.Denoiser(tmp_path / "libOpenImageDenoise.so.2")
    assert isinstance(info.value, DRTError)
    assert "not found" in str(info.value) and "\n" not in str(info.value)


def test_a_library_that_is_not_oidn_is_a_drt_error(tmp_path):
    libm = next((p for p in ("/lib/x86_64-linux-gnu/libm.so.6", "/usr/lib64/libm.so.6", "/usr/lib/libm.so.6")
                 if Path(p).is_file()), None)
    if libm is not None:
        with pytest.raises(DenoiserError, match="not an OpenImageDenoise 2 library"):
            denoiser.Denoiser(libm)
    bogus = tmp_path / "libOpenImageDenoise.so.2"
    bogus.write_bytes(b"not a library")
    with pytest.raises(DenoiserError, match="cannot be loaded"):
        denoiser.Denoiser(bogus)


def test_bad_arguments_are_drt_errors(oidn):
    with pytest.raises(DenoiserError, match="prefilter"):
        oidn.denoise(gradient(), prefilter="SOMETIMES")
    with pytest.raises(DenoiserError, match="differs"):
        oidn.denoise(gradient(), np.zeros((4, 4, 3)))
