"""The ratio estimator (shadow_estimator RATIO, core.integrator.ratio) on the soft-shadow scene (scenes.soft_shadow_scene).

Exact where the light is wholly in view; no bias against a converged Monte Carlo reference
beyond the noise (image mean and 4x4 blocks); an error estimate (Noise pass, error log) that
tracks the true error as tests/blender/test_adaptive_calibration.py asks of Monte Carlo.
"""
from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.render.adaptive import true_error
from drt_engine.core.film.film import Film
from drt_engine.core.film.ratio_sums import FILM_CHANNELS, NDU_CHANNELS, RATIO
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Light
from drt_engine.core.settings import RenderSettings
from tests.support import scenes
from tests.support.scenes import translation

WIDTH = 48
REFERENCE_SAMPLES = 1024
BIAS_SAMPLES, BIAS_SEEDS = 16, 8
CAP, SEEDS, FACTOR, RELMSE_FROM = 64, range(4), 1.5, 16  # as the Blender calibration test


def soft_shadow_scene(width):
    scene, base = scenes.soft_shadow_scene(width)
    return scene, dict(base, threads=1)


@pytest.fixture(scope="module")
def soft():
    """The scene at WIDTH px, its settings, and a Monte Carlo reference (image, variance)."""
    scene, base = soft_shadow_scene(WIDTH)
    settings = RenderSettings(samples=REFERENCE_SAMPLES, seed=1 << 20, shadow_estimator="MONTE_CARLO",
                              passes=("Combined", "Noise"), **base)
    ref = Renderer(scene, settings).render().passes
    return scene, base, (ref["Combined"][..., :3].astype(float), ref["Noise"].astype(float) ** 2)


def render(scene, samples, seed, estimator, **kw):
    renderer = Renderer(scene, RenderSettings(samples=samples, seed=seed, shadow_estimator=estimator, **kw))
    return renderer, renderer.render()


def test_a_wholly_lit_patch_is_exact():
    """Floor in front of the objects sees the whole light: two seeds at 4 spp agree within 1e-3
    (Monte Carlo differs by about 1%). The world is black and the pixel filter a point, so that
    only the light's sampling differs between seeds (the filter's footprint over the floor's
    gradient is anti-aliasing noise: with Blackman-Harris 1.5 it leaves 0.4% at 4 spp)."""
    scene, base = soft_shadow_scene(64)
    scene.world.radiance = np.zeros(3)
    base.update(filter_type="BOX", filter_size=0.01)
    patch = (slice(2, 10), slice(20, 44))  # rows from the bottom: the floor nearest the camera
    for estimator, holds in (("RATIO", True), ("MONTE_CARLO", False)):
        images = []
        for seed in (1, 2):
            renderer, result = render(scene, 4, seed, estimator, **base)
            images.append(result.passes["Combined"][..., :3].astype(float)[patch])
            if estimator == "RATIO":  # every sample of the patch saw the light: N = D
                ndu = renderer.film.sums[RATIO].reshape(48, 64, -1)[patch]
                assert np.allclose(ndu[..., 0:3], ndu[..., 3:6], rtol=1e-12) and (ndu[..., 3:6] > 0).all()
        a, b = images
        diff = np.abs(a - b).mean() / a.mean()
        assert (diff < 1e-3) == holds, (estimator, diff)


def test_a_diffuse_part_other_than_lambert_stays_monte_carlo():
    """The closed form U is Lambert's: an Oren-Nayar floor's direct light is left to Monte Carlo
    (no N, D, U of its samples), so its patch renders as with the Monte Carlo estimator, bit for bit."""
    from drt_engine.core.scene import Closure, Material
    scene, base = soft_shadow_scene(64)
    scene.materials[0] = Material("floor", [Closure("DIFFUSE", color=(0.6, 0.6, 0.6), diffuse_roughness=1.0)])
    patch = (slice(2, 10), slice(20, 44))
    images = {}
    for estimator in ("RATIO", "MONTE_CARLO"):
        renderer, result = render(scene, 4, 1, estimator, **base)
        images[estimator] = result.passes["Combined"][..., :3][patch]
        if estimator == "RATIO":
            assert not renderer.film.sums[RATIO].reshape(48, 64, -1)[patch].any()
    assert np.array_equal(images["RATIO"], images["MONTE_CARLO"])


