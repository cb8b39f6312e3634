"""Anisotropic GGX scenes against Cycles (tests/blender/test_anisotropic_cycles.py, and the
anisotropic rows of bench/node_parity.py): smooth spheres under an area light over a black world."""
from __future__ import annotations

import bpy

from tests.support import procedural_scenes as ps

WIDTH, HEIGHT = 64, 32


def _lit_scene(camera_location):
    """A black world, the camera at ``camera_location`` looking at the origin, and a 3 m area
    light of 150 W above and in front."""
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, camera_location)
    scene.camera.data.lens = 50.0
    ps.black_world(scene)
    light = bpy.data.objects.new("Area", bpy.data.lights.new("Area", "AREA"))
    light.data.energy = 150.0
    light.data.size = 3.0
    ps.aim(light, (1.5, -3.0, 3.0))
    scene.collection.objects.link(light)
    return scene


def anisotropic_scene():
    """The Principled metal (Anisotropic 0.9) and the Glossy (Anisotropy -0.7, Rotation 0.125) spheres."""
    scene = _lit_scene((0.0, -7.0, 1.5))
    metal, _ = ps.closure_material("Brushed", "ShaderNodeBsdfPrincipled", Base_Color=(0.9, 0.7, 0.4, 1.0),
                                   Metallic=1.0, Roughness=0.35, Anisotropic=0.9)
    ps.smooth_sphere("Principled", -1.1, metal)
    glossy, _ = ps.closure_material("Turned", "ShaderNodeBsdfAnisotropic", Color=(0.5, 0.7, 0.9, 1.0),
                                    Roughness=0.4, Anisotropy=-0.7, Rotation=0.125)
    ps.smooth_sphere("Glossy", 1.1, glossy)
    return scene


def textured_scene():
    """A Metallic BSDF sphere (before Blender 5, which has none, a metallic Principled BSDF: the
    same anisotropic alphas) whose anisotropy rises with height (Generated z, a keyed input),
    turned per hit by a Noise texture, along the UV map's tangent (a Tangent node)."""
    scene = _lit_scene((0.0, -5.0, 1.0))
    if hasattr(bpy.types, "ShaderNodeBsdfMetallic"):
        material, node = ps.closure_material("Textured", "ShaderNodeBsdfMetallic", Base_Color=(0.8, 0.8, 0.85, 1.0),
                                              Roughness=0.4)
        anisotropy, rotation = node.inputs["Anisotropy"], node.inputs["Rotation"]
    else:
        material, node = ps.closure_material("Textured", "ShaderNodeBsdfPrincipled", Base_Color=(0.8, 0.8, 0.85, 1.0),
                                              Metallic=1.0, Roughness=0.4)
        anisotropy, rotation = node.inputs["Anisotropic"], node.inputs["Anisotropic Rotation"]
    tree = material.node_tree
    coords = tree.nodes.new("ShaderNodeTexCoord")
    xyz = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(coords.outputs["Generated"], xyz.inputs["Vector"])
    tree.links.new(xyz.outputs["Z"], anisotropy)
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 2.0
    tree.links.new(noise.outputs["Fac"], rotation)
    tangent = tree.nodes.new("ShaderNodeTangent")
    tangent.direction_type = "UV_MAP"
    tree.links.new(tangent.outputs["Tangent"], node.inputs["Tangent"])
    ps.smooth_sphere("Sphere", 0.0, material)
    return scene
