"""Adaptive sampling and the stop rules: who gets samples, when the render stops, and what it returns.

The test scene is a floor seen from above: its left half an emitter (every sample
sees the same radiance, so its pixels have no noise at all), its right half a diffuse
floor lit by a large area light just above it (light sampling makes it noisy: about 3%
relative standard error at 16 samples).
"""
import time

import numpy as np
import pytest

from drt_engine.core.render import adaptive
from drt_engine.core.film.film import Film
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Mesh, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import translation

RES = 24
EMISSION = 0.5
PASSES = ("Combined", "Sample Count", "Noise")


def half_plane(name, x0, x1, material):
    v = [[x0, -2, 0], [x1, -2, 0], [x1, 2, 0], [x0, 2, 0]]
    return Mesh(name, v, [[0, 1, 2], [0, 2, 3]], [material, material])


def halves_scene(right="LIT", res=RES):
    """Left: emitter of radiance 0.5. Right: lit diffuse floor ("LIT") or an emitter of radiance ``right``."""
    camera = Camera(translation(0, 0, 1)[None], (-1, 1, -1, 1), (res, res))
    materials = [Material("emitter", [Closure("EMISSION", emission=(EMISSION,) * 3)])]
    lights = []
    if right == "LIT":
        materials.append(Material("floor", [Closure("DIFFUSE", color=(0.5,) * 3)]))
        lights.append(Light("AREA", translation(0.5, 0, 0.1), radiance=np.full(3, 4.0), size_x=3.0))
    else:
        materials.append(Material("emitter2", [Closure("EMISSION", emission=(right,) * 3)]))
    meshes = [half_plane("left", -2, 0, 0), half_plane("right", 0, 2, 1)]
    return SceneData(camera, meshes, [Instance(0, np.eye(4)), Instance(1, np.eye(4))], materials, lights)


def render(scene=None, progress=None, **kw):
    settings = RenderSettings(**{"samples": 128, "threads": 1, "passes": PASSES, **kw})
    return Renderer(scene or halves_scene(), settings).render(progress=progress)


