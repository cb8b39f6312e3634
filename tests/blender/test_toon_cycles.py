"""The Toon BSDF against Cycles: two smooth spheres under an area light and a point light, one a
diffuse toon (Size from a texture, 0.3 on its lower half and 0.6 on its upper, Smooth 0.1: lit flat
out to 27 or 54 degrees from the light, fading to dark 9 degrees further), one a glossy toon (Size
0.15, Smooth 0.1: flat highlights about the lights' mirror directions, and the diffuse toon sphere
seen in it through glossy rays); and with diffuse bounces 2 over a grey floor.

Parity as procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles (seed 0) at most
1.5x Cycles' own between seeds 0 and 1, plus 0.002; the same scene with the Toon BSDF left out
(rendered default grey, as before DRT had it) must fail that limit, and so must DRT without the
diffuse bounces. Measured (64x32 px, 256 spp): 0.0276 against a limit of 0.0415 (Cycles' seeds
0.0264), left grey 1.097; with diffuse bounces 2 over the floor 0.0276 against 0.0416, without
them 0.668 (the diffuse toon sphere's underside, lit by the floor through its cone)."""
from __future__ import annotations

import bpy

from drt_engine.blender.export import materials as export_materials
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

WIDTH, HEIGHT = 64, 32
SAMPLES = 256


def _toon_material(name, component, colour, size, smooth):
    material, toon = ps.closure_material(name, "ShaderNodeBsdfToon", Color=colour, Size=size, Smooth=smooth)
    toon.component = component
    return material


def _stepped_size(material):
    """The toon's Size from a texture: 0.3 on the sphere's lower half, 0.6 on its upper (Generated z)."""
    tree = material.node_tree
    toon = tree.nodes["Toon BSDF"]
    z = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["Generated"], z.inputs[0])
    step = tree.nodes.new("ShaderNodeMath")
    step.operation = "GREATER_THAN"
    step.inputs[1].default_value = 0.5
    tree.links.new(z.outputs["Z"], step.inputs[0])
    size = tree.nodes.new("ShaderNodeMath")
    size.operation = "MULTIPLY_ADD"
    size.inputs[1].default_value = 0.3
    size.inputs[2].default_value = 0.3
    tree.links.new(step.outputs[0], size.inputs[0])
    tree.links.new(size.outputs[0], toon.inputs["Size"])
    return material



def _floor():
    """A 20 m grey Diffuse floor under the spheres, which lights them from below through diffuse bounces."""
    material, _ = ps.closure_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, -1.0))
    bpy.context.active_object.data.materials.append(material)


def toon_scene(floor=False):
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    ps.add_light(scene, "Area", "AREA", 150.0, (1.5, -3.0, 3.0), size=2.0)
    ps.add_light(scene, "Point", "POINT", 400.0, (-3.0, -2.5, 1.0))
    ps.smooth_sphere("Diffuse toon", -1.1,
                     _stepped_size(_toon_material("Diffuse toon", "DIFFUSE", (0.9, 0.6, 0.3, 1.0), 0.5, 0.1)))
    ps.smooth_sphere("Glossy toon", 1.1, _toon_material("Glossy toon", "GLOSSY", (0.6, 0.8, 0.9, 1.0), 0.15, 0.1))
    if floor:
        _floor()
    return scene



def test_toon_bsdf_matches_cycles(drt, tmp_path, monkeypatch):
    scene = toon_scene()
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, "toon")
    monkeypatch.delitem(export_materials.CLOSURE_NODES, "ShaderNodeBsdfToon")
    grey = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="grey")
    off = ps.parity(grey.rgb, cycles0.rgb, cycles1.rgb)
    print("left grey", off)
    assert not off["ok"], f"the Toon BSDF left grey passes too: {off}"


def test_toon_bsdf_with_diffuse_bounces_matches_cycles(drt, tmp_path):
    """With diffuse bounces on, paths continue through the diffuse toon too (sampled in its cone):
    over a grey floor that lights the spheres from below; without the bounces DRT must fail."""
    scene = toon_scene(floor=True)
    scene.drt.diffuse_bounces = 2
    cycles0, cycles1 = ps.assert_parity(scene, SAMPLES, tmp_path, "toon-bounces")
    scene.drt.diffuse_bounces = 0
    direct = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="direct")
    off = ps.parity(direct.rgb, cycles0.rgb, cycles1.rgb)
    print("without diffuse bounces", off)
    assert not off["ok"], f"the render without diffuse bounces passes too: {off}"
