"""Holdouts against Cycles on a scene built for them: a ground lit by an area light and a sun; on
it a sphere whose object is a holdout (a hole where the camera sees it, but for the 0.4 its
Principled Alpha lets through to the ground; its shadow on the ground and its reflection in a
mirror behind it as Cycles renders them), and a quad mixing a Holdout with
a red Diffuse BSDF by a checker (0.25 and 0.75 held out). Compared on RGBA with Film Transparent
on and off (Cycles takes the holdouts' share of alpha either way). The rule is
procedural_scenes.parity's: DRT's worst 4x4-block difference from Cycles seed 0 within 1.5x
Cycles' own seed-0-against-seed-1 worst plus 0.002. Measured (48 x 48, 128 samples): worst block
0.0210, limit 0.0343 (Cycles' seeds 0.0216), Film Transparent on and off (alpha alone 0.0073 and
0.0049); without holdouts 0.897; with the sphere held out whole (its Alpha ignored) 0.142."""
from __future__ import annotations

import bpy
import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.blender_scenes import add_light
from tests.support.datablocks import new_material

SIZE = 48
SAMPLES = 128


def _material(name, *nodes):
    """A material of one closure node (``nodes[0]``, by type) or a checker's mix of two."""
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    made = [tree.nodes.new(kind) for kind in nodes]
    for node in made:
        if "Color" in node.inputs:
            node.inputs["Color"].default_value = (0.8, 0.15, 0.1, 1.0)
        if "Roughness" in node.inputs:
            node.inputs["Roughness"].default_value = 0.0
    shader = made[0].outputs[0]
    if len(made) == 2:
        checker = tree.nodes.new("ShaderNodeTexChecker")
        checker.inputs["Scale"].default_value = 3.0
        checker.inputs["Color1"].default_value = (0.75, 0.75, 0.75, 1.0)
        checker.inputs["Color2"].default_value = (0.25, 0.25, 0.25, 1.0)
        mix = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(checker.outputs["Fac"], mix.inputs["Fac"])
        tree.links.new(made[0].outputs[0], mix.inputs[1])
        tree.links.new(made[1].outputs[0], mix.inputs[2])
        shader = mix.outputs["Shader"]
    tree.links.new(shader, tree.nodes["Material Output"].inputs["Surface"])
    return mat


def _placed(obj, name, mat):
    obj.name = name
    obj.data.materials.append(mat)
    return obj


def holdout_scene(transparent: bool):
    scene = ps.dark_scene(SIZE, (0.0, -6.0, 4.0), 35.0, transparent)
    ground = new_material("Ground")
    ground.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    bpy.ops.mesh.primitive_plane_add(size=5.0)
    _placed(bpy.context.active_object, "Ground", ground)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(-0.6, 0.0, 0.6))
    held = new_material("Held")
    held.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.6
    sphere = _placed(bpy.context.active_object, "Held", held)
    sphere.is_holdout = True
    bpy.ops.mesh.primitive_plane_add(size=1.4, location=(1.0, -0.6, 0.9), rotation=(1.2, 0.0, 0.2))
    _placed(bpy.context.active_object, "Mixed", _material("Mixed", "ShaderNodeHoldout", "ShaderNodeBsdfDiffuse"))
    bpy.ops.mesh.primitive_plane_add(size=2.5, location=(-0.4, 1.6, 1.0), rotation=(1.5708, 0.0, 0.0))
    _placed(bpy.context.active_object, "Mirror", _material("Mirror", "ShaderNodeBsdfGlossy"))
    add_light(scene, "AREA", location=(1.0, -2.0, 4.0), energy=200.0, size=1.0)
    add_light(scene, "SUN", rotation=(0.5, -0.4, 0.0), energy=1.5)
    return scene


@pytest.mark.parametrize("transparent", [True, False])
def test_holdouts_match_cycles(drt, tmp_path, transparent):
    scene = holdout_scene(transparent)
    image, cycles0, cycles1 = (rh.render(scene, engine, SAMPLES, seed, tmp_path, name="holdout").passes["Combined"]
                               for engine, seed in ps.RUNS)
    alpha = cycles0[..., 3]
    assert (alpha < 0.3).mean() > 0.01 and ((alpha > 0.3) & (alpha < 0.8)).mean() > 0.01  # holdouts seen
    figures = ps.parity(image, cycles0, cycles1)
    assert figures["ok"], ps.message(f"holdouts, Film Transparent {transparent} (RGBA)", figures)
