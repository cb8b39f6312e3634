"""Multiple importance sampling adds light sampling and lobe sampling without bias.

A white glossy plane (multiscatter GGX reflects everything) under an emitter that
fills nearly the whole sky must show the emitter's radiance, whichever strategy
found it; a perfect mirror shows light bodies at the radiance Cycles gives them.
"""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera, translation

L = 2.0


def glossy_plane_scene(roughness, lights=(), emitter=False, world=0.0):
    mats = [Material("glossy", [Closure("GLOSSY", color=(1, 1, 1), roughness=roughness)]),
            Material("sky", [Closure("EMISSION", emission=(L,) * 3)])]
    meshes, instances = [plane(10)], [Instance(0, np.eye(4))]
    if emitter:
        meshes.append(plane(4000.0, z=1.5, material=1))
        instances.append(Instance(1, np.eye(4)))
    cam = top_camera(height=1.0, half_width=0.2, res=8)
    return SceneData(cam, meshes, instances, mats, list(lights), World(np.full(3, world)))


def mean(scene, samples=64):
    return Renderer(scene, RenderSettings(samples=samples, threads=1)).render().passes["Combined"][..., :3].mean()


@pytest.mark.parametrize("roughness", [0.0, 0.2, 0.6])
def test_glossy_furnace_under_a_huge_area_light(roughness):
    light = Light("AREA", translation(0, 0, 1.5), radiance=np.full(3, L), size_x=4000.0, size_y=4000.0)
    assert mean(glossy_plane_scene(roughness, [light])) == pytest.approx(L, rel=0.01)


@pytest.mark.parametrize("roughness", [0.0, 0.2, 0.6])
def test_glossy_furnace_under_an_emissive_mesh(roughness):
    assert mean(glossy_plane_scene(roughness, emitter=True)) == pytest.approx(L, rel=0.01)


@pytest.mark.parametrize("roughness", [0.0, 0.2, 0.6])
def test_glossy_furnace_under_the_world(roughness):
    assert mean(glossy_plane_scene(roughness, world=L)) == pytest.approx(L, rel=0.01)


@pytest.mark.parametrize("soft", [True, False])
def test_mirror_shows_a_round_light_at_its_radiance(soft):
    """Point light of power P, radius r seen in a mirror: radiance P / (4 pi^2 r^2) (Cycles)."""
    power, r = 100.0, 0.5
    light = Light("POINT", translation(0, 0, 3.0), intensity=np.full(3, power / (4 * np.pi)), radius=r,
                  soft_falloff=soft)
    scene = glossy_plane_scene(0.0, [light])
    scene.camera.frame = (-0.001, 0.001, -0.001, 0.001)
    assert mean(scene, samples=4) == pytest.approx(power / (4 * np.pi**2 * r * r), rel=1e-3)


def test_mirror_shows_the_sun_disk():
    strength, angle = 3.0, 0.2
    sun = Light("SUN", np.eye(4), irradiance=np.full(3, strength), angle=angle)
    scene = glossy_plane_scene(0.0, [sun])
    scene.camera.frame = (-0.001, 0.001, -0.001, 0.001)
    expected = strength / (np.pi * np.sin(angle / 2) ** 2)
    assert mean(scene, samples=4) == pytest.approx(expected, rel=1e-3)


def test_lights_are_hidden_from_the_camera_unless_visible_camera():
    facing_up = translation(0, 0, -1) @ np.diag([1.0, -1.0, -1.0, 1.0])
    light = Light("AREA", facing_up, radiance=np.full(3, L), size_x=1.0)
    scene = SceneData(top_camera(height=1.0, half_width=0.01), lights=[light])
    assert mean(scene, samples=4) == 0.0
    light.visible_camera = True
    assert mean(scene, samples=4) == pytest.approx(L)


@pytest.mark.parametrize("transparent", [False, True])
def test_a_visible_light_lets_the_camera_see_what_is_behind_it(transparent):
    """Cycles' integrate_light: a light is no surface, so the camera ray adds its emission and goes
    on; the world behind adds its own (or, with a transparent film, makes the pixel transparent)."""
    facing_up = translation(0, 0, -1) @ np.diag([1.0, -1.0, -1.0, 1.0])
    light = Light("AREA", facing_up, radiance=np.full(3, L), size_x=1.0, visible_camera=True)
    scene = SceneData(top_camera(height=1.0, half_width=0.01), lights=[light], world=World(np.full(3, 0.25)))
    scene.film_transparent = transparent
    combined = Renderer(scene, RenderSettings(samples=4, threads=1)).render().passes["Combined"]
    assert combined[..., :3].mean() == pytest.approx(L if transparent else L + 0.25)
    assert combined[..., 3].mean() == pytest.approx(0.0 if transparent else 1.0)


def _tiled_lights(n_side, size=4000.0, height=1.5):
    tile = size / n_side
    return [Light("AREA", translation(-size / 2 + (i + 0.5) * tile, -size / 2 + (j + 0.5) * tile, height),
                  radiance=np.full(3, L), size_x=tile, size_y=tile) for i in range(n_side) for j in range(n_side)]


@pytest.mark.parametrize("roughness", [0.0, 0.3])
def test_lights_chosen_by_contribution_stay_unbiased_under_mis(monkeypatch, roughness):
    """The huge sky split into 25 tiles and only 2 tiles sampled per point: still L."""
    from drt_engine.core.lights import collection as lights_module
    monkeypatch.setattr(lights_module, "SELECT_ABOVE", 4)
    monkeypatch.setattr(lights_module, "SELECT_SLOTS", 2)
    scene = glossy_plane_scene(roughness, _tiled_lights(5))
    assert Renderer(scene, RenderSettings(samples=1, threads=1)).lights.selecting
    assert mean(scene, samples=64) == pytest.approx(L, rel=0.01)


def test_lights_chosen_by_contribution_light_a_diffuse_plane_like_all_lights(monkeypatch):
    from drt_engine.core.lights import collection as lights_module
    rng = np.random.default_rng(5)
    lights = [Light("POINT", translation(*rng.uniform([-3, -3, 0.5], [3, 3, 2])), intensity=rng.uniform(0.5, 2, 3))
              for _ in range(12)]
    mats = [Material("white", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])]
    scene = SceneData(top_camera(height=1.0, half_width=2.0, res=16), [plane(20)], [Instance(0, np.eye(4))], mats,
                      lights)
    every = Renderer(scene, RenderSettings(samples=4, threads=1)).render().passes["Combined"][..., :3]
    monkeypatch.setattr(lights_module, "SELECT_ABOVE", 4)
    monkeypatch.setattr(lights_module, "SELECT_SLOTS", 3)
    chosen = Renderer(scene, RenderSettings(samples=256, threads=1)).render().passes["Combined"][..., :3]
    assert chosen.mean() == pytest.approx(every.mean(), rel=0.01)
