"""IES Texture cases: a floor lit through the profiles of ies_profiles (and a light through Light
Falloff), for the Cycles parity test."""
from __future__ import annotations

import math
import tempfile
from pathlib import Path

import bpy
import mathutils

from tests.support import procedural_scenes as ps
from tests.support.ies_profiles import ASYMMETRIC, QUADRANT, TYPE_B
from tests.support.datablocks import new_material, with_nodes


def _ies_tree(light, node_mode, source, strength=None, scale=None):
    """The light's node tree: an IES Texture (``node_mode`` INTERNAL with a Text of ``source``,
    EXTERNAL with ``source`` a file path) into its Emission's Strength, through Math Multiply by
    ``scale`` when given; the IES node's Strength ``strength`` when given."""
    with_nodes(light.data)
    tree = light.data.node_tree
    node = tree.nodes.new("ShaderNodeTexIES")
    node.mode = node_mode
    if node_mode == "INTERNAL":
        text = bpy.data.texts.new(f"{light.name}.ies")
        text.write(source)
        node.ies = text
    else:
        node.filepath = source
    if strength is not None:
        node.inputs["Strength"].default_value = strength
    fac = node.outputs["Fac"]
    if scale is not None:
        multiply = tree.nodes.new("ShaderNodeMath")
        multiply.operation = "MULTIPLY"
        tree.links.new(fac, multiply.inputs[0])
        multiply.inputs[1].default_value = scale
        fac = multiply.outputs[0]
    tree.links.new(fac, tree.nodes["Emission"].inputs["Strength"])
    return node


def _light(scene, name, kind, energy, location, rotation, radius=0.0, soft=True):
    light = bpy.data.objects.new(name, bpy.data.lights.new(name, kind))
    light.data.energy = energy
    light.location = location
    light.rotation_euler = rotation
    if kind == "AREA":
        light.data.size = radius
    else:
        light.data.shadow_soft_size = radius
        light.data.use_soft_falloff = soft
    scene.collection.objects.link(light)
    return light


def _ies_emitter(name, text):
    """A material emitting by an IES Texture on the object's normals (its Vector unlinked)."""
    material = new_material(name)
    tree = material.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    emission = tree.nodes.new("ShaderNodeEmission")
    node = tree.nodes.new("ShaderNodeTexIES")
    node.mode = "INTERNAL"
    node.ies = bpy.data.texts.new(f"{name}.ies")
    node.ies.write(text)
    node.inputs["Strength"].default_value = 0.05
    tree.links.new(node.outputs["Fac"], emission.inputs["Strength"])
    tree.links.new(emission.outputs[0], out.inputs["Surface"])
    return material


def ies_scene(size=48):
    """A white floor seen from above under a black world, lit through IES profiles: a point light
    tilted and turned (the asymmetric profile, a Text), a spot light with a soft radius (the quadrant
    profile from a file, the node's Strength 2), a sphere light without soft falloff (type B), an
    area light (the asymmetric profile through Math Multiply), a point light whose strength is Light
    Falloff's Linear output and an emissive sphere whose material's IES Texture has its default Vector."""
    scene = ps.dark_scene(size, (0.0, -5.0, 6.5), 24.0, False)
    scene.render.resolution_x, scene.render.resolution_y = 2 * size, size
    floor = bpy.data.meshes.new("Floor")
    floor.from_pydata([(-8, -6, 0), (8, -6, 0), (8, 6, 0), (-8, 6, 0)], [], [(0, 1, 2, 3)])
    floor.materials.append(ps.closure_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))[0])
    scene.collection.objects.link(bpy.data.objects.new("Floor", floor))
    tilted = _light(scene, "IES point", "POINT", 0.4, (-3.0, 0.5, 1.2), (0.35, -0.2, 0.7))
    _ies_tree(tilted, "INTERNAL", ASYMMETRIC)
    path = Path(tempfile.mkdtemp(prefix="drt-ies-")) / "quadrant.ies"
    path.write_text(QUADRANT)
    spot = _light(scene, "IES spot", "SPOT", 0.3, (0.0, 1.2, 1.4), (0.0, 0.0, 0.4), radius=0.1)
    spot.data.spot_size = math.radians(120.0)
    _ies_tree(spot, "EXTERNAL", str(path), strength=2.0)
    sphere = _light(scene, "IES sphere", "POINT", 0.5, (3.0, 0.3, 1.0), (0.0, 0.0, -0.5), radius=0.15, soft=False)
    _ies_tree(sphere, "INTERNAL", TYPE_B)
    area = _light(scene, "IES area", "AREA", 2.0, (0.0, -1.8, 1.3), (0.0, 0.0, 0.0), radius=0.4)
    _ies_tree(area, "INTERNAL", ASYMMETRIC, scale=0.5)
    falloff = _light(scene, "Falloff point", "POINT", 3.0, (-1.2, -1.5, 0.8), (0.0, 0.0, 0.0))
    with_nodes(falloff.data)
    tree = falloff.data.node_tree
    node = tree.nodes.new("ShaderNodeLightFalloff")
    node.inputs["Strength"].default_value, node.inputs["Smooth"].default_value = 0.6, 0.5
    tree.links.new(node.outputs["Linear"], tree.nodes["Emission"].inputs["Strength"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(1.5, -1.0, 0.6), segments=32, ring_count=16,
                                         rotation=mathutils.Euler((0.4, 0.0, 0.3)))
    bpy.context.active_object.data.materials.append(_ies_emitter("IES glow", ASYMMETRIC))
    return scene


CASES = {"point light, turned (type C, whole circle)": "IES point",
         "spot light with a radius (type C quadrant, a file)": "IES spot",
         "sphere light (type B)": "IES sphere",
         "area light (through Math Multiply)": "IES area",
         "material of an emissive sphere": "Sphere"}
"""IES parity cases: label -> the one emitter of ``ies_scene`` left to light the floor."""
FALLOFF = "Falloff point"
"""The light of ``ies_scene`` whose strength is Light Falloff's (no IES Texture)."""


def lit_by(name: str, size=48):
    """``ies_scene`` with every emitter but the object ``name`` hidden from the render."""
    scene = ies_scene(size)
    for obj in scene.objects:
        if obj.type == "LIGHT" or obj.name.startswith("Sphere"):
            obj.hide_render = obj.name != name
    return scene
