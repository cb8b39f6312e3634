"""Transparent shadows against Cycles on a scene built for them: a ground lit by an area light and a
sun, above it two quads that let light through, one a Principled BSDF whose Alpha a checker
texture sets (0.25 and 0.75), one a Mix Shader of a tinted Transparent BSDF and a Diffuse BSDF,
each casting a partial, coloured shadow; one quad reaches past the ground's edge and the film is
transparent, so alpha is compared too. The rule is procedural_scenes.parity's on RGBA: DRT's worst
4x4-block difference from Cycles seed 0 within 1.5x Cycles' own seed-0-against-seed-1 worst plus
0.002. Measured (48 x 48, 128 samples): worst block 0.0053, limit 0.0125 (Cycles' seeds 0.0070);
with shadow rays that stop at every surface 0.3284; before the MIS state was kept through
transparent pass-throughs (light through the quads counted by both strategies), 0.0255 against
0.0249 with the lights 2.7 and 2 times as strong."""
from __future__ import annotations

import bpy
import numpy as np

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.blender_scenes import add_light
from tests.support.datablocks import new_material

SIZE = 48
SAMPLES = 128


def _quad(name, mat, location, size, rotation=(0.0, 0.0, 0.0)):
    return ps.add_primitive(bpy.ops.mesh.primitive_plane_add, mat, name, size=size, location=location,
                            rotation=rotation)


def _checker_alpha():
    """A Principled BSDF whose Alpha is 0.25 + 0.5 x a checker's Fac."""
    mat = new_material("Checker alpha")
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.2, 0.7, 0.3, 1.0)
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 3.0
    ramp = tree.nodes.new("ShaderNodeMath")
    ramp.operation = "MULTIPLY_ADD"
    ramp.inputs[1].default_value, ramp.inputs[2].default_value = 0.5, 0.25
    tree.links.new(checker.outputs["Fac"], ramp.inputs[0])
    tree.links.new(ramp.outputs["Value"], bsdf.inputs["Alpha"])
    return mat


def _tinted_mix():
    """Half a Transparent BSDF tinted orange, half a blue Diffuse BSDF."""
    mat = new_material("Tinted mix")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    clear = tree.nodes.new("ShaderNodeBsdfTransparent")
    clear.inputs["Color"].default_value = (0.9, 0.5, 0.2, 1.0)
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.3, 0.3, 0.8, 1.0)
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.5
    tree.links.new(clear.outputs["BSDF"], mix.inputs[1])
    tree.links.new(diffuse.outputs["BSDF"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], tree.nodes["Material Output"].inputs["Surface"])
    return mat


def shadow_scene():
    scene = ps.dark_scene(SIZE, (0.0, -6.0, 5.0), 40.0, True)
    ground = new_material("Ground")
    ground.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    ground.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    _quad("Ground", ground, (0.0, 0.0, 0.0), 4.0)
    _quad("Checker", _checker_alpha(), (-0.9, 0.2, 1.0), 1.6, (0.2, 0.0, 0.0))
    _quad("Tinted", _tinted_mix(), (1.3, 1.2, 0.8), 1.6, (0.0, 0.3, 0.0))
    add_light(scene, "AREA", location=(0.5, -0.5, 4.0), energy=150.0, size=1.0)
    add_light(scene, "SUN", rotation=(0.4, -0.3, 0.0), energy=1.0)
    return scene


def test_transparent_shadows_match_cycles(drt, tmp_path):
    scene = shadow_scene()
    image, cycles0, cycles1 = (rh.render(scene, engine, SAMPLES, seed, tmp_path, name="shadows").passes["Combined"]
                               for engine, seed in ps.RUNS)
    assert np.ptp(cycles0[..., 3]) > 0.3  # the ground's edge and a quad past it: alpha varies
    figures = ps.parity(image, cycles0, cycles1)
    assert figures["ok"], ps.message("transparent shadows (RGBA)", figures)
