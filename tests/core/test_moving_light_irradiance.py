"""A point light sliding over a Lambertian floor: the time-averaged image has a closed form.

A point light of intensity I at height h moves from x0 to x1 along y = 0 over the shutter
(two light transforms, interpolated linearly per ray). A floor point (x, y) receives
E(p) = I h / ((x - p)^2 + d^2)^(3/2) with d^2 = y^2 + h^2, and averaged over the path
(1 / (x1 - x0)) [h u / (d^2 sqrt(u^2 + d^2))] for u = p - x from x0 - x to x1 - x; its
radiance is albedo / pi times that. Each pixel is compared with the closed form averaged over
its footprint (box filter), and the check is shown to fail on the render 3% too dark.
"""
import numpy as np

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Light
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import lit_plane_scene, translation

I, h, X0, X1, ALBEDO = 2.0, 0.5, -0.5, 0.5, 0.5
RES, HALF = 48, 1.0
TOLERANCE = 0.01


def render(seed=0):
    light = Light("POINT", translation(0, 0, h), intensity=np.full(3, I),
                  matrices=[translation(X0, 0, h), translation(X1, 0, h)])
    camera = Camera(translation(0, 0, 1.0)[None], (-HALF, HALF, -HALF * 2 / RES, HALF * 2 / RES), (RES, 2),
                    type="ORTHO", clip_start=1e-3)
    settings = RenderSettings(samples=256, seed=seed, threads=1, filter_type="BOX", filter_size=1.0)
    return Renderer(lit_plane_scene(light, albedo=ALBEDO, camera=camera), settings).render().passes["Combined"][..., 0]


def analytic():
    """The closed form averaged over each pixel's footprint."""
    step = 2 * HALF / RES
    offsets = (np.arange(16) + 0.5) / 16 - 0.5
    x = (-HALF + (np.arange(RES) + 0.5) * step)[:, None, None] + offsets[None, :, None] * step
    y = np.zeros((1, 1, 1)) + offsets[None, None, :] * step
    d2 = y * y + h * h

    def primitive(u):
        return h * u / (d2 * np.sqrt(u * u + d2))

    irradiance = I * (primitive(X1 - x) - primitive(X0 - x)) / (X1 - X0)
    return ALBEDO / np.pi * irradiance.mean(axis=(1, 2))


def worst(image, expected):
    return float(np.abs(image.mean(axis=0) / expected - 1.0).max())


def test_sliding_point_light_matches_the_time_averaged_closed_form():
    image, expected = render(), analytic()
    assert expected.max() > 3 * expected.min()  # the light's path shows in the image
    assert worst(0.97 * image, expected) > TOLERANCE  # a render 3% too dark fails
    assert worst(image, expected) < TOLERANCE, worst(image, expected)
