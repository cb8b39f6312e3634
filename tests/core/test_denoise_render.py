"""A render with ``use_denoising``: Combined denoised, the image as traced kept as Noisy Image, and
the denoised image's error estimated from the film's two replicate halves (core.render.denoise).

The scene is the soft-shadow scene (a sphere and a cube under a rectangular area light, 48x36
pixels): its error sits in the penumbrae, where OIDN has real work to do. The reference is a
512-sample render of another seed, its own variance taken off the true errors.
"""
import math

import numpy as np
import pytest

from drt_engine.core.errors import SettingsError
from drt_engine.core.film import denoiser
from drt_engine.core.render.adaptive import true_error
from drt_engine.core.render.denoise import DENOISED_SHARE, Schedule, denoised_error
from drt_engine.core.render.driver import TARGET_MIN_SAMPLES
from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import NOISY_IMAGE, RenderSettings
from tests.support import split_render
from tests.support.oidn import require_oidn
from tests.support.scenes import defocused_checker_scene, soft_shadow_scene

WIDTH, SPP, REFERENCE_SPP = 48, 8, 512
ESTIMATE_FACTOR = 2.0
"""The denoised error estimate is within this factor of the true error (issue 25's target); measured
here: 0.91 of it (its noise part alone, the halves' denoised difference, 0.71; 0.86 and 0.68 when the halves
shared the features of all the samples)."""
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
    """Traced over all samples and per half (Film's ``halved``) when denoising; neither without it."""
    denoised, _ = pair
    assert set(denoised.passes) == {"Combined", "Noise", NOISY_IMAGE}
    scene, base = soft_shadow_scene(8)
    for use_denoising, halved in ((True, {"Denoising Albedo", "Denoising Normal"}), (False, set())):
        settings = RenderSettings(**base, samples=2, use_denoising=use_denoising)
        film = Renderer(scene, settings, denoiser=oidn).film
        assert set(film.sums_a) == halved and halved <= set(film.sums)
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
          f"denoised {denoised_true:.3g} (est. {estimate:.3g}, its noise part {denoised.stats['relmse_denoised_noise']:.3g})")
    assert denoised_true < DENOISED_GAIN * noisy_true
    assert 1 / ESTIMATE_FACTOR < estimate / denoised_true < ESTIMATE_FACTOR
    assert 0 < denoised.stats["relmse_denoised_noise"] <= estimate
    assert denoised.log[-1]["relmse_denoised"] == estimate  # in the log beside the noisy estimate
    assert denoised.stats["denoising"]["prefilter"] == "ACCURATE"


def render_checker(oidn, samples, seed, **kw):
    scene, base = defocused_checker_scene(64)
    settings = RenderSettings(**{**base, "samples": samples, "seed": seed, "passes": ("Combined", "Noise"), **kw})
    return Renderer(scene, settings, denoiser=oidn).render()


@pytest.fixture(scope="module")
def checker_reference():
    result = render_checker(None, REFERENCE_SPP, 7)
    return result.passes["Combined"][..., :3], result.passes["Noise"] ** 2


@pytest.mark.parametrize("seed", [1, 2])
def test_the_estimate_is_calibrated_where_defocus_makes_the_features_noisy(oidn, checker_reference, seed):
    """Depth of field (tests.support.scenes.defocused_checker_scene, 64x48, 16 samples): each half
    denoised with its own half's albedo and normal. With the features of all the samples shared by
    the three denoisings, the estimate read 0.02 of the true error here (their noise, correlated
    with both halves, cancelled in the halves' difference); with its own, 1.17 and 1.18."""
    ref, ref_var = checker_reference
    denoised = render_checker(oidn, 16, seed, use_denoising=True)
    true = true_error(denoised.passes["Combined"][..., :3], ref, ref_var)[1]
    noisy = true_error(denoised.passes[NOISY_IMAGE][..., :3], ref, ref_var)[1]
    estimate = denoised.stats["relmse_denoised"]
    print(f"seed {seed}: denoised relMSE {true:.3g} (noisy {noisy:.3g}), estimated {estimate:.3g}")
    assert true < 0.2 * noisy
    assert 1 / ESTIMATE_FACTOR < estimate / true < ESTIMATE_FACTOR


