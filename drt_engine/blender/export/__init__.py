"""The evaluated depsgraph into one plain-data ``SceneData``.

Every visible object, including collection, geometry-nodes and particle instances,
comes from ``depsgraph.object_instances``; the depsgraph has already left out what
is disabled for render or excluded from the view layer.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...core.errors import RenderCancelled
from ...core.scene import SceneData
from ..properties import lightgroup_of, view_layer_lightgroups
from .camera import export_camera
from .geometry import GeometryExporter, MeshCache
from .left_out import LeftOut, passes_left_out
from .linking import LightLinks
from .lights import export_light
from .materials import MaterialTable
from .motion import add_motion, add_motion_pass, instance_key
from .shader_graph import ImageTable
from .world import export_world

CANCEL_CHECK_INTERVAL = 256
"""Instances exported between two calls of the cancel callback."""


def export_scene(
    depsgraph,
    camera_object=None,
    cancel: Callable[[], bool] | None = None,
    frame_set: Callable[[int, float], None] | None = None,
    meshes: MeshCache | None = None,
) -> SceneData:
    """Export the scene seen by ``depsgraph`` from ``camera_object`` (default: the scene camera).

    With ``frame_set`` (the render engine's) and motion blur on, motion over the
    shutter is sampled too; with the Vector pass on instead, the previous and next frames.
    ``meshes`` (the viewport's) keeps meshes between exports: one found there is not read again. Raises ``SceneError`` for a scene that cannot be rendered
    and ``RenderCancelled`` when ``cancel()`` returns True.
    """
    scene = depsgraph.scene
    camera_object = camera_object or scene.camera
    if camera_object is not None and not camera_object.is_evaluated:
        camera_object = camera_object.evaluated_get(depsgraph)  # animated and constrained transform
    camera = export_camera(scene, camera_object)
    warnings: list[str] = []
    images = ImageTable(warnings, scene.frame_current)
    materials = MaterialTable(warnings, images, (scene, depsgraph.view_layer))
    light_groups = view_layer_lightgroups(depsgraph.view_layer)
    group_of = {name: i for i, name in enumerate(light_groups)}
    geometry = GeometryExporter(materials, depsgraph.view_layer.material_override, meshes, depsgraph.view_layer_eval,
                                group_of)
    lights = []
    light_keys = []
    left_out = LeftOut(depsgraph.mode == "RENDER")
    links = LightLinks()
    for count, instance in enumerate(depsgraph.object_instances):
        if cancel is not None and count % CANCEL_CHECK_INTERVAL == 0 and cancel():
            raise RenderCancelled("Render cancelled during scene export")
        if not instance.show_self:
            continue
        obj = instance.object
        rendered = left_out.look_at(obj, instance.is_instance)
        links.look_at(obj)
        matrix = np.array(instance.matrix_world, dtype=np.float64)
        if obj.type == "LIGHT":
            light = export_light(obj, matrix, warnings, images)
            if light is not None:
                light.lightgroup = lightgroup_of(obj, group_of)
                lights.append(light)
                light_keys.append(instance_key(instance))
        elif rendered:
            geometry.add(obj, matrix, instance_key(instance), instance.parent if instance.is_instance else None,
                         instance.random_id if instance.is_instance else None)
    geometry.finish()
    links.apply(lights, geometry.instances, [key[1] for key in geometry.keys], warnings)
    world = getattr(depsgraph.view_layer, "world_override", None) or scene.world
    warnings.extend(left_out.warnings())
    if depsgraph.mode == "RENDER":  # the viewport writes no passes
        warnings.extend(passes_left_out(depsgraph.view_layer))
    scene_data = SceneData(
        camera=camera,
        meshes=geometry.meshes,
        instances=geometry.instances,
        materials=materials.materials,
        lights=lights,
        world=replace(export_world(world, warnings, images, depsgraph.view_layer),
                      lightgroup=lightgroup_of(world, group_of)),
        images=images.images,
        film_transparent=scene.render.film_transparent,
        warnings=warnings,
        light_groups=list(light_groups),
    )
    if frame_set is not None:
        add_motion(scene_data, depsgraph, frame_set, geometry.keys, light_keys, camera_object.name)
        add_motion_pass(scene_data, depsgraph, frame_set, geometry.keys, camera_object.name)
    return scene_data

