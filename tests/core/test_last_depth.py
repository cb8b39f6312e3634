"""The last depth of a path: no ray leaves it, so its light samples carry all of its direct light.

A rough glossy plane under an area light: at max_depth 1 the highlight is light samples and
BSDF rays that reach the light, weighted against each other; at max_depth 0 no BSDF ray is traced
and light sampling must find the same light alone. Weighted as if a ray would follow, depth 0
lost two thirds of the highlight (2.03 for 6.07).
"""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera, translation


def highlight(max_depth):
    light = Light("AREA", translation(0, 0, 0.5), radiance=np.full(3, 10.0), size_x=0.4, size_y=0.4)
    mat = Material("rough metal", [Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.3)])
    scene = SceneData(top_camera(height=1.0, half_width=0.1, res=8), [plane(4.0)], [Instance(0, np.eye(4))], [mat],
                      [light])
    result = Renderer(scene, RenderSettings(samples=256, threads=1, max_depth=max_depth)).render()
    return result.passes["Combined"][..., :3].mean()


def test_the_last_depth_keeps_the_share_of_rays_never_traced():
    assert highlight(0) == pytest.approx(highlight(1), rel=0.02)