def _box3(image):
    """A linear 'denoiser': the 3x3 box mean (edges repeated), which blurs detail as well as noise."""
    h, w = image.shape[:2]
    pad = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    return sum(pad[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)) / 9.0


def test_the_estimate_sees_the_noise_left_and_the_blur_of_a_linear_denoiser(monkeypatch):
    """Truth: stripes one pixel wide (detail a 3x3 box blurs away) plus a gradient; two halves of
    independent noise; D = box(N). For a linear smoother both parts of the estimate are unbiased:
    the noise part is D's variance, the whole is D's mean squared error, blur included."""
    rng = np.random.default_rng(5)
    h, w = 200, 200
    y, x = np.mgrid[0:h, 0:w]
    truth = (0.3 + 0.4 * (x % 2) + 0.2 * y / h)[..., None] * np.ones(3)
    sigma = 0.3
    noisy_a = truth + sigma * rng.standard_normal(truth.shape)
    noisy_b = truth + sigma * rng.standard_normal(truth.shape)
    noisy = 0.5 * (noisy_a + noisy_b)
    d, da, db = _box3(noisy), _box3(noisy_a), _box3(noisy_b)
    n, na = np.full(h * w, 8.0), np.full(h * w, 4.0)
    est = denoised_error(d, da, db, noisy_a, noisy_b, n, na)
    true_mse = float(((d - truth) ** 2).mean())
    blur = float(((_box3(truth) - truth) ** 2).mean())
    variance = (sigma ** 2 / 2) / 9  # the box of 9 independent pixels of the full image's noise
    assert est["rmse_noise"] ** 2 == pytest.approx(variance, rel=0.05)
    assert est["rmse"] ** 2 == pytest.approx(true_mse, rel=0.05)
    assert blur > 5 * variance  # the blur dominates: the noise part alone would miss most of the error
    assert est["relmse"] > 5 * est["relmse_noise"]
    unknown = denoised_error(d, da, db, noisy_a, noisy_b, n, np.where(np.arange(h * w) == 7, 0.0, na))
    assert unknown["relmse"] == np.inf  # a pixel without half B
    from drt_engine.core.render import denoise

    monkeypatch.setattr(denoise, "ERROR_BLOCK", 999)  # in blocks of pixels, the same sums
    assert denoised_error(d, da, db, noisy_a, noisy_b, n, na) == pytest.approx(est, rel=1e-12)


def test_denoising_without_a_library_is_a_settings_error():
    scene, base = soft_shadow_scene(8)
    with pytest.raises(SettingsError, match="OpenImageDenoise"):
        Renderer(scene, RenderSettings(**base, samples=2, use_denoising=True))


def test_a_farm_part_is_not_denoised(oidn):
    part = render(oidn, samples=4, use_denoising=True, sample_start=0, sample_end=2)
    assert NOISY_IMAGE not in part.passes and "relmse_denoised" not in part.stats
    assert any("not denoised" in w for w in part.warnings)


def test_the_denoised_estimate_is_logged_at_the_end_or_at_the_steps_that_could_meet_the_target(oidn, pair):
    denoised, plain = pair
    assert [("relmse_denoised" in entry) for entry in denoised.log] == [False] * (len(denoised.log) - 1) + [True]
    assert all("relmse_denoised" not in entry for entry in plain.log)
    unreachable = render(oidn, samples=32, use_denoising=True, target_error=1e-9)
    assert [("relmse_denoised" in entry) for entry in unreachable.log] == [False] * (len(unreachable.log) - 1) + [True]
    assert unreachable.stats["stopped_by"] == "samples"
    loose = render(oidn, samples=32, use_denoising=True, target_error=1.0)  # any denoised image is under it
    steps = [entry for entry in loose.log if "relmse_denoised" in entry]
    assert loose.stats["stopped_by"] == "target_error" and steps == [loose.log[-1]]
    assert loose.log[-1]["spp_max"] == TARGET_MIN_SAMPLES and loose.log[-1]["relmse_denoised"] < 1.0


