"""Smooth-shaded rims against Cycles: an 8-sided smooth-shaded cylinder of a Diffuse BSDF under a
high sun, seen from above at an angle. Along its top rim the interpolated normals turn away from
the camera; Cycles shades a diffuse closure about them all the same (core.integrator.hits).

Parity as procedural_scenes.parity. Measured (96x64 px, 128 spp, Blender 5.0): 0.0017 against a
limit of 0.0045; the geometric normal in their place (DRT before) 0.19, the normal raised as for
a glossy closure (the other materials' rule) 0.13 (asserted to fail)."""
from __future__ import annotations

import bpy

from drt_engine.core.bsdf.shader import MaterialShader
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

SAMPLES = 128


def smooth_cylinder():
    scene = ps._scene(96, 64)
    ps.aim(scene.camera, (0.0, -6.0, 4.0))
    scene.camera.data.lens = 40.0
    ps.black_world(scene)
    material, _ = ps.closure_material("Smooth diffuse", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    ps.add_primitive(bpy.ops.mesh.primitive_cylinder_add, material, "Cylinder", vertices=8, radius=1.5,
                     depth=2.0, location=(0.0, 0.0, 1.0))
    bpy.ops.object.shade_smooth()
    sun = bpy.data.objects.new("High sun", bpy.data.lights.new("High sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.05
    ps.aim(sun, (3.0, -2.0, 6.0))
    scene.collection.objects.link(sun)
    return scene


def test_smooth_rim_of_a_diffuse_cylinder(drt, tmp_path, monkeypatch):
    scene = smooth_cylinder()
    drt_image, cycles0, cycles1 = [rh.render(scene, e, SAMPLES, s, tmp_path, name="rim") for e, s in ps.RUNS]
    figures = ps.parity(drt_image.rgb, cycles0.rgb, cycles1.rgb)
    print("smooth rim", figures)
    assert figures["ok"], ps.message("smooth rim", figures)
    monkeypatch.setattr(MaterialShader, "keeps_normal", property(lambda shader: False))
    raised = ps.parity(rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="raised").rgb, cycles0.rgb, cycles1.rgb)
    print("raised", raised)
    assert not raised["ok"], f"DRT passes with the raised normal too: {raised}"
