"""Export a scene through a real render depsgraph (render visibility, render levels).

A throwaway RenderEngine runs ``export_scene`` inside ``bpy.ops.render.render``, so
tests see exactly the depsgraph a render engine gets, without the DRT engine.
"""
from __future__ import annotations

import bpy
import numpy as np

from drt_engine.blender.export import export_scene


class ExportCaptureEngine(bpy.types.RenderEngine):
    bl_idname = "DRT_EXPORT_CAPTURE"
    bl_label = "DRT export capture"
    bl_use_shading_nodes_custom = False
    captured: list = []
    motion = False  # sample the shutter as a render does (the engine's frame_set)

    def render(self, depsgraph):
        try:
            self.captured.append(export_scene(depsgraph, frame_set=self.frame_set if self.motion else None))
        except Exception as error:  # handed back to the test, which re-raises it
            self.captured.append(error)


def render_export(scene=None, motion=False):
    """SceneData exported from the render depsgraph of ``scene`` (default: the context scene);
    ``motion``: with its motion over the shutter."""
    ExportCaptureEngine.motion = motion
    if not ExportCaptureEngine.is_registered:
        bpy.utils.register_class(ExportCaptureEngine)
    scene = scene or bpy.context.scene
    scene.render.engine = ExportCaptureEngine.bl_idname
    ExportCaptureEngine.captured.clear()
    bpy.ops.render.render(scene=scene.name)
    result = ExportCaptureEngine.captured.pop()
    if isinstance(result, Exception):
        raise result
    return result


def empty_scene(width=8, height=8):
    """Factory-empty scene with a camera at +Z looking down, tiny resolution."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, 0.0, 10.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def add_object(scene, name, data, location=(0.0, 0.0, 0.0)):
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def cube_mesh(name="Cube"):
    """A unit-half-size cube mesh: 8 vertices, 6 quads."""
    verts = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    return mesh


def world_triangles(data, instance):
    """World-space triangle corners (T, 3, 3) of one exported instance."""
    mesh = data.meshes[instance.mesh]
    corners = mesh.vertices[mesh.triangles]
    m = instance.matrix
    return corners @ m[:3, :3].T + m[:3, 3]


def total_area(data):
    area = 0.0
    for inst in data.instances:
        t = world_triangles(data, inst)
        area += 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    return area
