"""Principled's Coat Normal scene against Cycles (tests/blender/test_coat_normal_cycles.py, and the
Coat Normal row of bench/node_parity.py): two smooth coated spheres, the left one's coat normal a
Bump of wave bands (its base on the sphere's normal), the right one's base normal a Bump of noise
and its coat normal an object-space Normal Map tilted sideways."""
from __future__ import annotations

from tests.support import procedural_scenes as ps

WIDTH, HEIGHT = 64, 32


def _coated(name, colour):
    material, node = ps.closure_material(name, "ShaderNodeBsdfPrincipled", Base_Color=colour, Roughness=0.6,
                                         Coat_Weight=1.0, Coat_Roughness=0.15)
    return material, node


def _bump(tree, height, strength=1.0, distance=0.2):
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = strength
    bump.inputs["Distance"].default_value = distance
    tree.links.new(height, bump.inputs["Height"])
    return bump.outputs["Normal"]


def _banded_coat():
    """The coat normal a Bump of wave bands across the sphere, the base on the sphere's normal."""
    material, node = _coated("Banded coat", (0.05, 0.08, 0.25, 1.0))
    tree = material.node_tree
    wave = tree.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 2.0
    tree.links.new(_bump(tree, wave.outputs["Fac"]), node.inputs["Coat Normal"])
    return material


def _tilted_coat():
    """The base normal a Bump of noise, the coat normal an object-space Normal Map tilted along x."""
    material, node = _coated("Tilted coat", (0.25, 0.06, 0.03, 1.0))
    tree = material.node_tree
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 6.0
    tree.links.new(_bump(tree, noise.outputs["Fac"], strength=0.6), node.inputs["Normal"])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    normal_map.space = "OBJECT"
    normal_map.inputs["Color"].default_value = (0.85, 0.35, 0.75, 1.0)
    normal_map.inputs["Strength"].default_value = 0.7
    tree.links.new(normal_map.outputs["Normal"], node.inputs["Coat Normal"])
    return material


def coat_normal_scene():
    """The two coated spheres under an area light and a point light over a black world."""
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    ps.add_light(scene, "Area", "AREA", 200.0, (1.5, -3.0, 3.0), size=1.5)
    ps.add_light(scene, "Point", "POINT", 300.0, (-3.0, -2.5, 1.0))
    ps.smooth_sphere("Banded", -1.1, _banded_coat())
    ps.smooth_sphere("Tilted", 1.1, _tilted_coat())
    return scene
