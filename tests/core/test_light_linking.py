"""Light linking (core.lights.linking): the receiver sets and memberships Blender computes for
Cycles, and renders in which an emitter that does not light an object gives it nothing, by light
sampling or by rays that find the emitter, while the camera still sees the emitter."""
from dataclasses import replace

import numpy as np

from drt_engine.core.lights.linking import light_sets, lights
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import LIGHT_SETS_ALL, Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera, translation, uv_sphere


def test_no_collection_lights_every_set():
    receiver, membership = light_sets([None, None])
    assert receiver == {} and membership == [LIGHT_SETS_ALL, LIGHT_SETS_ALL]


def test_excludes_only_light_every_other_object():
    """A collection with only exclusions lights the default set and every set but the excluded's."""
    receiver, membership = light_sets([{"floor": False}, None])
    assert receiver == {"floor": 1}
    assert membership[0] == LIGHT_SETS_ALL & ~(1 << 1) and membership[1] == LIGHT_SETS_ALL
    assert lights(np.array(membership, np.uint64), np.array([0, 0])).all()
    assert list(lights(np.array(membership, np.uint64), np.array([1, 1]))) == [False, True]


def test_an_inclusion_lights_the_included_alone():
    """With one inclusion, objects no collection names (the default set 0) are not lit by it."""
    receiver, membership = light_sets([{"ball": True, "floor": False}])
    assert receiver["ball"] != receiver["floor"]
    m = np.array(membership, np.uint64)
    assert list(lights(np.repeat(m, 3), np.array([0, receiver["ball"], receiver["floor"]]))) == [False, True, False]


def test_objects_named_alike_share_a_set_and_shared_collections_a_membership():
    shared = {"a": True, "b": True}
    receiver, membership = light_sets([shared, shared, {"c": False}])
    assert receiver["a"] == receiver["b"] != receiver["c"]
    assert membership[0] == membership[1] == 1 << receiver["a"]
    assert membership[2] == LIGHT_SETS_ALL & ~(1 << receiver["c"])


def test_sixty_four_sets_at_most():
    """Past 63 distinct sets, further objects stay in the default set (Blender's overflow)."""
    collections = [{f"o{k}": True} for k in range(64)]
    receiver, membership = light_sets(collections)
    assert len(receiver) == 63 and "o63" not in receiver and membership[63] == LIGHT_SETS_ALL


def scene(light_membership=LIGHT_SETS_ALL, glow_membership=LIGHT_SETS_ALL, floor_set=0) -> SceneData:
    """A diffuse floor (receiver set ``floor_set``) and ball under an area light, beside an emissive
    ball, black world."""
    white = Material("white", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8))])
    glow = Material("glow", [Closure("EMISSION", emission=(2.0, 1.0, 0.5))])
    meshes = [plane(6.0), uv_sphere(0.4, (0.3, 0.0, 0.4), 24, 12), uv_sphere(0.25, (-0.6, 0.4, 0.3), 16, 8, material=1)]
    instances = [Instance(0, np.eye(4), name="floor", receiver_light_set=floor_set),
                 Instance(1, np.eye(4), name="ball"),
                 Instance(2, np.eye(4), name="glow", light_set_membership=glow_membership)]
    light = Light("AREA", translation(0.0, 0.0, 2.0), radiance=np.array([3.0, 3.0, 3.0]), size_x=0.8, size_y=0.8,
                  light_set_membership=light_membership)
    return SceneData(top_camera(3.0, 0.5, 24), meshes, instances, [white, glow], [light],
                     World(radiance=np.zeros(3)))


def render(data, **settings):
    s = RenderSettings(**{"samples": 8, "threads": 1, "max_depth": 1, **settings})
    return Renderer(data, s).render().passes["Combined"][..., :3].astype(np.float64)


def _floor_mask(image):
    """Pixels the floor alone fills (the render with the floor excluded from every emitter is black there)."""
    return image.max(axis=2) == 0


