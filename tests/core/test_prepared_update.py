"""An edited scene's prepared scene, updated from the one before the edit, renders the image a
fresh preparation of the edited scene gives, and rebuilds only the parts the edit touched."""
import dataclasses

import numpy as np

from drt_engine.core.geometry.embree import TriangleScene
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import PASSES, RenderSettings
from tests.support.scenes import translation
from tests.support.textured_scenes import environment_world, with_image_world
from test_determinism import scene

SETTINGS = RenderSettings(samples=4, seed=3, threads=1, passes=PASSES)


def same_image_as_fresh(updated: PreparedScene, edited) -> np.ndarray:
    """The updated prepared scene renders bit for bit what a fresh one (same centre) does, and
    the edit shows: the image differs from the scene before it."""
    fresh = PreparedScene(edited, center=updated.geometry.center)
    ours = Renderer(edited, SETTINGS, updated).render().passes
    theirs = Renderer(edited, SETTINGS, fresh).render().passes
    for name in theirs:
        assert np.array_equal(ours[name], theirs[name]), name
    return ours["Combined"]


def before(base, prepared):
    return Renderer(base, SETTINGS, prepared).render().passes["Combined"]


def mesh_builds(update):
    """The Embree mesh scenes (BVHs) ``update()`` built, and what it returned."""
    before = TriangleScene.builds
    result = update()
    return TriangleScene.builds - before, result


def test_an_instance_transform_rebuilds_the_geometry_and_keeps_the_materials():
    """... and no mesh's Embree scene: only the top level is new."""
    base = scene()
    prepared = PreparedScene(base)
    instances = list(base.instances)
    instances[1] = dataclasses.replace(instances[1], matrices=translation(0.3, 0.2, 0.1)[None])
    edited = dataclasses.replace(base, instances=instances)
    builds, updated = mesh_builds(lambda: prepared.update(edited))
    assert builds == 0
    assert updated.geometry is not prepared.geometry and updated.shading is prepared.shading
    assert updated.textures is prepared.textures
    image = same_image_as_fresh(updated, edited)
    assert not np.array_equal(image, before(base, prepared))


def test_a_mesh_edit_rebuilds_the_geometry():
    """... building that mesh's Embree scene alone."""
    base = scene()
    prepared = PreparedScene(base)
    meshes = list(base.meshes)
    meshes[2] = dataclasses.replace(meshes[2], vertices=meshes[2].vertices * np.float32(0.8))
    edited = dataclasses.replace(base, meshes=meshes)
    builds, updated = mesh_builds(lambda: prepared.update(edited))
    assert builds == 1
    assert updated.geometry is not prepared.geometry and updated.shading is prepared.shading
    same_image_as_fresh(updated, edited)


def test_a_material_edit_recompiles_that_material_alone():
    base = scene()
    prepared = PreparedScene(base)
    materials = list(base.materials)
    closure = dataclasses.replace(materials[2].closures[0], color=np.array([0.2, 0.3, 0.9]))
    materials[2] = dataclasses.replace(materials[2], closures=[closure])
    # a new export: equal materials as new objects are recognised by content
    materials[0] = dataclasses.replace(materials[0])
    edited = dataclasses.replace(base, materials=materials)
    updated = prepared.update(edited)
    assert updated.geometry is prepared.geometry
    assert [a is b for a, b in zip(updated.shading, prepared.shading)] == [True, True, False]
    image = same_image_as_fresh(updated, edited)
    assert not np.array_equal(image, before(base, prepared))


def test_a_light_edit_updates_the_lights_alone():
    base = scene()
    prepared = PreparedScene(base)
    light = dataclasses.replace(base.lights[0], radiance=np.array([2.0, 4.0, 10.0]))
    edited = dataclasses.replace(base, lights=[light])
    updated = prepared.update(edited)
    assert updated.geometry is prepared.geometry and updated.shading is prepared.shading
    assert updated.lights is not prepared.lights
    image = same_image_as_fresh(updated, edited)
    assert not np.array_equal(image, before(base, prepared))


def test_a_world_edit_updates_the_lights():
    base = scene()
    prepared = PreparedScene(base)
    edited = dataclasses.replace(base, world=dataclasses.replace(base.world, radiance=np.full(3, 0.5)))
    updated = prepared.update(edited)
    assert updated.lights is not prepared.lights and updated.geometry is prepared.geometry
    same_image_as_fresh(updated, edited)


def test_an_unchanged_export_rebuilds_nothing():
    base = scene()
    prepared = PreparedScene(base)
    again = dataclasses.replace(base, instances=[dataclasses.replace(i) for i in base.instances],
                                materials=[dataclasses.replace(m) for m in base.materials],
                                lights=[dataclasses.replace(light) for light in base.lights])
    updated = prepared.update(again)
    assert (updated.geometry, updated.shading, updated.lights) == (prepared.geometry, prepared.shading,
                                                                   prepared.lights)
    assert updated.serves(again) and not prepared.serves(again)


def test_an_edit_that_leaves_the_world_and_images_alone_keeps_the_world_table():
    """Tabulating an image world is most of the lights' cost (0.8 s for a 1024x512 map): a light
    edit and an object's move keep the table, and render what a fresh preparation renders."""
    base = with_image_world(scene())
    prepared = PreparedScene(base)
    light = dataclasses.replace(base.lights[0], radiance=np.array([2.0, 4.0, 10.0]))
    instances = list(base.instances)
    instances[2] = dataclasses.replace(instances[2], matrices=translation(0.2, 0.0, 0.1)[None])
    for edited in (dataclasses.replace(base, lights=[light]), dataclasses.replace(base, instances=instances)):
        updated = prepared.update(edited)
        assert updated.lights is not prepared.lights
        assert updated.lights.environment is prepared.lights.environment is not None
        same_image_as_fresh(updated, edited)


def test_a_world_or_image_edit_tabulates_the_world_again():
    base = with_image_world(scene())
    prepared = PreparedScene(base)
    sky = dataclasses.replace(base.images[0], pixels=base.images[0].pixels[::-1].copy())
    for edited in (dataclasses.replace(base, world=environment_world(image=0, strength=2.0)),
                   dataclasses.replace(base, images=[sky])):
        updated = prepared.update(edited)
        assert updated.lights.environment is not prepared.lights.environment
        image = same_image_as_fresh(updated, edited)
        assert not np.array_equal(image, before(base, prepared))
