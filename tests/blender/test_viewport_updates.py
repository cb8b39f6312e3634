"""The viewport's edits, from the depsgraph's own update list: a transform re-reads no mesh, a
mesh edit re-reads that mesh alone, and the prepared scene updated from the exports renders what
a fresh preparation of the edited scene renders."""
import dataclasses

import bpy
import numpy as np
import pytest

from drt_engine.blender.export import export_scene
from drt_engine.blender.export.geometry import MeshCache
from drt_engine.blender.export.viewport import edited_geometry
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import RenderSettings
from tests.support import render_helpers as rh


@pytest.fixture
def viewport(drt, sample_scene):
    """``edit(change)``: apply ``change`` to the Cornell box, then export as view_update does
    (the meshes the depsgraph reports edited forgotten first); returns (scene data, geometry names)."""
    bpy.ops.wm.open_mainfile(filepath=str(sample_scene("cornell_box")))
    cache = MeshCache()
    seen = []

    def handler(scene, depsgraph):
        seen.append(edited_geometry(depsgraph.updates))

    bpy.app.handlers.depsgraph_update_post.append(handler)

    def edit(change=None):
        if change is not None:
            change()
        seen.clear()
        bpy.context.view_layer.update()
        names = set().union(*seen)
        cache.forget(names)
        return export_scene(bpy.context.evaluated_depsgraph_get(), meshes=cache), names

    yield edit
    bpy.app.handlers.depsgraph_update_post.remove(handler)


def mesh_named(scene_data, name):
    return next(m for m in scene_data.meshes if m.name == name)


def test_transform_material_and_light_edits_keep_the_meshes_a_mesh_edit_rereads_its_own(viewport):
    first, _ = viewport()
    room = bpy.data.objects["Room"]
    moved, names = viewport(lambda: setattr(room, "location", (0.1, 0.0, 0.0)))
    assert names == set() and all(a is b for a, b in zip(first.meshes, moved.meshes))
    assert any(not np.array_equal(a.matrices, b.matrices) for a, b in zip(first.instances, moved.instances))
    light = next(o for o in bpy.data.objects if o.type == "LIGHT")
    lit, _ = viewport(lambda: setattr(light.data, "energy", light.data.energy * 2))
    assert all(a is b for a, b in zip(first.meshes, lit.meshes))

    def edit_mesh():
        room.data.vertices[0].co.x += 0.01
        room.data.update()

    edited, names = viewport(edit_mesh)
    assert "Room" in names
    kept = [m.name for m, old in zip(edited.meshes, first.meshes) if m is old]
    assert mesh_named(edited, room.data.name) is not mesh_named(first, room.data.name)
    assert sorted(kept) == sorted(m.name for m in first.meshes if m.name != room.data.name)


def test_the_updated_prepared_scene_renders_the_edited_scene(viewport):
    first, _ = viewport()
    prepared = PreparedScene(first)
    box = bpy.data.objects["TallBox"]
    moved, _ = viewport(lambda: setattr(box, "rotation_euler", (0.0, 0.0, box.rotation_euler.z + 0.3)))
    updated = prepared.update(moved)
    assert updated.shading is prepared.shading and updated.geometry is not prepared.geometry
    settings = RenderSettings(samples=2, threads=1)
    moved = dataclasses.replace(moved, camera=dataclasses.replace(moved.camera, resolution=(32, 32), window=None))
    ours = Renderer(moved, settings, updated).render().passes["Combined"]
    fresh = PreparedScene(moved, center=prepared.geometry.center)
    assert np.array_equal(ours, Renderer(moved, settings, fresh).render().passes["Combined"])


def test_an_image_world_is_tabulated_again_only_when_the_world_changes(viewport):
    """Every edit exports the world anew; the update compares its digest (and the images'), so the
    world's sampling table (lights.environment, most of the lights' cost under an image world) stays
    through a light edit and a move and is made again when the world is edited."""
    world = bpy.context.scene.world
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(str(rh.ROOT / "tests" / "data" / "grid_weight.png"))
    background = next(node for node in tree.nodes if node.type == "BACKGROUND")
    tree.links.new(texture.outputs["Color"], background.inputs["Color"])
    prepared = PreparedScene(viewport()[0])
    table = prepared.lights.environment
    assert table is not None
    light = next(o for o in bpy.data.objects if o.type == "LIGHT")
    for edit in (lambda: setattr(light.data, "energy", light.data.energy * 2),
                 lambda: setattr(bpy.data.objects["TallBox"], "location", (0.1, 0.2, 0.0))):
        prepared = prepared.update(viewport(edit)[0])
        assert prepared.lights.environment is table
    prepared = prepared.update(viewport(lambda: setattr(background.inputs["Strength"], "default_value", 2.0))[0])
    assert prepared.lights.environment is not table


def test_the_viewport_traces_with_the_scenes_light_paths(viewport):
    """Rendered shading takes the scene's Light Paths as F12 does (diffuse bounces included): only
    the samples, the passes and the stop rules are the viewport's own."""
    from drt_engine.blender.properties import settings_from_scene
    from drt_engine.blender.viewport import viewport_settings

    drt = bpy.context.scene.drt
    drt.diffuse_bounces, drt.glossy_bounces, drt.transmission_bounces, drt.max_depth = 3, 5, 2, 6
    final = settings_from_scene(bpy.context.scene, bpy.context.view_layer)
    shown = viewport_settings(final, drt.preview_samples)
    light_paths = ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "max_depth", "min_light_bounces",
                   "max_transparent_bounces", "sample_clamp_direct", "sample_clamp_indirect", "filter_glossy")
    assert [getattr(shown, name) for name in light_paths] == [getattr(final, name) for name in light_paths]
    assert (shown.diffuse_bounces, shown.samples) == (3, drt.preview_samples)