def test_a_step_is_denoised_when_its_noisy_error_times_the_last_ratio_is_under_the_target():
    schedule = Schedule(1e-3)
    assert schedule.ratio == DENOISED_SHARE and not schedule.due(0.02) and schedule.due(0.009)
    schedule.measured(4e-3, 2e-3)  # this scene's denoiser halves the error
    assert not schedule.due(2.1e-3) and schedule.due(1.9e-3)
    schedule.measured(math.inf, 1e-3)  # an unknown step changes nothing
    assert schedule.ratio == 0.5


def test_the_target_error_applies_to_the_denoised_image(oidn):
    """The same target stops a denoised render sooner: its image reaches it with fewer samples."""
    target = 2e-3
    noisy = render(samples=64, target_error=target)
    denoised = render(oidn, samples=64, target_error=target, use_denoising=True)
    print(f"target {target}: noisy stops at {noisy.stats['samples']} spp, denoised at {denoised.stats['samples']}")
    assert noisy.stats["stopped_by"] == denoised.stats["stopped_by"] == "target_error"
    assert denoised.stats["samples"] < noisy.stats["samples"]
    assert denoised.stats["relmse_denoised"] < target < denoised.stats["relmse"]


def test_merged_parts_are_denoised_once_as_the_whole_render_is(oidn, monkeypatch, tmp_path):
    """A farm's parts carry the denoiser's features, over all samples and per half, and the replicate
    halves in their sums, through their files; the merge denoises the merged film once (not per part,
    however often its images are asked for) and gives the whole render's denoised image and estimate."""
    from drt_engine.core.film import parts
    from drt_engine.core.film.denoising import PASSES as FEATURE_PASSES
    from drt_engine.core.render import merge

    scene, base = soft_shadow_scene(WIDTH)

    def run(start=0, end=0):
        settings = RenderSettings(**{**base, "samples": SPP, "seed": 1, "passes": ("Combined",),
                                     "use_denoising": True, "sample_start": start, "sample_end": end})
        return split_render.render_part(scene, settings, oidn)

    whole = run()[1]
    pieces = [run(a, b)[0] for a, b in ((3, SPP), (0, 3))]
    assert all(set(FEATURE_PASSES) <= set(piece.sums) and set(FEATURE_PASSES) == set(piece.sums_a)
               for piece in pieces)
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    pieces = [parts.read(tmp_path / f"{i}.exr") for i in range(len(pieces))]
    calls = []
    monkeypatch.setattr(merge, "denoise_film", lambda *a, real=merge.denoise_film: calls.append(a) or real(*a))
    merger = merge.merge_parts(pieces, ["A", "B"])
    assert not calls and all("relmse_denoised" not in entry for entry in merger.log.entries)
    images = merger.images(oidn)
    assert merger.images(oidn)["Combined"] is not images["Combined"] and len(calls) == 1
    assert set(images) == {"Combined", NOISY_IMAGE}
    np.testing.assert_allclose(images[NOISY_IMAGE], whole.passes[NOISY_IMAGE], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(images["Combined"], whole.passes["Combined"], rtol=1e-3, atol=1e-4)
    stats = merger.report(1.0)["stats"]
    assert stats["relmse_denoised"] == pytest.approx(whole.stats["relmse_denoised"], rel=1e-3)
    assert ["relmse_denoised" in entry for entry in merger.log.entries] == [False, True]
    assert set(merger.images(None)) == {"Combined"}  # without a library: the merged image as rendered
