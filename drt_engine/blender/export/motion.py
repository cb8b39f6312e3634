"""Motion over the shutter: the depsgraph sampled at several times, as Cycles does.

The engine's ``frame_set(frame, subframe)`` re-evaluates the render depsgraph at each
shutter time; every instance's world matrix, the camera's, and the vertices of meshes
that deform are read there, then the frame is restored. Blender's own settings drive
it: ``render.use_motion_blur``, ``motion_blur_shutter`` (frames) and
``motion_blur_position`` (START: opens at the frame, CENTER: centred, END: closes), and
each object's Motion Blur panel as Cycles reads it (blender/object.cpp object_motion_steps):
its Motion Blur switch (and its instancer's), Deformation, and Steps, which sample it at
2^Steps + 1 evenly spaced times (3 by default). Times nest, so the scene is evaluated at the
finest object's times and every other object's steps are among them; between its own steps an
object moves as Cycles moves it, translation and stretch linearly and rotation by slerp.

Shutters longer than a frame get at least ``STEPS_PER_FRAME`` steps per frame, beyond Cycles:
slerp takes the short way between two steps, so an object turning more than half a turn between
them turns back, and whole turns between them do not show (an arm spinning 4 turns over a
10-frame shutter stands still at Steps 1, in Cycles too).
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ...core.geometry.motion import Motion
from .camera import without_scale

MAX_STEPS = 129
"""Cycles' Object::MAX_MOTION_STEPS."""
STEPS_PER_FRAME = 4
"""Steps per frame of a shutter longer than a frame: follows up to two turns per frame."""

_SHUTTER_START = {"START": 0.0, "CENTER": -0.5, "END": -1.0}


def shutter_times(scene, steps: int) -> np.ndarray | None:
    """Frame times of ``steps`` motion steps, or None when motion blur is off."""
    render = scene.render
    if not render.use_motion_blur or render.motion_blur_shutter <= 0 or steps < 2:
        return None
    shutter = render.motion_blur_shutter
    now = scene.frame_current + scene.frame_subframe
    start = now + _SHUTTER_START.get(render.motion_blur_position, -0.5) * shutter
    return start + np.linspace(0.0, shutter, steps)


def long_shutter_steps(shutter: float) -> int:
    """The fewest steps (2^k + 1) a shutter of ``shutter`` frames needs: ``STEPS_PER_FRAME`` per
    frame beyond one frame, none asked for up to one."""
    if shutter <= 1.0:
        return 0
    return min((1 << math.ceil(math.log2(STEPS_PER_FRAME * shutter))) + 1, MAX_STEPS)


def motion_steps(obj, instancer=None) -> int:
    """The times ``obj`` is sampled at over the shutter (0: its motion blur is off), as Cycles'
    object_motion_steps: an instance takes its instancer's switch too and the larger Steps."""
    owners = [obj] if instancer is None or instancer == obj else [obj, instancer]
    steps = 1
    for owner in owners:
        settings = getattr(owner, "cycles", None)
        if settings is None:
            continue
        if not settings.use_motion_blur:
            return 0
        steps = max(steps, settings.motion_steps)
    return min((2 << (steps - 1)) + 1, MAX_STEPS)


def deforms_in_motion(obj) -> bool:
    """The object's Deformation switch (Cycles' use_deform_motion)."""
    settings = getattr(obj, "cycles", None)
    return settings is None or settings.use_deform_motion


