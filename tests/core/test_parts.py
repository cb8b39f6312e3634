"""Disjoint sample ranges rendered apart add up to the whole render (core.film.parts)."""
import dataclasses

import numpy as np
import pytest

from drt_engine.core.render import report
from drt_engine.core.film import parts
from drt_engine.core.render.adaptive import image_error
from drt_engine.core.errors import SettingsError
from drt_engine.core.film.ratio_sums import RATIO
from drt_engine.core.settings import PASSES, RenderSettings
from test_determinism import scene
from tests.support import split_render

SAMPLES = 12
RELATIVE = 1e-6


def result_settings(pattern, start=0, end=0, seed=3, estimator="MONTE_CARLO"):
    return RenderSettings(samples=SAMPLES, seed=seed, threads=1, sampling_pattern=pattern, passes=PASSES,
                          sample_start=start, sample_end=end, shadow_estimator=estimator)


def render_part(pattern, start=0, end=0, seed=3, estimator="MONTE_CARLO"):
    return split_render.render_part(scene(), result_settings(pattern, start, end, seed, estimator))


def close(a, b, scale=None):
    """Equal within RELATIVE of the larger magnitude (the order of float64 additions differs),
    or of ``scale`` for a difference of two estimates (Noise: the full mean less the class A mean)."""
    scale = np.maximum(np.abs(a), np.abs(b)) if scale is None else scale
    return np.all(np.abs(a - b) <= RELATIVE * scale + 1e-300)


@pytest.mark.parametrize("pattern, estimator", [("SOBOL", "MONTE_CARLO"), ("GRID", "MONTE_CARLO"),
                                                ("SOBOL", "RATIO"), ("GRID", "RATIO")])
def test_merged_ranges_equal_the_whole_render(pattern, estimator, tmp_path):
    whole, result = render_part(pattern, estimator=estimator)
    assert (RATIO in whole.sums) == (estimator == "RATIO")  # the ratio estimator's sums travel too
    pieces = [render_part(pattern, a, b, estimator=estimator)[0] for a, b in ((5, 12), (0, 2), (2, 5))]
    merger = split_render.merged(pieces, tmp_path)  # through the files: float64 sums, losslessly
    film = merger.film
    assert np.array_equal(film.count, whole.count) and np.array_equal(film.count_a, whole.count_a)
    assert close(film.sum_a, whole.sum_a)
    for name in whole.sums:
        assert close(film.sums[name], whole.sums[name]), name
    images = film.images()
    combined = np.abs(result.passes["Combined"][..., :3])
    for name, image in result.passes.items():
        assert close(images[name], image, combined if name == "Noise" else None), name
    # the same error estimate as the whole render's
    assert image_error(film) == pytest.approx((result.stats["rmse"], result.stats["relmse"]), rel=RELATIVE)
    merged = merger.report(1.0)
    assert merged["settings"] == report.report_dict(result_settings(pattern, estimator=estimator), {}, [])["settings"]
    assert merged["stats"]["relmse"] == pytest.approx(result.stats["relmse"], rel=RELATIVE)
    assert merged["stats"]["rays"] == result.stats["rays"]
    assert [e["samples"] for e in merged["log"]] == [2 * 576, 5 * 576, 12 * 576]  # as ranges 0:2, 2:5, 5:12 merge
    # a part alone is not the image: its sums differ from the whole's
    assert not close(pieces[0].sums["Combined"], whole.sums["Combined"])


def test_other_seed_differs():
    a, _ = render_part("SOBOL", 0, 4, seed=1)
    b, _ = render_part("SOBOL", 0, 4, seed=2)
    assert not close(a.sums["Combined"], b.sums["Combined"])


def test_mismatched_parts_are_refused():
    a, _ = render_part("SOBOL", 0, 6)
    b, _ = render_part("SOBOL", 6, 12)
    parts.check([b, a])  # any order
    with pytest.raises(parts.PartError, match="samples 6:12 are missing"):
        parts.check([a])
    with pytest.raises(parts.PartError, match="overlaps"):
        parts.check([a, b, dataclasses.replace(b, header=dict(b.header, sample_range=[4, 8]))])
    for key, value, word in (("seed", 9, "seeds"), ("frame", 2, "frames"), ("fingerprint", "0" * 64, "scenes"),
                             ("settings", dict(b.header["settings"], max_depth=3), "settings")):
        other = dataclasses.replace(b, header=dict(b.header, **{key: value}))
        with pytest.raises(parts.PartError, match=f"different {word}"):
            parts.check([a, other], ["A.exr", "B.exr"])


def test_fingerprint_follows_the_scene():
    one, two = scene(), scene()
    assert parts.fingerprint(one) == parts.fingerprint(two)
    two.lights[0].radiance = two.lights[0].radiance * 2
    assert parts.fingerprint(one) != parts.fingerprint(two)


def test_sample_range_checks():
    with pytest.raises(SettingsError, match="not inside"):
        RenderSettings(samples=8, sample_start=4, sample_end=9)
    with pytest.raises(SettingsError, match="fixed sample count"):
        RenderSettings(samples=8, sample_start=4, use_adaptive_sampling=True)
    assert not RenderSettings(samples=8, sample_end=8).partial
