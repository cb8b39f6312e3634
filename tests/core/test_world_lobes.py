"""A uniform world's light sample drawn from the hit's diffuse-type lobes (core.integrator.world_lobes).

A patch of a tilted plane, seen at 70 degrees from its normal under a white world, every pixel
the same view: the mean is the same as with the cosine-weighted world sample it replaces (its
multiple importance sampling against the glossy rays that escape is consistent, the recorded
density at the bounce being the one the sample had), and a sheen's noise is a fraction of it.
"""
import math

import numpy as np
import pytest

from drt_engine.core.lights.collection import Lights
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera

L = 1.0
TILT = math.radians(70.0)


def _tilted():
    c, s = math.cos(TILT), math.sin(TILT)
    m = np.eye(4)
    m[1, 1], m[1, 2], m[2, 1], m[2, 2] = c, -s, s, c
    return m


def _scene(closures):
    return SceneData(top_camera(height=1.0, half_width=0.005, res=8), [plane(10)], [Instance(0, _tilted())],
                     [Material("m", closures)], [], World(np.full(3, L)))


def _render(scene, cosine, monkeypatch, samples=64, seed=0):
    """Combined (8 x 8), with the lobe-drawn world sample, or (``cosine``) the cosine-weighted one alone."""
    with monkeypatch.context() as m:
        if cosine:
            m.setattr(Lights, "uniform_world", property(lambda self: False))
        settings = RenderSettings(samples=samples, threads=1, seed=seed)
        return Renderer(scene, settings).render().passes["Combined"][..., :3]


SHEEN = [Closure("SHEEN", color=(1, 1, 1), roughness=0.3)]
MIXED = [Closure("SHEEN", weight=np.full(3, 0.5), color=(1, 1, 1), roughness=0.5),
         Closure("GLOSSY", weight=np.full(3, 0.5), color=(1, 1, 1), roughness=0.4)]


@pytest.mark.parametrize("closures", [SHEEN, MIXED], ids=["sheen", "sheen and glossy"])
def test_the_mean_is_the_cosine_samples(closures, monkeypatch):
    scene = _scene(closures)
    lobes = _render(scene, False, monkeypatch, samples=256).mean()
    cosine = _render(scene, True, monkeypatch, samples=256).mean()
    assert lobes == pytest.approx(cosine, rel=0.01)
    assert lobes > 0.05


def test_a_sheen_is_lit_with_a_fraction_of_the_cosine_samples_noise(monkeypatch):
    scene = _scene(SHEEN)
    lobes = _render(scene, False, monkeypatch, samples=16).std()
    cosine = _render(scene, True, monkeypatch, samples=16).std()
    assert lobes < 0.5 * cosine, (lobes, cosine)


def test_a_scene_with_no_lobe_to_draw_from_skips_the_draw_and_keeps_its_image(monkeypatch):
    """Lambert and glossy lobes keep the cosine sample: a scene with no sheen, toon or translucent
    lobe draws no lobe choice for the world and records no density for it (integrator.world_drawn),
    and its image is the very one it was with them drawn."""
    from drt_engine.core.integrator import integrator
    scene = _scene([Closure("DIFFUSE", weight=np.full(3, 0.5), color=(0.8, 0.6, 0.4)),
                    Closure("GLOSSY", weight=np.full(3, 0.5), color=(1, 1, 1), roughness=0.4)])
    settings = RenderSettings(samples=16, threads=1, seed=3, max_depth=3)
    renderer = Renderer(scene, settings)
    skipped = renderer.render().passes["Combined"]
    assert not renderer.integrator.world_drawn
    with monkeypatch.context() as m:
        m.setattr(integrator, "draws_from", lambda shader: True)
        drawn = Renderer(scene, settings)
        image = drawn.render().passes["Combined"]
        assert drawn.integrator.world_drawn
    assert np.array_equal(image, skipped)