def own_steps(per_time: np.ndarray, steps: int, interpolate) -> np.ndarray:
    """Samples at every scene time (S, ...) from the object's own ``steps`` among them (S = 1 +
    k (steps - 1)): between two of its steps, ``interpolate(own, fractions)``."""
    if steps >= len(per_time):
        return per_time
    own = per_time[::(len(per_time) - 1) // (steps - 1)]
    return interpolate(own, np.linspace(0.0, 1.0, len(per_time)))


def _matrices_between(own: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    motion = Motion(own)
    return np.stack([motion.matrix_at(t) for t in fractions])


def _vertices_between(own: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    x = fractions * (len(own) - 1)
    i = np.minimum(x.astype(np.int64), len(own) - 2)
    u = (x - i)[:, None, None]
    return (1.0 - u) * own[i] + u * own[i + 1]


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


def _kept_vertices(obj, mesh) -> np.ndarray | None:
    """The evaluated object's vertices where they are as many as the exported ``mesh``'s (Cycles
    keeps no vertex motion for a mesh whose topology changes), else None."""
    v = _vertices(obj)
    return v if v is not None and len(v) == len(mesh.vertices) else None


def _read_once(vertices: dict, mesh_index: int, mesh, obj, k: int, count: int) -> None:
    """The vertices of ``mesh`` at the ``k``-th of ``count`` times, read from the first object found
    using it: the objects and instances sharing a mesh share its evaluated vertices, and Cycles syncs
    a shared geometry's motion once, for all of them."""
    per_time = vertices.setdefault(mesh_index, [None] * count)
    if per_time[k] is None:
        per_time[k] = _kept_vertices(obj, mesh)


def _steps_of(depsgraph, wanted: dict, light_index: dict, camera_name: str):
    """Each wanted instance's, light's and the camera's motion steps (``motion_steps``, at least
    ``long_shutter_steps``) and whether each instance's mesh may deform (its Deformation switch),
    read at the current frame."""
    floor = long_shutter_steps(depsgraph.scene.render.motion_blur_shutter)

    def steps(obj, instancer=None):
        own = motion_steps(obj, instancer)
        return max(own, floor) if own else 0

    inst_steps, deform = np.zeros(len(wanted), np.int64), np.zeros(len(wanted), bool)
    light_steps = np.zeros(len(light_index), np.int64)
    for instance in depsgraph.object_instances:
        key = instance_key(instance)
        obj = instance.object.original
        instancer = instance.parent.original if instance.is_instance and instance.parent else None
        if instance.object.type == "LIGHT" and key in light_index:
            light_steps[light_index[key]] = steps(obj, instancer)
        elif key in wanted:
            inst_steps[wanted[key]] = steps(obj, instancer)
            deform[wanted[key]] = deforms_in_motion(obj)
    cam = depsgraph.objects.get(camera_name)
    camera_steps = steps(cam.original) if cam is not None else 0
    return inst_steps, deform, light_steps, camera_steps


def add_motion(scene_data, depsgraph, frame_set: Callable[[int, float], None], instance_keys: list,
               light_keys: list, camera_name: str) -> None:
    """Fill instance, light and camera matrices over the shutter, and deforming meshes' vertices."""
    scene = depsgraph.scene
    if not scene.render.use_motion_blur:
        return
    wanted = {key: i for i, key in enumerate(instance_keys)}
    light_index = {key: i for i, key in enumerate(light_keys)}
    inst_steps, deform, light_steps, camera_steps = _steps_of(depsgraph, wanted, light_index, camera_name)
    times = shutter_times(scene, max([camera_steps, *inst_steps, *light_steps]))
    if times is None:
        return
    mesh_steps: dict[int, int] = {}  # per mesh that may deform, the most steps an object using it takes
    for i, inst in enumerate(scene_data.instances):
        if deform[i] and inst_steps[i]:
            mesh_steps[inst.mesh] = max(mesh_steps.get(inst.mesh, 0), int(inst_steps[i]))
    steps = len(times)
    matrices = np.repeat(np.stack([inst.matrices[0] for inst in scene_data.instances])[:, None], steps, 1) \
        if scene_data.instances else np.zeros((0, steps, 4, 4))
    seen = np.zeros((len(instance_keys), steps), bool)
    light_matrices = np.repeat(np.stack([light.matrix for light in scene_data.lights])[:, None], steps, 1) \
        if scene_data.lights else np.zeros((0, steps, 4, 4))
    light_seen = np.zeros((len(light_keys), steps), bool)
    vertices: dict[int, list] = {}  # mesh -> its vertices per time
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
                if mesh_index in mesh_steps:
                    _read_once(vertices, mesh_index, scene_data.meshes[mesh_index], instance.object, k, steps)
            cam = depsgraph.objects.get(camera_name)
            if cam is not None:
                camera[k] = without_scale(cam.matrix_world)
    finally:
        frame_set(frame, subframe)
    for i, inst in enumerate(scene_data.instances):
        if seen[i].all() and inst_steps[i]:
            inst.matrices = own_steps(matrices[i], inst_steps[i], _matrices_between)
    if camera_steps:
        scene_data.camera.matrices = own_steps(camera, camera_steps, _matrices_between)
    for j, light in enumerate(scene_data.lights):
        if light_seen[j].all() and light_steps[j] and not np.allclose(light_matrices[j], light_matrices[j][:1]):
            light.matrices = own_steps(light_matrices[j], light_steps[j], _matrices_between)
    for mesh_index, per_step in vertices.items():
        if all(v is not None for v in per_step):
            stack = np.stack(per_step)
            if not np.allclose(stack, stack[:1]):
                scene_data.meshes[mesh_index].motion_vertices = own_steps(stack, mesh_steps[mesh_index],
                                                                          _vertices_between)


def add_motion_pass(scene_data, depsgraph, frame_set: Callable[[int, float], None], instance_keys: list,
                    camera_name: str) -> None:
    """For the Vector pass, each instance's and the camera's transforms at the previous and the next
    frame, and the vertices there of meshes that deform (Cycles' motion for passes: frame -1 and +1
    when motion blur is off; with it on Cycles' pass is 0, and so is DRT's without them). As for
    motion blur, a mesh's vertices are read where an object using it has its Deformation switch on
    and its vertex count stays (Cycles keeps no vertex motion otherwise)."""
    scene = depsgraph.scene
    if not depsgraph.view_layer.use_pass_vector or scene.render.use_motion_blur:
        return
    wanted = {key: i for i, key in enumerate(instance_keys)}
    matrices = np.zeros((len(instance_keys), 2, 4, 4))
    seen = np.zeros((len(instance_keys), 2), bool)
    camera = np.repeat(scene_data.camera.matrix[None], 2, 0)
    vertices: dict[int, list] = {}  # mesh -> its vertices at the previous and the next frame
    frame, subframe = scene.frame_current, scene.frame_subframe
    try:
        for k, step in enumerate((-1, 1)):
            frame_set(frame + step, subframe)
            for instance in depsgraph.object_instances:
                i = wanted.get(instance_key(instance))
                if i is None or instance.object.type == "LIGHT":
                    continue
                matrices[i, k] = np.array(instance.matrix_world, dtype=np.float64)
                seen[i, k] = True
                mesh_index = scene_data.instances[i].mesh
                if deforms_in_motion(instance.object.original):
                    _read_once(vertices, mesh_index, scene_data.meshes[mesh_index], instance.object, k, 2)
            cam = depsgraph.objects.get(camera_name)
            if cam is not None:
                camera[k] = without_scale(cam.matrix_world)
    finally:
        frame_set(frame, subframe)
    for i, inst in enumerate(scene_data.instances):
        if seen[i].all() and not np.allclose(matrices[i], inst.matrix[None]):
            inst.motion_pass = matrices[i]
    if not np.allclose(camera, scene_data.camera.matrix[None]):
        scene_data.camera.motion_pass = camera
    for mesh_index, (pre, post) in vertices.items():
        mesh = scene_data.meshes[mesh_index]
        if pre is not None and post is not None and not (np.allclose(pre, mesh.vertices)
                                                         and np.allclose(post, mesh.vertices)):
            mesh.motion_pass_vertices = np.stack([pre, post])
