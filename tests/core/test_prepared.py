"""A prepared scene serves renders with other cameras exactly as a scene prepared for each."""
import copy
import dataclasses

import numpy as np
import pytest

from drt_engine.core.sampling import dims as D
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Light
from drt_engine.core.settings import PASSES, RenderSettings
from tests.support.scenes import look_at, translation
from test_determinism import scene


def camera(eye):
    return Camera(look_at(eye, (0, 0, 0.5))[None], (-0.3, 0.3, -0.3, 0.3), (24, 24))


def test_another_camera_on_a_prepared_scene_gives_the_image_of_a_scene_prepared_for_it():
    """Nothing camera-dependent is kept: a render reusing the prepared scene equals one that
    prepares the scene anew (around the same centre: Embree's float32 coordinates are centred
    on the camera the scene was prepared with, see core.render.prepared)."""
    base = scene()
    prepared = PreparedScene(base)
    assert np.array_equal(prepared.geometry.center, base.camera.matrix[:3, 3])
    s = RenderSettings(samples=4, seed=2, threads=1, passes=PASSES)
    for eye in ((0, -5, 2), (3, -4, 1.5), (-2, -3, 4)):
        moved = dataclasses.replace(base, camera=camera(eye))
        reused = Renderer(moved, s, prepared).render().passes
        fresh = Renderer(moved, s, PreparedScene(moved, center=prepared.geometry.center)).render().passes
        for name in fresh:
            assert np.array_equal(reused[name], fresh[name]), (eye, name)
    assert Renderer(base, s, prepared).geometry is prepared.geometry


def test_a_prepared_scene_refuses_another_scene():
    with pytest.raises(ValueError):
        Renderer(scene(), RenderSettings(samples=1), PreparedScene(scene()))


def test_adding_a_light_leaves_every_other_strategy_dimension_and_the_path_dimensions():
    base = scene()
    extra = Light("POINT", translation(0, 0, 3), intensity=np.full(3, 5.0), name="Extra")
    one = D.LightDims(D.strategy_keys(PreparedScene(base).lights), 8)
    more = dataclasses.replace(base, lights=[extra] + base.lights)
    two = D.LightDims(D.strategy_keys(PreparedScene(more).lights), 8)
    assert one.keys == two.keys[1:] and len(one.keys) == 2  # the area light and the world
    for depth in range(9):
        for k in range(len(one.keys)):
            assert one.point(depth, k) == two.point(depth, k + 1) and one.choice(depth, k) == two.choice(depth, k + 1)
        used = {two.point(depth, k) + i for k in range(3) for i in range(4)}
        assert D.lobe(depth) < min(used) and len(used) == 12
    assert D.lobe(8) + 2 < min(D.LightDims(["a"], 8).point(d, 0) for d in range(9))


def test_the_content_key_ignores_the_camera_and_sees_any_other_change():
    from drt_engine.core.render.prepared import content_key

    base = scene()
    key = content_key(base)
    assert key == content_key(copy.deepcopy(base)) == content_key(dataclasses.replace(base, camera=camera((1, -4, 2))))
    moved = copy.deepcopy(base)
    moved.meshes[1].vertices[0, 0] += 1e-6
    recoloured = copy.deepcopy(base)
    recoloured.materials[2].closures[0].color = np.array([0.9, 0.7, 0.31])
    dimmer = copy.deepcopy(base)
    dimmer.lights[0].radiance = np.full(3, 9.0)
    keys = {content_key(s) for s in (moved, recoloured, dimmer)}
    assert key not in keys and len(keys) == 3


def test_an_adopted_scene_renders_on_the_prepared_parts():
    base = scene()
    prepared = PreparedScene(base)
    later = copy.deepcopy(dataclasses.replace(base, camera=camera((1, -4, 2))))  # the next frame's export
    adopted = prepared.adopt(later)
    assert prepared.serves(adopted) and adopted.camera is later.camera
    s = RenderSettings(samples=2, threads=1)
    fresh = Renderer(later, s, PreparedScene(later, center=prepared.geometry.center)).render().passes["Combined"]
    assert np.array_equal(Renderer(adopted, s, prepared).render().passes["Combined"], fresh)
