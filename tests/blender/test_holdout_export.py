"""Holdouts as exported: an object's Holdout or its view layer's holdout collection makes its
instance a holdout (an instance takes its instancer's, as Cycles' sync_object), and the Holdout
shader node is a HOLDOUT closure of its Mix Shader weight, neither named in a warning."""
from __future__ import annotations

import bpy
import numpy as np

from tests.support.datablocks import new_material
from tests.support.export_helpers import add_object, cube_mesh, empty_scene, render_export


def test_objects_held_out_by_their_holdout_or_their_collection():
    scene = empty_scene()
    held = add_object(scene, "Held", cube_mesh("Held"))
    held.is_holdout = True
    add_object(scene, "Plain", cube_mesh("Plain"), location=(3.0, 0.0, 0.0))
    masked = bpy.data.collections.new("Masked")
    scene.collection.children.link(masked)
    inside = bpy.data.objects.new("Inside", cube_mesh("Inside"))
    masked.objects.link(inside)
    bpy.context.view_layer.layer_collection.children["Masked"].holdout = True
    instancer = add_object(scene, "Instancer", None, location=(0.0, 4.0, 0.0))
    instancer.instance_type, instancer.instance_collection = "COLLECTION", masked
    data = render_export(scene)
    holdout = sorted((i.name, i.holdout) for i in data.instances)
    # "Inside" itself, and its instance, which takes its instancer's (not held out)
    assert holdout == [("Held", True), ("Inside", False), ("Inside", True), ("Plain", False)], holdout
    assert not data.warnings, data.warnings


def test_the_holdout_node_is_a_holdout_closure():
    scene = empty_scene()
    mat = new_material("Half held")
    tree = mat.node_tree
    holdout, mix = tree.nodes.new("ShaderNodeHoldout"), tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.25
    tree.links.new(holdout.outputs[0], mix.inputs[1])
    tree.links.new(tree.nodes["Principled BSDF"].outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    cube = add_object(scene, "Cube", cube_mesh())
    cube.data.materials.append(mat)
    data = render_export(scene)
    (material,) = [m for m in data.materials if m.name == "Half held"]
    kinds = {c.kind: c.weight for c in material.closures}
    assert np.allclose(kinds["HOLDOUT"], 0.75) and np.allclose(kinds["PRINCIPLED"], 0.25), kinds
    assert not data.warnings, data.warnings
