"""The estimated error of a render tracks its true error, on every sample scene.

At every logged step, the estimated RMSE and relMSE of the image (``adaptive.image_error``,
from the film's two independent replicates) are each within a factor of 1.5 of the true ones
against a reference of 1024 samples with another seed, less the reference's own estimated
variance (the relMSE from RELMSE_FROM samples up), with and without adaptive sampling.
Both are pooled over four seeds (RMSE as the root of the mean square, relMSE as the mean):
at 32 pixels wide the error of glossy_spheres sits in the handful of pixels that hold the gold
sphere's highlight, so one render's true error is itself a sum of a few squares (one seed alone
ranged from 0.5 to 1.9 times its estimate). It passes there by a balance, not part by part: at
64 spp the pixels one of whose replicate halves reads over 3x the other (the highlight's) are
estimated at about 3x their true error and the others at about half theirs (measured offline on
four seeds against a 2048-sample reference), so a change to the estimate that mends either part
alone fails it. Adaptive renders are compared step by step (the k-th logged step of each seed;
their rounds follow their own pixels, so the most samples a pixel holds can differ between
seeds), which always includes the first test.
"""
import bpy
import numpy as np
import pytest

from drt_engine.blender.export import export_scene
from drt_engine.core.render.adaptive import first_test, true_error
from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import RenderSettings
from tests.support.sample_scene_files import SCENES

WIDTH = 32
REFERENCE_SAMPLES = 1024
CAP = 64
SEEDS = range(4)
FACTOR = 1.5
MIN_SAMPLES = 8
RELMSE_FROM = 16
"""The relMSE is checked from this many samples in the busiest pixel up. At 8 samples and 32 px,
glossy_spheres' relMSE sits in the few pixels of the gold sphere's highlight, which most renders
miss entirely (pooled over the four seeds: true 0.108, estimated 0.047); no estimate from the
samples can see a highlight they missed. At 64 px the same step reads 0.89 (bench/adaptive_study.py)."""


@pytest.fixture(scope="module", params=SCENES)
def scene(request, drt, sample_scene):
    bpy.ops.wm.open_mainfile(filepath=str(sample_scene(request.param)), load_ui=False)
    blender_scene = bpy.context.scene
    render = blender_scene.render
    aspect = render.resolution_y / render.resolution_x
    render.resolution_x, render.resolution_y = WIDTH, max(4, round(WIDTH * aspect))
    render.resolution_percentage = 100
    render.use_border = False
    data = export_scene(bpy.context.evaluated_depsgraph_get())
    base = dict(max_depth=blender_scene.drt.max_depth, filter_type=blender_scene.drt.filter_type,
                filter_size=render.filter_size, passes=("Combined", "Noise"))
    reference = Renderer(data, RenderSettings(samples=REFERENCE_SAMPLES, seed=1 << 20, **base)).render().passes
    truth = (reference["Combined"][..., :3].astype(float), reference["Noise"].astype(float) ** 2)
    return request.param, data, base, truth


def pooled_steps(scene, **settings) -> list[tuple]:
    """(most samples a pixel holds, least over the seeds; estimated RMSE; true RMSE; estimated relMSE;
    true relMSE), means of the squared errors over the seeds, at every step (the k-th logged of each
    render) all seeds logged."""
    _, data, base, truth = scene
    per_seed = []
    for seed in SEEDS:
        steps = {}

        def progress(update):
            if update.entry is not None:
                rmse, relmse = true_error(update.passes()["Combined"][..., :3], *truth)
                e = update.entry
                steps[len(steps)] = (e["spp_max"], e["rmse"] ** 2, rmse ** 2, e["relmse"], relmse)
            return True

        Renderer(data, RenderSettings(samples=CAP, seed=seed, **base, **settings)).render(progress=progress)
        per_seed.append(steps)
    common = sorted(set.intersection(*(set(s) for s in per_seed)))
    return [(min(s[k][0] for s in per_seed), *(np.sqrt(np.mean([s[k][c] for s in per_seed])) for c in (1, 2)),
             *(np.mean([s[k][c] for s in per_seed]) for c in (3, 4))) for k in common]


def assert_tracks(name, steps):
    for spp, *errors in steps:
        checks = [("RMSE", *errors[:2])]
        if spp >= RELMSE_FROM:
            checks.append(("relMSE", *errors[2:]))
        for kind, estimated, true in checks:
            assert np.isfinite(estimated), (name, kind, spp)
            assert 1 / FACTOR < estimated / true < FACTOR, (name, kind, spp, estimated, true)


def test_estimated_error_tracks_the_true_error(scene):
    steps = pooled_steps(scene)
    assert len(steps) >= 2 and steps[-1][0] == CAP
    assert_tracks(scene[0], steps)


@pytest.mark.parametrize("mode", ["NOISE", "CONTRAST"])
def test_estimated_error_tracks_the_true_error_while_adapting(scene, mode):
    steps = pooled_steps(scene, use_adaptive_sampling=True, adaptive_mode=mode, adaptive_threshold=0.01,
                         adaptive_min_samples=MIN_SAMPLES)
    after = [step for step in steps if step[0] >= first_test(MIN_SAMPLES)]
    assert after[0][0] == first_test(MIN_SAMPLES) and len(after) >= 2
    assert_tracks(f"{scene[0]} {mode}", after)