def columns(counts):
    """Mean sample count of the flat interior of the left half and of the right half."""
    counts = counts[..., 0]
    return counts[:, : RES // 2 - 3].mean(), counts[:, RES // 2 + 2:].mean()


def assert_consistent(result):
    """The passes are those of the samples the render traced, and the log ends where the image is."""
    counts = result.passes["Sample Count"][..., 0]
    assert counts.sum() == result.stats["rays"]["camera"]  # only the samples counted were traced
    assert counts.max() == result.stats["samples"]
    assert result.log[-1]["samples"] == counts.sum()
    assert result.log[-1].get("stopped") == result.stats["stopped_by"]
    for name, image in result.passes.items():
        assert np.isfinite(image).all(), name


# -- Cycles' semantics -----------------------------------------------------------------

def test_automatic_threshold_is_cycles_and_min_samples_leave_the_allocation_room():
    # scene/integrator.cpp: threshold 0 -> max(0.001, 1 / samples)
    assert adaptive.effective_threshold(0.0, 256) == pytest.approx(1 / 256)
    assert adaptive.effective_threshold(0.0, 4096) == pytest.approx(0.001)
    assert adaptive.effective_threshold(0.02, 256) == 0.02
    # min 0 -> min(16, cap / 8), at least 4 (Cycles: max(4, ceil(16 / threshold^0.3)), 64 at 0.01)
    assert adaptive.min_samples(0, 64) == 8
    assert adaptive.min_samples(0, 4096) == 16
    assert adaptive.min_samples(0, 16) == 4
    assert adaptive.min_samples(24, 64) == 24 and adaptive.min_samples(2, 64) == 4
    # the first test comes right after the minimum (Cycles: at the next multiple of 16 after it)
    assert adaptive.first_test(64) == 64 and adaptive.first_test(8) == 8 and adaptive.first_test(85) == 85


def test_rounds_hold_enough_samples_but_keep_the_first_test_and_the_cap():
    points = adaptive.checkpoints(256, 96)  # 1, 2, 4, ..., 64, 96, 112, ..., 240, 256
    assert adaptive.next_checkpoint(points, 0, 1 << 20, 96) == 1  # a large image: every checkpoint
    assert adaptive.next_checkpoint(points, 0, 1000, 96) == 32  # 1000 pixels x 32 >= MIN_ROUND
    assert adaptive.next_checkpoint(points, 0, 100, 96) == 96  # never past the first test
    assert adaptive.next_checkpoint(points, 96, 300, 96) == 160  # 300 x 64 >= MIN_ROUND
    assert adaptive.next_checkpoint(points, 240, 1, 96) == 256  # never past the cap


def test_threshold_zero_is_automatic_in_a_render():
    result = render(samples=128, use_adaptive_sampling=True, adaptive_threshold=0.0)
    assert result.stats["adaptive_threshold"] == pytest.approx(1 / 128)
    assert result.stats["adaptive_first_test"] == adaptive.first_test(adaptive.min_samples(0, 128)) == 16
    assert result.passes["Sample Count"].min() >= 16


# -- noise-adaptive ---------------------------------------------------------------------

def test_noise_adaptive_stops_converged_pixels_and_traces_only_active_ones():
    result = render(samples=256, use_adaptive_sampling=True, adaptive_threshold=0.002, adaptive_min_samples=8)
    counts = result.passes["Sample Count"]
    flat, noisy = columns(counts)
    first = adaptive.first_test(8)
    assert counts.min() == first  # every pixel took the minimum; the noiseless ones stopped at the first test
    assert flat == first
    assert noisy > 3 * flat
    assert len(np.unique(counts)) > 3  # a real per-pixel count, not one number
    assert_consistent(result)
    active = [e["active"] for e in result.log]
    assert 0 < min(active) < 0.75


def test_min_samples_are_honoured():
    for requested in (8, 40):
        result = render(samples=128, use_adaptive_sampling=True, adaptive_threshold=0.5, adaptive_min_samples=requested)
        assert result.passes["Sample Count"].min() == adaptive.first_test(requested) == requested


def test_a_noiseless_image_stops_by_the_threshold():
    result = render(halves_scene(EMISSION), samples=256, use_adaptive_sampling=True, adaptive_min_samples=8)
    assert result.stats["stopped_by"] == "threshold"
    assert result.passes["Sample Count"].max() == adaptive.first_test(8)
    assert_consistent(result)


def test_contrast_mode_refines_the_edge_only():
    # two noiseless emitters: the only contrast of the image is the edge between them
    result = render(halves_scene(0.05), samples=96, use_adaptive_sampling=True, adaptive_mode="CONTRAST",
                    adaptive_min_samples=8)
    counts = result.passes["Sample Count"][..., 0]
    first = adaptive.first_test(8)
    edge = counts[:, RES // 2 - 1: RES // 2 + 1]
    assert (edge == 96).all()  # samples keep differing across an edge: refined to the cap
    assert (counts[:, : RES // 2 - 3] == first).all() and (counts[:, RES // 2 + 3:] == first).all()
    assert_consistent(result)


def test_rounds_are_shared_in_proportion_to_the_error_per_sample():
    """Water-filling toward n_i = lambda x spread_i: the totals of the pixels that gain are in
    proportion to their spread, the others keep theirs, no pixel passes the cap."""
    film = Film(4, 1, ("Combined",))
    film.count[:] = 8
    film.count_a[:] = 4
    film.sums["Combined"][:] = 8 * 0.5
    deviation = np.array([0.0, 0.05, 0.1, 0.2])  # |full mean - replicate A mean|
    film.sum_a[:] = 4 * (0.5 + deviation)[:, None]
    spread = adaptive.sample_spread(film)
    assert np.all(np.diff(spread) > 0) and spread[0] > 0  # the noiseless pixel keeps a defensive share
    need = adaptive.allocate(film, np.arange(4), 60, cap=1000)
    total = 8 + need
    assert 60 <= need.sum() < 60 + 4
    gained = need > 0
    assert np.allclose(total[gained] / spread[gained], (total[gained] / spread[gained]).mean(), rtol=0.1)
    assert (adaptive.allocate(film, np.arange(4), 10 ** 6, cap=50) == 42).all()


def test_noise_rounds_beat_uniform_samples_at_equal_cost():
    """A small light just above a floor: the error per sample falls off with the distance,
    and giving samples where it is large lowers the image relMSE for the same samples."""
    camera = Camera(translation(0, 0, 1)[None], (-1, 1, -1, 1), (RES, RES))
    scene = SceneData(camera, [half_plane("floor", -2, 2, 0)], [Instance(0, np.eye(4))],
                      [Material("floor", [Closure("DIFFUSE", color=(0.5,) * 3)])],
                      [Light("AREA", translation(0.6, 0, 0.05), radiance=np.full(3, 40.0), size_x=0.3)])
    reference = render(scene, samples=4096, seed=7, passes=("Combined", "Noise"))
    truth = (reference.passes["Combined"][..., :3], reference.passes["Noise"] ** 2)
    adaptive_error, uniform_error = [], []
    for seed in range(3):
        shared = render(scene, samples=256, seed=seed, use_adaptive_sampling=True, adaptive_threshold=1e-4,
                        adaptive_min_samples=8)
        uniform = render(scene, samples=round(shared.stats["samples_mean"]), seed=seed)
        adaptive_error.append(adaptive.true_error(shared.passes["Combined"][..., :3], *truth)[1])
        uniform_error.append(adaptive.true_error(uniform.passes["Combined"][..., :3], *truth)[1])
        assert_consistent(shared)
    assert np.mean(uniform_error) > 1.25 * np.mean(adaptive_error), (uniform_error, adaptive_error)


# -- the error estimate -------------------------------------------------------------------

def test_noise_pass_is_the_standard_error_of_the_pixel_mean():
    """Pooled over pixels and seeds, the Noise pass squared is the squared error against a reference."""
    scene = halves_scene()
    reference = render(scene, samples=2048, seed=99, passes=("Combined", "Noise"))
    ref = reference.passes["Combined"][..., :3]
    ref_var = reference.passes["Noise"] ** 2
    right = np.s_[:, RES // 2 + 2:]
    squared_error, estimate = [], []
    for seed in range(6):
        result = render(scene, samples=32, seed=seed)
        squared_error.append(((result.passes["Combined"][..., :3] - ref) ** 2 - ref_var)[right].mean())
        estimate.append((result.passes["Noise"] ** 2)[right].mean())
        assert (result.passes["Sample Count"] == 32).all()
        assert (result.passes["Noise"][:, : RES // 2 - 3] == 0).all()  # the emitter's samples are all equal: no error, and none estimated
    ratio = np.sqrt(np.mean(estimate) / np.mean(squared_error))
    assert 1 / 1.3 < ratio < 1.3, ratio


def test_film_error_of_independent_halves_is_unbiased():
    """Samples of a known variance: the film's estimate of the mean's variance averages to var / n."""
    rng = np.random.default_rng(3)
    film = Film(2000, 1, ("Combined",))
    n = 16
    pixel = np.repeat(np.arange(2000), n)
    values = rng.normal(1.0, 0.2, (len(pixel), 4))
    film.add(pixel[::2], {"Combined": values[::2]}, np.zeros(len(pixel) // 2, np.uint32), replicate=0)
    film.add(pixel[1::2], {"Combined": values[1::2]}, np.zeros(len(pixel) // 2, np.uint32), replicate=1)
    assert film.variance().mean() == pytest.approx(0.04 / n, rel=0.08)



def test_relmse_estimate_pools_pixels_by_their_counts():
    """With equal counts the pooled estimate keeps the image's relMSE (up to the repeated edges);
    a pixel stopped on an estimate of 0 among pixels that kept sampling reads their error."""
    rng = np.random.default_rng(5)
    film = Film(32, 32, ("Combined",))
    film.count[:], film.count_a[:] = 16, 8
    film.sums["Combined"][:] = 16 * 0.5
    film.sum_a[:] = 8 * (0.5 + rng.exponential(0.05, (film.n, 1)))
    var = film.variance()
    own = (var / (np.maximum(0.25 - var, 0.25 * 0.25) + adaptive.RELMSE_EPSILON)).mean()
    assert adaptive.image_error(film)[1] == pytest.approx(own, rel=0.03)

    film.count[:], film.count_a[:] = 32, 16
    film.sums["Combined"][:] = 32 * 0.5
    film.sum_a[:] = 16 * 0.55
    centre = 16 * 32 + 16
    film.count[centre], film.count_a[centre] = 8, 4
    film.sums["Combined"][centre], film.sum_a[centre] = 8 * 0.5, 4 * 0.5
    pooled = adaptive.pooled_relative_error(film)
    assert pooled[centre] == pytest.approx(pooled[0], rel=0.05) and pooled[0] > 0

# -- stop rules ---------------------------------------------------------------------------

def test_target_error_stops_at_the_first_step_under_it():
    result = render(samples=4096, use_adaptive_sampling=True, adaptive_threshold=0.001, adaptive_min_samples=8,
                    target_error=2e-4)
    assert result.stats["stopped_by"] == "target_error"
    log = result.log
    assert log[-1]["relmse"] < 2e-4 <= log[-2]["relmse"]
    assert result.stats["samples"] < 4096
    assert result.stats["relmse"] == log[-1]["relmse"]
    assert_consistent(result)


def test_time_limit_stops_the_render_in_time():
    # minutes of work at full samples; two seconds allowed
    renderer = Renderer(halves_scene(res=64), RenderSettings(samples=65536, threads=1, passes=PASSES, time_limit=2.0))
    start = time.perf_counter()
    result = renderer.render()
    wall = time.perf_counter() - start
    assert result.stats["stopped_by"] == "time_limit"
    assert 2.0 <= wall < 2.5, wall
    assert result.stats["samples"] < 65536 // 8
    assert_consistent(result)


def test_cancel_mid_round_returns_a_consistent_image():
    calls = []

    def progress(update):
        calls.append(update)
        return len(calls) < 3

    result = render(halves_scene(res=64), samples=4096, progress=progress)
    assert result.cancelled and result.stats["stopped_by"] == "cancelled"
    assert_consistent(result)


def test_the_log_is_monotone_and_ends_at_the_cap():
    result = render(samples=128, use_adaptive_sampling=True, adaptive_threshold=0.002, adaptive_min_samples=8)
    log = result.log
    assert len(log) >= 3
    for key in ("elapsed", "cpu", "samples"):
        values = [e[key] for e in log]
        assert all(a <= b for a, b in zip(values, values[1:])), key
    assert all(0 < e["active"] <= 1 for e in log)
    assert result.stats["stopped_by"] in ("samples", "threshold")
    assert_consistent(result)
