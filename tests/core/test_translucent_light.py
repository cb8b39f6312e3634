"""Light through a surface from the world: a Translucent ray is a transmission bounce (Cycles counts it
so, and continues it whatever the diffuse bounces), and an environment map lights what transmits
from behind as well as from above."""
from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.core.test_environment import L, constant_map
from tests.support.textured_scenes import environment_world, ortho_top, uv_plane

WHITE_TRANSLUCENT = [Closure("TRANSLUCENT", color=(1, 1, 1))]


def furnace(closures, world_map, heights=(0.0,)):
    """Wide planes of ``closures`` at ``heights`` seen from above under a world of radiance L, uniform or
    from a constant environment map."""
    world = environment_world() if world_map else World(radiance=np.full(3, L))
    return SceneData(camera=ortho_top(8, half=0.5, height=3.0), meshes=[uv_plane(half=50, z=z) for z in heights],
                     instances=[Instance(i, np.eye(4)) for i in range(len(heights))],
                     materials=[Material("m", closures)], world=world, images=[constant_map()] if world_map else [])


def mean(scene, diffuse_bounces=0, samples=256):
    settings = RenderSettings(samples=samples, seed=1, threads=1, diffuse_bounces=diffuse_bounces)
    return Renderer(scene, settings).render().passes["Combined"][..., :3].astype(np.float64).mean()


def test_translucent_rays_are_planned_and_counted_without_diffuse_bounces():
    """The plan names the Translucent's rays (DRT counts them as diffuse rays) at diffuse bounces 0,
    and a Lambert scene still leaves diffuse rays out."""
    result = Renderer(furnace(WHITE_TRANSLUCENT, False), RenderSettings(samples=4, threads=1)).render()
    assert result.stats["plan"]["rays"]["diffuse"] and result.stats["rays"]["diffuse"] > 0
    lambert = Renderer(furnace([Closure("DIFFUSE", color=(1, 1, 1))], False), RenderSettings(samples=4, threads=1))
    assert "diffuse rays" in lambert.render().stats["plan_summary"]


@pytest.mark.parametrize("world_map", [False, True], ids=["uniform", "map"])
@pytest.mark.parametrize("diffuse_bounces", [0, 1])
def test_a_white_translucent_plane_passes_the_world_on(world_map, diffuse_bounces):
    """A white Translucent plane transmits all the light from behind it: it shows L. Under a map,
    whose light sample was left out below the normal while the escaping rays' MIS weighed against
    it, it read 0 without diffuse bounces and 0.47% dark with them."""
    assert abs(mean(furnace(WHITE_TRANSLUCENT, world_map), diffuse_bounces) / L - 1) < 0.002


@pytest.mark.parametrize("world_map", [False, True], ids=["uniform", "map"])
def test_a_translucent_seen_through_a_translucent_passes_the_world_on(world_map):
    """Two white Translucent planes, one above the other: the lower passes the world's L on to the
    upper, which passes it on to the camera, L again, without diffuse bounces. A Translucent ray not
    traced (the upper plane's light sample blocked by the lower) leaves it dark."""
    assert abs(mean(furnace(WHITE_TRANSLUCENT, world_map, heights=(0.0, -1.0))) / L - 1) < 0.005


def test_a_world_hidden_from_diffuse_rays_is_hidden_from_a_translucent():
    """A Translucent's ray is a diffuse ray and a transmission at once (Cycles' ray flags): a world
    whose ray visibility leaves out Diffuse lights it neither by light samples nor by its rays, so
    the plane is black, as in Cycles. Taken by the side it leaves alone (a transmission, which the
    world still lights), the ray saw the world."""
    scene = furnace(WHITE_TRANSLUCENT, False)
    hidden = replace(scene, world=replace(scene.world, visible_diffuse=False))
    assert mean(hidden) < 1e-6 < mean(scene)


def test_rough_glass_takes_a_map_world_as_a_uniform_one():
    """A rough glass plane under a constant map and under a uniform world of the same radiance: one
    image. With the map's light sample left out below the normal, the map's read 0.34% dark."""
    glass = [Closure("GLASS", color=(1, 1, 1), roughness=0.5, ior=1.5)]
    assert mean(furnace(glass, True)) / mean(furnace(glass, False)) == pytest.approx(1.0, abs=1e-3)
