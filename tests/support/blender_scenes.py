"""Scenes built in bpy for the numerics cases, rendered by DRT through ``bpy.ops.render.render``.

``render`` turns on every pass, writes a multilayer EXR, reads every channel back and
asserts it is finite; it returns pass name -> (h, w, C) with the top row first.
"""
from __future__ import annotations

from pathlib import Path

import bpy
import numpy as np

from tests.support import render_helpers as rh
from tests.support.datablocks import new_material
from drt_engine.blender.properties import BLENDER_PASS_TOGGLES, DRT_PASS_TOGGLES
from drt_engine.core.settings import PASS_CHANNELS

LAYER = "ViewLayer"


def new_scene(width=8, height=8, samples=4, lens=50.0):
    """Factory-empty scene rendered by DRT, black world, camera at the origin looking down -Z."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rh.set_resolution(scene, width, height)
    scene.render.engine = "DRT"
    scene.drt.samples = samples
    scene.drt.use_adaptive_sampling = False
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = lens
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("World")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def set_world(scene, strength):
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = strength


def material(kind="DIFFUSE", color=None, strength=1.0, name=None, **inputs):
    """A one-node material: 'DIFFUSE' (Diffuse BSDF), 'EMISSION', 'GLOSSY' or 'GLASS'.

    Colour 0.8 grey by default, white for emission (radiance = strength)."""
    color = color or ((1.0, 1.0, 1.0) if kind == "EMISSION" else (0.8, 0.8, 0.8))
    node_type = {"DIFFUSE": "ShaderNodeBsdfDiffuse", "EMISSION": "ShaderNodeEmission",
                 "GLOSSY": "ShaderNodeBsdfAnisotropic", "GLASS": "ShaderNodeBsdfGlass"}[kind]
    mat = new_material(name or kind.title())
    tree = mat.node_tree
    tree.nodes.clear()
    node = tree.nodes.new(node_type)
    node.inputs["Color"].default_value = (*color, 1.0)
    if kind == "EMISSION":
        node.inputs["Strength"].default_value = strength
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def add_mesh(scene, name, verts, faces, location=(0, 0, 0), mat=None, smooth=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    mesh.update()
    if smooth:
        mesh.shade_smooth()
    if mat is not None:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def mesh_from_arrays(scene, name, vertices, triangles, mat=None):
    """A triangle mesh object from NumPy arrays (fast for millions of faces, unlike from_pydata)."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", np.asarray(vertices, np.float32).ravel())
    mesh.loops.add(3 * len(triangles))
    mesh.loops.foreach_set("vertex_index", np.asarray(triangles, np.int32).ravel())
    mesh.polygons.add(len(triangles))
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(triangles), 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    if mat is not None:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def add_plane(scene, name="Plane", half=1.0, location=(0, 0, 0), mat=None):
    h = half
    return add_mesh(scene, name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)], location, mat)


def cube(scene, name="Cube", half=1.0, location=(0, 0, 0), mat=None):
    """A closed cube, faces wound outward."""
    v = [(x * half, y * half, z * half) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return add_mesh(scene, name, v, faces, location, mat)


def add_light(scene, kind, location=(0, 0, 0), rotation=(0, 0, 0), energy=10.0, name=None, **props):
    data = bpy.data.lights.new(name or kind.title(), kind)
    data.energy = energy
    for key, value in props.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(data.name, data)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


def render(scene, out_dir, name="render") -> dict:
    """Every pass of a DRT render, each checked finite: name -> (h, w, C), top row first."""
    layer = scene.view_layers[LAYER]
    for toggle in BLENDER_PASS_TOGGLES.values():
        setattr(layer, toggle, True)
    for toggle in DRT_PASS_TOGGLES.values():
        setattr(layer.drt, toggle, True)
    path = rh.set_exr_output(scene, Path(out_dir) / f"{name}.exr")
    assert bpy.ops.render.render(write_still=True, scene=scene.name) == {"FINISHED"}
    channels = rh.read_channels(path)
    for key, pixels in channels.items():
        assert np.isfinite(pixels).all(), f"channel {key} has non-finite pixels"
    out = {}
    for pass_name, ids in PASS_CHANNELS.items():
        keys = [f"{LAYER}.{pass_name}.{c}" for c in ids]
        if all(k in channels for k in keys):
            out[pass_name] = np.stack([channels[k] for k in keys], axis=-1)
    assert "Combined" in out and "Depth" in out, sorted(channels)
    return out


def render_error(scene) -> str:
    """The one-line error report of a render that must fail (no traceback, Blender's report)."""
    try:
        bpy.ops.render.render(scene=scene.name)
    except RuntimeError as error:
        message = str(error).strip()
        assert len(message.splitlines()) == 1, message
        return message
    raise AssertionError("the render did not fail")