def test_excluded_floor_gets_no_light_and_the_rest_is_unchanged():
    """Floor in set 1, both emitters leaving set 1 out (direct light only): the image is the one
    with a black floor, where the balls and the emissive ball the camera sees are as they were."""
    out = LIGHT_SETS_ALL & ~(1 << 1)
    linked = render(scene(out, out, floor_set=1))
    data = scene()
    data.materials.append(Material("black", [Closure("DIFFUSE", color=(0.0, 0.0, 0.0))]))
    data.meshes[0] = plane(6.0, material=2)
    black_floor = render(data)
    plain = render(scene())
    floor = _floor_mask(linked)
    assert floor.mean() > 0.5 and plain[floor].mean() > 0.05  # the floor was lit before
    np.testing.assert_allclose(linked, black_floor, rtol=1e-5, atol=1e-6)


def test_each_emitter_linked_apart():
    """Floor unlit by the area light alone: it keeps exactly the emissive ball's light (the render
    with the area light dark), found by light sampling and by rays (max depth 2)."""
    out = LIGHT_SETS_ALL & ~(1 << 1)
    linked = render(scene(out, floor_set=1), max_depth=2)
    data = scene(floor_set=1)
    dark = replace(data.lights[0], radiance=np.zeros(3))
    data.lights = [dark]
    glow_only = render(data, max_depth=2)
    plain = render(scene(), max_depth=2)
    floor = _floor_mask(render(scene(out, out, floor_set=1)))
    assert abs(linked[floor].mean() - glow_only[floor].mean()) < 0.05 * glow_only[floor].mean()
    assert plain[floor].mean() > 2 * linked[floor].mean()


def shadow_scene(light_membership=LIGHT_SETS_ALL, occluder_set=0, occluder_shadow=True) -> SceneData:
    """A floor under a square occluder (blocker set ``occluder_set``) and an area light, black world."""
    white = Material("white", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8)),
                               Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.3, weight=(0.3,) * 3)])
    meshes = [plane(6.0), plane(1.2, 0.8)]
    instances = [Instance(0, np.eye(4), name="floor"),
                 Instance(1, np.eye(4), name="occluder", blocker_shadow_set=occluder_set,
                          visible_shadow=occluder_shadow)]
    light = Light("AREA", translation(1.0, 0.0, 2.0), radiance=np.array([3.0, 3.0, 3.0]), size_x=0.6, size_y=0.6,
                  shadow_set_membership=light_membership)
    return SceneData(top_camera(3.0, 1.0, 24), meshes, instances, [white], [light], World(radiance=np.zeros(3)))


def test_a_blocker_the_light_leaves_out_casts_no_shadow():
    """The light's shadows cast by set 0 alone, the occluder in set 1: the image is (up to noise) the
    one with the occluder hidden from shadow rays, and far from the one with its shadow; the camera
    still sees the occluder, and reflections (max depth 2) of it, alike."""
    settings = {"samples": 64, "max_depth": 2}
    linked = render(shadow_scene(1, occluder_set=1), **settings)
    hidden = render(shadow_scene(occluder_shadow=False), **settings)
    shadowed = render(shadow_scene(), **settings)
    assert abs(linked.mean() - hidden.mean()) < 0.02 * hidden.mean()
    assert np.abs(linked - hidden).mean() < 0.2 * np.abs(shadowed - hidden).mean()
    assert np.abs(shadowed - hidden).mean() > 0.02 * hidden.mean()  # the shadow shows (4% of the mean)


def test_shadow_masks():
    from drt_engine.core.geometry.visibility import SHADOW, shadow_ray_mask
    assert shadow_ray_mask(LIGHT_SETS_ALL) & SHADOW and shadow_ray_mask(1 << 1) == 1 << 5
    assert shadow_ray_mask(LIGHT_SETS_ALL & ~1) & SHADOW == 0