def test_no_bias_against_monte_carlo(soft):
    """Mean of BIAS_SEEDS renders at BIAS_SAMPLES spp against the reference: image mean within
    0.3%, every 4x4 block within 5 standard errors and their mean squared z-score near 1 (the
    ratio's bias in penumbrae, O(1 / samples), would show as a shift beyond the noise)."""
    scene, base, (ref, ref_var) = soft
    images = np.stack([render(scene, BIAS_SAMPLES, seed, "RATIO", **base)[1].passes["Combined"][..., :3]
                       for seed in range(BIAS_SEEDS)]).astype(float)
    mean = images.mean(axis=0)
    assert abs(mean.mean() / ref.mean() - 1) < 3e-3
    var = images.var(axis=0, ddof=1) / BIAS_SEEDS + ref_var  # of the mean's pixels, and the reference's

    def blocks(x):
        h, w = x.shape[0] // 4 * 4, x.shape[1] // 4 * 4
        return x[:h, :w].reshape(h // 4, 4, w // 4, 4, 3).sum(axis=(1, 3))

    z = blocks(mean - ref) / np.sqrt(blocks(var))
    assert np.abs(z).max() < 5, np.abs(z).max()
    assert (z ** 2).mean() < 1.5, (z ** 2).mean()


@pytest.mark.parametrize("adaptive", [False, True])
def test_estimated_error_tracks_the_true_error(soft, adaptive):
    """At every logged step (k-th of each seed), pooled over SEEDS: estimated RMSE and relMSE
    within FACTOR of the true ones against the reference (less its variance), relMSE from
    RELMSE_FROM samples up."""
    scene, base, truth = soft
    extra = dict(use_adaptive_sampling=True, adaptive_threshold=0.01, adaptive_min_samples=8) if adaptive else {}
    per_seed = []
    for seed in SEEDS:
        steps = []

        def progress(update):
            if update.entry is not None:
                rmse, relmse = true_error(update.passes()["Combined"][..., :3], *truth)
                e = update.entry
                steps.append((e["spp_max"], e["rmse"] ** 2, rmse ** 2, e["relmse"], relmse))
            return True

        Renderer(scene, RenderSettings(samples=CAP, seed=seed, shadow_estimator="RATIO", **base, **extra)).render(
            progress=progress)
        per_seed.append(steps)
    common = min(len(s) for s in per_seed)
    assert common >= 2
    for k in range(common):
        spp = min(s[k][0] for s in per_seed)
        est_rmse, true_rmse, est_rel, true_rel = (np.mean([s[k][c] for s in per_seed]) for c in (1, 2, 3, 4))
        checks = [("RMSE", np.sqrt(est_rmse), np.sqrt(true_rmse))]
        if spp >= RELMSE_FROM:
            checks.append(("relMSE", est_rel, true_rel))
        for kind, estimated, true in checks:
            assert 1 / FACTOR < estimated / true < FACTOR, (kind, spp, estimated, true)


def test_plan_names_what_stays_monte_carlo():
    scene, base = soft_shadow_scene(16)
    scene.lights.append(Light("POINT", translation(0, 0, 3), intensity=np.full(3, 5.0), name="lamp"))
    ratio = Renderer(scene, RenderSettings(samples=1, shadow_estimator="RATIO", **base))
    assert ratio.plan.as_dict()["ratio"] == [ratio.plan.strategies[0]]
    assert ratio.plan.monte_carlo == ["point lamp (delta)", "world"]
    assert "Monte Carlo: point lamp (delta), world" in ratio.plan.summary()
    assert RATIO in ratio.film.sums
    mc = Renderer(scene, RenderSettings(samples=1, shadow_estimator="MONTE_CARLO", **base))
    assert mc.plan.ratio == [] and mc.plan.monte_carlo == [] and RATIO not in mc.film.sums


def test_film_reads_combined_resolved():
    """Combined = sum - N + U N / D per pixel and channel (N where D = 0); the Noise pass is the
    standard error from the two halves, each resolved with its own sums."""
    film = Film(2, 1, ("Combined", "Noise"), ratio=True)
    assert film.sums[RATIO].shape == (2, FILM_CHANNELS)
    rng = np.random.default_rng(5)
    n = 8
    pixel = np.repeat([0, 1], n)
    ndu = np.zeros((2 * n, NDU_CHANNELS))
    ndu[:n, 3:6] = rng.uniform(0.5, 1.5, (n, 3))  # pixel 0: D
    ndu[:n, 0:3] = ndu[:n, 3:6] * (rng.random((n, 1)) < 0.5)  # N: each sample visible or not
    ndu[:n, 6:9] = 1.0  # U
    combined = np.zeros((2 * n, 4))
    combined[:, :3] = ndu[:, 0:3] + 0.25  # the Monte Carlo N plus other light
    combined[:, 3] = 1.0
    replicate = np.tile([0, 1], n)
    for r in (0, 1):
        sel = replicate == r
        film.add(pixel[sel], {"Combined": combined[sel], RATIO: ndu[sel]}, np.arange(2 * n)[sel], replicate=r)
    images = film.images()
    s = ndu[:n].sum(axis=0)
    expected = 0.25 + s[6:9] / n * s[0:3] / s[3:6]
    assert np.allclose(images["Combined"][0, 0, :3], expected)
    assert np.allclose(images["Combined"][0, 1, :3], 0.25)  # D = 0: as Monte Carlo
    a = ndu[:n][replicate[:n] == 1].sum(axis=0)
    b = s - a
    half_a, half_b = 0.25 + a[6:9] / (n / 2) * a[0:3] / a[3:6], 0.25 + b[6:9] / (n / 2) * b[0:3] / b[3:6]
    assert np.allclose(images["Noise"][0, 0], np.abs(half_a - half_b) / 2)


def test_the_ratio_estimator_takes_lambertian_materials_without_diffuse_bounces():
    """The ratio estimator's closed form is of Lambert's cosine (MaterialShader.lambertian): a scene with
    no Lambertian material gives it nothing to take, so the plan names no strategy for it. With
    diffuse bounces a diffuse reflection's direct light is weighed against its rays, which the ratio
    estimator does not do, so it stands aside; a Translucent's rays are traced whatever the diffuse
    bounces (Lobe.bounces_diffuse), and only they name diffuse rays at diffuse bounces 0."""
    scene, base = soft_shadow_scene(16)

    def plan(closure, diffuse_bounces):
        materials = [replace(m, closures=[Closure(closure, color=(0.6, 0.6, 0.6))]) for m in scene.materials]
        settings = RenderSettings(samples=1, shadow_estimator="RATIO", diffuse_bounces=diffuse_bounces, **base)
        return Renderer(replace(scene, materials=materials), settings).plan

    for closure in ("TRANSLUCENT", "GLOSSY"):
        assert plan(closure, 0).ratio == plan(closure, 1).ratio == []
    assert plan("TRANSLUCENT", 0).rays["diffuse"] and not plan("DIFFUSE", 0).rays["diffuse"]
    assert plan("DIFFUSE", 1).rays["diffuse"]
    assert plan("DIFFUSE", 0).ratio != [] and plan("DIFFUSE", 1).ratio == []
