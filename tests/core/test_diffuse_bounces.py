"""Diffuse bounces (Cycles' Light Paths): light that bounces off diffuse surfaces, counted once.

Inside a closed polyhedron whose every face emits E and reflects diffusely with albedo a, every
point is lit by the whole enclosure. If the radiance leaving the walls is L everywhere, the
irradiance is pi L and the walls reflect a L, so light that has bounced i times is E a^i. The
camera sees the emission (i = 0) and, with diffuse bounces k, the walls' direct light (i = 1,
light sampling at the first hit) and k more bounces (each diffuse vertex sampling the lights):

    L_k = E (1 + a + ... + a^(k+1)) = E (1 - a^(k+2)) / (1 - a).

With k = 0 (the default) that is E (1 + a), the classic image. A bounce missing or counted
twice (light sampling and the diffuse ray both adding the emission they find, unweighted) moves
the value by E a^(k+1) or more, far outside the tolerance. Flat faces: the closed form needs the
shading normal of the facet.
"""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera, uv_sphere

ALBEDO, E = 0.8, 1.0


def furnace(albedo=ALBEDO):
    """Camera at the centre of a closed flat-faced sphere of emission E and diffuse albedo ``albedo``."""
    mat = Material("glowing wall", [Closure("DIFFUSE", color=np.full(3, albedo)),
                                    Closure("EMISSION", emission=np.full(3, E))])
    sphere = uv_sphere(1.0, segments=16, rings=8, smooth=False)
    camera = top_camera(height=0.0, half_width=0.5, res=8)
    return SceneData(camera, [sphere], [Instance(0, np.eye(4))], [mat], [], World(np.zeros(3)))


def mean(scene, samples, **settings):
    result = Renderer(scene, RenderSettings(samples=samples, threads=1, **settings)).render()
    return result.passes["Combined"][..., :3].mean()


def closed_form(k, albedo=ALBEDO):
    return E * (1.0 - albedo ** (k + 2)) / (1.0 - albedo)


@pytest.mark.parametrize("k", [0, 1, 3])
def test_furnace_converges_to_its_closed_form(k):
    assert mean(furnace(), 128, diffuse_bounces=k) == pytest.approx(closed_form(k), rel=0.01)


def test_the_bounces_stop_at_the_path_depth():
    """max_depth bounds every path: with diffuse bounces 4 and depth 2 the walls show two bounces."""
    assert mean(furnace(), 128, diffuse_bounces=4, max_depth=2) == pytest.approx(closed_form(2), rel=0.01)


def test_russian_roulette_keeps_the_furnace_unbiased():
    """Paths of up to 64 diffuse bounces ended by Russian roulette after the first bounce: the
    infinite sum E / (1 - a) (a^66 is nothing); without the roulette's 1 / p it is far darker."""
    albedo = 0.5
    value = mean(furnace(albedo), 128, diffuse_bounces=64, max_depth=64)
    assert value == pytest.approx(closed_form(64, albedo), rel=0.01)


@pytest.mark.parametrize("hidden", ["visible_diffuse", "visible_glossy", "visible_transmission"])
def test_diffuse_rays_see_the_world_by_its_diffuse_visibility(hidden):
    """A diffuse plane open to a uniform world of radiance L reflects albedo x L, found by light
    samples and escaping diffuse rays weighted against each other: none of it with the world
    hidden from diffuse rays (as Cycles' background shader), all of it with the world hidden
    from glossy or transmitted ones (a diffuse ray taking their visibility loses its share)."""
    albedo, radiance = 0.5, 0.8
    world = World(np.full(3, radiance))
    setattr(world, hidden, False)
    scene = SceneData(top_camera(height=1.0, half_width=0.2, res=4), [plane(4.0)], [Instance(0, np.eye(4))],
                      [Material("white", [Closure("DIFFUSE", color=np.full(3, albedo))])], [], world)
    value = mean(scene, 64, diffuse_bounces=2)
    if hidden == "visible_diffuse":
        assert value == 0.0
    else:
        assert value == pytest.approx(albedo * radiance, rel=0.02)
