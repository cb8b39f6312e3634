"""Soft shadows: the penumbra of a straight edge under a disk light, and how fast it converges.

Geometry: the ground z = 0, an opaque half-plane x < 0 at height h, a disk light of
radius R at height H centred over the edge. A ground point at x sees the part of the
disk beyond the chord at x_L = -x (H - h) / h, so the lit fraction is a circular
segment and the penumbra is 2 R h / (H - h) wide. An orthographic camera between
the occluder and the ground looks down at a strip across the edge.
"""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Mesh, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, translation

R, H, h = 0.5, 4.0, 1.0
WIDTH = 2 * R * h / (H - h)
RES, HALF = 64, 0.4  # 80 pixels per unit: the penumbra is about 27 pixels wide


def edge_scene(occluded=True):
    mats = [Material("ground", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))]),
            Material("blocker", [Closure("DIFFUSE", color=(0.0, 0.0, 0.0))])]
    blocker = Mesh("blocker", [[-50, -50, h], [0, -50, h], [0, 50, h], [-50, 50, h]], [[0, 1, 2], [0, 2, 3]], [1, 1])
    meshes = [plane(100.0)] + ([blocker] if occluded else [])
    cam = Camera(translation(0, 0, h / 2)[None], (-HALF, HALF, -HALF * 4 / RES, HALF * 4 / RES), (RES, 4),
                 type="ORTHO", clip_start=1e-3)
    light = Light("AREA", translation(0, 0, H), radiance=np.full(3, 10.0), shape="DISK", size_x=2 * R, size_y=2 * R)
    return SceneData(cam, meshes, [Instance(i, np.eye(4)) for i in range(len(meshes))], mats, [light])


def profile(samples, pattern="SOBOL", seed=0, occluded=True):
    s = RenderSettings(samples=samples, seed=seed, threads=1, sampling_pattern=pattern, filter_type="BOX",
                       filter_size=1.0)
    return Renderer(edge_scene(occluded), s).render().passes["Combined"][..., 0].mean(axis=0)


def segment_fraction(c):
    """Fraction of a unit-radius disk beyond the chord at c (in radii)."""
    c = np.clip(c, -1.0, 1.0)
    return (np.arccos(c) - c * np.sqrt(1 - c * c)) / np.pi


def pixel_x():
    return -HALF + (np.arange(RES) + 0.5) * 2 * HALF / RES


def analytic():
    """Visible fraction averaged over each pixel's footprint (box filter)."""
    fine = pixel_x()[None, :] + np.linspace(-0.5, 0.5, 41)[:, None] * (2 * HALF / RES)
    return segment_fraction(-fine * (H - h) / h / R).mean(axis=0)


def test_penumbra_profile_and_width_match_the_circular_segment():
    ratio = profile(512) / profile(16, occluded=False)
    expected = analytic()
    assert np.abs(ratio - expected).max() < 0.02
    # width between the 1% and 99% points of the profile, in pixels
    x = pixel_x()
    lo, hi = np.interp(0.01, ratio, x), np.interp(0.99, ratio, x)
    lo_e, hi_e = np.interp(0.01, expected, x), np.interp(0.99, expected, x)
    px = 2 * HALF / RES
    assert abs((hi - lo) - (hi_e - lo_e)) < px
    assert (hi_e - lo_e) == pytest.approx(WIDTH * 0.9, rel=0.15)  # 1-99% of the full 2Rh/(H-h)


def rmse_curve(render_fn, reference, counts, seeds):
    """RMSE per sample count, the squared error pooled over seeds before the root."""
    return np.array([np.sqrt(np.mean([np.mean((render_fn(n, s) - reference) ** 2) for s in seeds]))
                     for n in counts])


def slope(counts, errors):
    return np.polyfit(np.log2(counts), np.log2(errors), 1)[0]


def test_chained_sobol_samples_converge_faster_than_independent_ones():
    """RMSE against a high-sample reference: slope per doubling <= -0.7 for SOBOL, about -0.5
    for independent random samples (one-sample SOBOL images with independent seeds, averaged)."""
    reference = profile(8192, seed=99)
    counts = [4, 8, 16, 32, 64]
    seeds = [1, 2, 3]
    sobol = rmse_curve(lambda n, s: profile(n, seed=s), reference, counts, range(1, 9))
    independent_cache = {s: [profile(1, seed=1000 * s + k) for k in range(max(counts))] for s in seeds}
    random = rmse_curve(lambda n, s: np.mean(independent_cache[s][:n], axis=0), reference, counts, seeds)
    assert slope(counts, sobol) <= -0.7
    assert -0.62 <= slope(counts, random) <= -0.38
