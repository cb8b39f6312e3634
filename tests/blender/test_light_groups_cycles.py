"""Light groups against Cycles: a floor and a sphere lit by a red area light (group "warm"), a blue
point light (group "cool"), an emissive box (group "glow") and a lit world in no group. Each
``Combined_<group>`` pass DRT writes is within the node parity's limit (procedural_scenes.parity:
the worst 4x4-block difference from Cycles seed 0 at most 1.5x Cycles' own between seeds 0 and 1,
plus 0.002) of Cycles' pass of that name, and so is Combined; a group pass that ignored its group
(empty, or the whole Combined) is far off it. Where every emitter is in a group, DRT's groups sum
to its Combined (tests/core/test_light_groups.py)."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world

WIDTH, HEIGHT = 64, 48
SAMPLES = 64
GROUPS = ("warm", "cool", "glow")


def _emission(name, color, strength):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new("ShaderNodeEmission")
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Strength"].default_value = strength
    tree.links.new(node.outputs["Emission"], tree.nodes["Material Output"].inputs["Surface"])
    return mat


def _diffuse(name, color, roughness=0.5, metallic=0.0):
    mat = new_material(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    return mat


def groups_scene():
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, (0.0, -7.0, 4.0))
    scene.camera.data.lens = 35.0
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.3, 0.35, 0.5, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.3
    scene.world = world  # in no group
    layer = scene.view_layers[0]
    for name in GROUPS:
        layer.lightgroups.add(name=name)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, _diffuse("Floor", (0.6, 0.6, 0.6)), "Floor", size=20.0)
    ps.add_primitive(bpy.ops.mesh.primitive_uv_sphere_add, _diffuse("Ball", (0.8, 0.8, 0.8), 0.3, 1.0), "Ball",
                     radius=1.0, location=(0.6, 0.5, 1.0), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    glow = ps.add_primitive(bpy.ops.mesh.primitive_cube_add, _emission("Glow", (1.0, 0.8, 0.2), 4.0), "Glow",
                            size=0.6, location=(-1.6, -0.5, 0.3))
    glow.lightgroup = "glow"
    ps.add_light(scene, "Warm", "AREA", 300.0, (3.0, -2.0, 4.0), size=1.5, color=(1.0, 0.3, 0.1)).lightgroup = "warm"
    ps.add_light(scene, "Cool", "POINT", 400.0, (-3.0, 1.0, 3.5), color=(0.1, 0.4, 1.0), radius=0.3).lightgroup = "cool"
    return scene


@pytest.fixture(scope="module")
def renders(drt, tmp_path_factory):
    """DRT seed 0, Cycles seeds 0 and 1 (procedural_scenes.RUNS) of the scene."""
    out = tmp_path_factory.mktemp("light_groups")
    scene = groups_scene()
    return [rh.render(scene, engine, SAMPLES, seed, out, name="light_groups") for engine, seed in ps.RUNS]


@pytest.mark.parametrize("group", GROUPS)
def test_each_group_pass_matches_cycles(renders, group):
    drt, cycles0, cycles1 = renders
    name = f"Combined_{group}"
    figures = ps.parity(drt.passes[name], cycles0.passes[name], cycles1.passes[name])
    print(name, figures)
    assert figures["ok"], ps.message(name, figures)
    # the feature off: an empty group pass, or one holding all of Combined, is far from Cycles'
    empty = ps.worst_block(np.zeros_like(cycles0.passes[name]), cycles0.passes[name])
    whole = ps.worst_block(drt.rgb, cycles0.passes[name])
    print(name, "empty", empty, "whole Combined", whole)
    assert min(empty, whole) > 3.0 * figures["limit"]


def test_combined_matches_cycles_and_holds_the_ungrouped_world(renders):
    """Combined within the limit, and more than its groups: the world is in none."""
    drt, cycles0, cycles1 = renders
    figures = ps.parity(drt.rgb, cycles0.rgb, cycles1.rgb)
    print("Combined", figures)
    assert figures["ok"], ps.message("Combined", figures)
    rest = drt.rgb - sum(drt.passes[f"Combined_{g}"] for g in GROUPS)
    cycles_rest = cycles0.rgb - sum(cycles0.passes[f"Combined_{g}"] for g in GROUPS)
    assert rest.mean() > 0.01 and abs(rest.mean() - cycles_rest.mean()) < 0.1 * cycles_rest.mean()
