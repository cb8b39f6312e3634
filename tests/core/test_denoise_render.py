"""A render with ``use_denoising``: Combined denoised, the image as traced kept as Noisy Image, and
the denoised image's error estimated from the film's two replicate halves (core.render.denoise).

The scene is the soft-shadow scene (a sphere and a cube under a rectangular area light, 48x36
pixels): its error sits in the penumbrae, where OIDN has real work to do. The reference is a
512-sample render of another seed, its own variance taken off the true errors.
"""
import numpy as np
import pytest

from drt_engine.core.errors import SettingsError
from drt_engine.core.film import denoiser
from drt_engine.core.render.adaptive import true_error
from drt_engine.core.render.denoise import denoised_error
from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import NOISY_IMAGE, RenderSettings
from tests.support.oidn import require_oidn
from tests.support.scenes import soft_shadow_scene

WIDTH, SPP, REFERENCE_SPP = 48, 8, 512
ESTIMATE_FACTOR = 2.0
"""The denoised error estimate is within this factor of the true error (issue 25's target). Measured
here at 8 spp: 0.68 of it (at 64x48: 0.59 at 4 spp, 0.74 at 16, 0.95 at 64; it reads low, more so
at fewer samples: the bias of blurred detail is not in it, and OIDN smooths a noisier half harder)."""
DENOISED_GAIN = 0.65
"""The denoised image's true relMSE is under this fraction of the noisy one's (measured 0.48 at 8 spp;
this small scene's penumbrae and edges leave OIDN less to gain than a larger image would)."""


@pytest.fixture(scope="module")
def oidn():
    return denoiser.load(require_oidn())


def render(oidn=None, samples=SPP, seed=1, **kw):
    scene, base = soft_shadow_scene(WIDTH)
    settings = RenderSettings(**{**base, "samples": samples, "seed": seed, "passes": ("Combined", "Noise"), **kw})
    return Renderer(scene, settings, denoiser=oidn).render()


@pytest.fixture(scope="module")
def reference():
    result = render(samples=REFERENCE_SPP, seed=7)
    return result.passes["Combined"][..., :3], result.passes["Noise"] ** 2


@pytest.fixture(scope="module")
def pair(oidn):
    return render(oidn, use_denoising=True), render()


def test_noisy_image_is_the_render_without_denoising(pair):
    denoised, plain = pair
    np.testing.assert_array_equal(denoised.passes[NOISY_IMAGE], plain.passes["Combined"])
    np.testing.assert_array_equal(denoised.passes["Noise"], plain.passes["Noise"])
    assert denoised.stats["relmse"] == plain.stats["relmse"]  # the noisy estimate is unchanged
    combined = denoised.passes["Combined"]
    assert not np.array_equal(combined[..., :3], plain.passes["Combined"][..., :3])
    np.testing.assert_array_equal(combined[..., 3], plain.passes["Combined"][..., 3])  # alpha as rendered
    assert np.isfinite(combined).all()


def test_features_are_traced_for_the_denoiser_but_written_only_when_asked(oidn, pair):
    denoised, _ = pair
    assert set(denoised.passes) == {"Combined", "Noise", NOISY_IMAGE}
    asked = render(oidn, samples=2, use_denoising=True,
                   passes=("Combined", "Denoising Albedo", "Denoising Normal"))
    assert set(asked.passes) == {"Combined", "Denoising Albedo", "Denoising Normal", NOISY_IMAGE}


def test_denoised_is_closer_to_the_reference_and_its_estimate_is_calibrated(pair, reference):
    denoised, plain = pair
    ref, ref_var = reference
    noisy_true = true_error(plain.passes["Combined"][..., :3], ref, ref_var)[1]
    denoised_true = true_error(denoised.passes["Combined"][..., :3], ref, ref_var)[1]
    estimate = denoised.stats["relmse_denoised"]
    print(f"{SPP} spp relMSE: noisy {noisy_true:.3g} (est. {plain.stats['relmse']:.3g}), "
          f"denoised {denoised_true:.3g} (est. {estimate:.3g})")
    assert denoised_true < DENOISED_GAIN * noisy_true
    assert 1 / ESTIMATE_FACTOR < estimate / denoised_true < ESTIMATE_FACTOR
    assert denoised.log[-1]["relmse_denoised"] == estimate  # in the log beside the noisy estimate
    assert denoised.stats["denoising"]["prefilter"] == "ACCURATE"


def test_the_estimate_is_the_halves_difference():
    """Equal halves of 4 samples each: the full image's variance is (A - B)^2 / 4 per channel."""
    full = np.full((2, 2, 3), 0.5)
    a, b = full + 0.1, full - 0.1
    n, na = np.full(4, 8.0), np.full(4, 4.0)
    rmse, relmse = denoised_error(full, a, b, n, na)
    assert rmse == pytest.approx(0.1)
    assert relmse == pytest.approx(0.01 / (0.25 - 0.01 + 0.01))
    assert denoised_error(full, a, b, n, np.array([4.0, 4, 4, 0]))[1] == np.inf  # a pixel without half B


def test_denoising_without_a_library_is_a_settings_error():
    scene, base = soft_shadow_scene(8)
    with pytest.raises(SettingsError, match="OpenImageDenoise"):
        Renderer(scene, RenderSettings(**base, samples=2, use_denoising=True))


def test_a_farm_part_is_not_denoised(oidn):
    part = render(oidn, samples=4, use_denoising=True, sample_start=0, sample_end=2)
    assert NOISY_IMAGE not in part.passes and "relmse_denoised" not in part.stats
    assert any("not denoised" in w for w in part.warnings)
