"""The viewport's worker: a new view of the same scene reuses its prepared scene, a new scene
prepares again, each view shows its coarse image first and ends with what a render of that
camera gives."""
import dataclasses

import numpy as np

from drt_engine.blender.export.viewport import coarse_divisor, level_cameras
from drt_engine.blender.viewport import ViewportRender
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera
from drt_engine.core.settings import RenderSettings
from tests.core.test_determinism import scene
from tests.support.scenes import look_at


def finish(viewport):
    viewport._thread.join(timeout=120)
    assert not viewport._thread.is_alive()
    return viewport.latest()[1]


class Shapes:
    """Records the shape of every image the worker publishes."""

    def __init__(self):
        self.viewport = None
        self.seen = []

    def __call__(self):
        image = self.viewport.latest()[1]
        self.seen.append(None if image is None else image.shape[:2])


def test_a_new_view_reuses_the_prepared_scene_and_renders_its_camera():
    shapes = Shapes()
    viewport = shapes.viewport = ViewportRender(shapes)
    base = scene()
    settings = RenderSettings(samples=2, threads=1)
    images, prepared = [], []
    for eye in ((0, -5, 2), (3, -4, 1.5)):
        camera = Camera(look_at(eye, (0, 0, 0.5))[None], (-0.3, 0.3, -0.3, 0.3), (24, 16))
        shapes.seen.clear()
        viewport.start(base, level_cameras(camera, 8), settings)
        images.append(finish(viewport))
        # one sample at 1/8 of the size, then the full size (once per round and at the end)
        assert shapes.seen[0] == (2, 3) and set(shapes.seen[1:]) == {(16, 24)} and len(shapes.seen) > 1, shapes.seen
        prepared.append(viewport._prepared[1])
        moved = dataclasses.replace(base, camera=camera)  # prepared anew around the first view's centre
        expected = Renderer(moved, settings, PreparedScene(moved, base.camera.matrix[:3, 3])).render().passes["Combined"]
        assert np.array_equal(images[-1], expected.astype(np.float32))
    assert prepared[0] is prepared[1]
    assert not np.array_equal(images[0], images[1])
    other = scene()
    viewport.start(other, [other.camera], settings)
    finish(viewport)
    assert viewport._prepared[1] is not prepared[0]


def test_the_coarse_image_is_an_eighth_with_its_long_side_128_pixels_or_more():
    """As Cycles' viewport starts a view: 1/8 of a large region, less where that would leave the
    long side under 128 pixels, none for a region under 256."""
    assert [coarse_divisor(size) for size in ((1280, 720), (720, 1280), (3840, 2160), (600, 400), (300, 40),
                                              (255, 255), (24, 16))] == [8, 8, 8, 4, 2, 1, 1]
    camera = Camera(look_at((0, -5, 2), (0, 0, 0.5))[None], (-0.3, 0.3, -0.3, 0.3), (1280, 720), window=(0, 0, 640, 720))
    coarse, full = level_cameras(camera)
    assert coarse.resolution == (160, 90) and coarse.window == (0, 0, 160, 90) and coarse.frame == camera.frame
    assert full is camera
    small = dataclasses.replace(camera, resolution=(200, 120), window=None)
    assert level_cameras(small) == [small]


def test_viewport_denoising_starts_at_its_start_sample_and_ends_as_a_denoised_render():
    """Below the start sample the image is as traced; from it on, denoised on the worker thread: the
    last image is the render's Combined through the same denoiser (Fast prefilter, Balanced quality
    unless the scene chose others, the features traced with it)."""
    from drt_engine.blender.viewport import ViewDenoise
    from drt_engine.core.film import denoiser
    from tests.support.oidn import require_oidn

    oidn = denoiser.load(require_oidn())
    base = scene()
    settings = RenderSettings(samples=4, threads=1)
    camera = Camera(look_at((0, -5, 2), (0, 0, 0.5))[None], (-0.3, 0.3, -0.3, 0.3), (48, 32))
    moved = dataclasses.replace(base, camera=camera)
    denoise = ViewDenoise(oidn, 2, "FAST", "BALANCED")  # Cycles' viewport defaults
    passes = Renderer(moved, denoise.settings(settings), PreparedScene(moved, base.camera.matrix[:3, 3])).render().passes
    denoised = passes["Combined"].copy()
    denoised[..., :3] = oidn.denoise(passes["Combined"], passes["Denoising Albedo"], passes["Denoising Normal"],
                                     prefilter=denoise.prefilter, quality=denoise.quality)
    chosen = denoised.copy()  # the scene's own prefilter and quality
    chosen[..., :3] = oidn.denoise(passes["Combined"], passes["Denoising Albedo"], passes["Denoising Normal"],
                                   prefilter="ACCURATE", quality="FAST")
    for start, options, expected, note in ((2, {}, denoised, True), (5, {}, passes["Combined"], False),
                                           (2, {"prefilter": "ACCURATE", "quality": "FAST"}, chosen, True)):
        statuses = []
        viewport = ViewportRender(lambda: statuses.append(viewport.status))
        viewport.start(base, level_cameras(camera), settings, dataclasses.replace(denoise, start_sample=start, **options))
        image = finish(viewport)
        assert statuses[-1].startswith("Done") and statuses[-1].endswith("| Denoised") == note, statuses[-1]
        np.testing.assert_array_equal(image, expected.astype(np.float32))
    assert not np.array_equal(denoised[..., :3], passes["Combined"][..., :3])
    assert not np.array_equal(denoised[..., :3], chosen[..., :3])


def test_views_share_the_denoisers_filters_until_the_viewport_closes():
    """Every view of one viewport denoises on the same filters (set up once per size, not per orbit
    step); closing the viewport releases them, and a late worker's call is then a DRT error."""
    import pytest

    from drt_engine.core.errors import DenoiserError
    from drt_engine.core.film import denoiser
    from tests.support.oidn import require_oidn

    oidn = denoiser.load(require_oidn())
    viewport = ViewportRender(lambda: None)
    filters = viewport.filters(oidn)
    assert viewport.filters(oidn) is filters
    filters.denoise(np.ones((8, 8, 3)))
    viewport.close()
    with pytest.raises(DenoiserError, match="released"):
        filters.denoise(np.ones((8, 8, 3)))
