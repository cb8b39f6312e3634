"""Motion over the shutter: the depsgraph sampled at several times, as Cycles does.

The engine's ``frame_set(frame, subframe)`` re-evaluates the render depsgraph at each
shutter time; every instance's world matrix, the camera's, and the vertices of meshes
that deform are read there, then the frame is restored. Blender's own settings drive
it: ``render.use_motion_blur``, ``motion_blur_shutter`` (frames) and
``motion_blur_position`` (START: opens at the frame, CENTER: centred, END: closes).
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .camera import without_scale

MOTION_STEPS = 5
"""Shutter times sampled at least: enough for curved paths and rotations up to a half turn."""
STEPS_PER_FRAME = 4
"""More for long shutters: between two sampled times an object must turn less than half a turn
(slerp takes the short way), and whole turns between samples would not show at all. Four per
frame follow up to two turns per frame."""

_SHUTTER_START = {"START": 0.0, "CENTER": -0.5, "END": -1.0}


def shutter_times(scene) -> np.ndarray | None:
    """Frame times of the motion steps, or None when motion blur is off."""
    render = scene.render
    if not render.use_motion_blur or render.motion_blur_shutter <= 0:
        return None
    shutter = render.motion_blur_shutter
    now = scene.frame_current + scene.frame_subframe
    start = now + _SHUTTER_START.get(render.motion_blur_position, -0.5) * shutter
    steps = max(MOTION_STEPS, math.ceil(STEPS_PER_FRAME * shutter) + 1)
    return start + np.linspace(0.0, shutter, steps)


def instance_key(instance) -> tuple:
    """Identifies one object instance across frames (object, instancer, persistent id)."""
    if instance.is_instance:
        parent = instance.parent.original.name if instance.parent else ""
        return instance.object.original.name, parent, tuple(instance.persistent_id)
    return instance.object.original.name, "", ()


def _vertices(obj) -> np.ndarray | None:
    mesh = obj.data
    if not hasattr(mesh, "vertices"):
        return None
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def add_motion(scene_data, depsgraph, frame_set: Callable[[int, float], None], instance_keys: list,
               light_keys: list, camera_name: str) -> None:
    """Fill instance, light and camera matrices over the shutter, and deforming meshes' vertices."""
    times = shutter_times(depsgraph.scene)
    if times is None:
        return
    scene = depsgraph.scene
    wanted = {key: i for i, key in enumerate(instance_keys)}
    users = np.bincount([inst.mesh for inst in scene_data.instances], minlength=len(scene_data.meshes))
    steps = len(times)
    matrices = np.repeat(np.stack([inst.matrices[0] for inst in scene_data.instances])[:, None], steps, 1) \
        if scene_data.instances else np.zeros((0, steps, 4, 4))
    seen = np.zeros((len(instance_keys), steps), bool)
    light_index = {key: i for i, key in enumerate(light_keys)}
    light_matrices = np.repeat(np.stack([light.matrix for light in scene_data.lights])[:, None], steps, 1) \
        if scene_data.lights else np.zeros((0, steps, 4, 4))
    light_seen = np.zeros((len(light_keys), steps), bool)
    vertices: dict[int, list] = {}
    camera = np.repeat(scene_data.camera.matrices[:1], steps, 0)
    frame, subframe = scene.frame_current, scene.frame_subframe
    try:
        for k, t in enumerate(times):
            whole = math.floor(t)
            frame_set(int(whole), float(t - whole))
            for instance in depsgraph.object_instances:
                key = instance_key(instance)
                j = light_index.get(key) if instance.object.type == "LIGHT" else None
                if j is not None:
                    light_matrices[j, k] = without_scale(instance.matrix_world)
                    light_seen[j, k] = True
                    continue
                i = wanted.get(key)
                if i is None:
                    continue
                matrices[i, k] = np.array(instance.matrix_world, dtype=np.float64)
                seen[i, k] = True
                mesh_index = scene_data.instances[i].mesh
                if users[mesh_index] == 1:
                    v = _vertices(instance.object)
                    if v is not None and len(v) == len(scene_data.meshes[mesh_index].vertices):
                        vertices.setdefault(mesh_index, [None] * steps)[k] = v
            cam = depsgraph.objects.get(camera_name)
            if cam is not None:
                camera[k] = without_scale(cam.matrix_world)
    finally:
        frame_set(frame, subframe)
    for i, inst in enumerate(scene_data.instances):
        if seen[i].all():
            inst.matrices = matrices[i]
    scene_data.camera.matrices = camera
    for j, light in enumerate(scene_data.lights):
        if light_seen[j].all() and not np.allclose(light_matrices[j], light_matrices[j][:1]):
            light.matrices = light_matrices[j]
    for mesh_index, per_step in vertices.items():
        if all(v is not None for v in per_step):
            stack = np.stack(per_step)
            if not np.allclose(stack, stack[:1]):
                scene_data.meshes[mesh_index].motion_vertices = stack
