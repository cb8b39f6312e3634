"""Principled's Thin Film against Cycles: three smooth spheres under an area light, a point light
and a grey world, each with a film of IOR 1.33 (Cycles' default), 500 nm thick but on the
dielectric, where a texture sets it from 300 nm at the bottom to 700 nm at the top: a dielectric
(its specular layer over the film, coloured by interference over a dark base), a metal (the film
over the F82-tint metal, Blender 5.0 on) and a glass (reflection and refraction through the film).

Parity as procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles (seed 0) at most
1.5x Cycles' own between seeds 0 and 1, plus 0.002; the same scene with the film left out (as DRT
rendered it before, with a warning) must fail that limit. Measured (64x48 px, 1024 spp, Blender
5.0.1): 0.0212 against a limit of 0.0477 (Cycles' seeds 0.0304; the textured dielectric's third
0.0051 against Cycles' 0.0063), the film left out 0.694; at 256 spp Cycles' own figure is 0.12 (the
metal's highlight), too loose to hold the film to. Before 5.0 Cycles computes the film otherwise
(DRT names it in the warning): skipped there."""
from __future__ import annotations

import bpy
import pytest

from drt_engine.blender.export import materials as export_materials
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

WIDTH, HEIGHT = 64, 48
SAMPLES = 1024
pytestmark = pytest.mark.skipif(bpy.app.version < export_materials.THIN_FILM_MATCHED_FROM,
                                reason="this Blender's Cycles computes the thin film otherwise (named in the warning)")
FILM = {"Thin_Film_Thickness": 500.0, "Thin_Film_IOR": 1.33}



def _thickness_from_height(material, low, high):
    """The Principled's Thin Film Thickness from ``low`` nm at the sphere's bottom to ``high`` at its
    top (Generated z, through a Map Range)."""
    tree = material.node_tree
    z = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["Generated"], z.inputs[0])
    ramp = tree.nodes.new("ShaderNodeMapRange")
    ramp.inputs["To Min"].default_value, ramp.inputs["To Max"].default_value = low, high
    tree.links.new(z.outputs["Z"], ramp.inputs["Value"])
    tree.links.new(ramp.outputs["Result"], tree.nodes["Principled BSDF"].inputs["Thin Film Thickness"])
    return material


def film_scene():
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, (0.0, -9.0, 1.5))
    scene.camera.data.lens = 50.0
    ps.black_world(scene)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.4
    ps.add_light(scene, "Area", "AREA", 200.0, (1.5, -3.0, 3.0), size=2.0)
    ps.add_light(scene, "Point", "POINT", 300.0, (-3.0, -2.5, 1.0))
    principled = "ShaderNodeBsdfPrincipled"
    dielectric, _ = ps.closure_material("Film dielectric", principled, Base_Color=(0.05, 0.05, 0.05, 1.0),
                                        Roughness=0.2, **FILM)
    metal, _ = ps.closure_material("Film metal", principled, Base_Color=(0.9, 0.6, 0.3, 1.0), Metallic=1.0,
                                   Roughness=0.25, **FILM)
    glass, _ = ps.closure_material("Film glass", principled, Base_Color=(0.9, 0.9, 0.9, 1.0), Roughness=0.1,
                                   Transmission_Weight=1.0, **FILM)
    ps.smooth_sphere("Film dielectric", -2.5, _thickness_from_height(dielectric, 300.0, 700.0))
    ps.smooth_sphere("Film metal", 0.0, metal)
    ps.smooth_sphere("Film glass", 2.5, glass)
    return scene


def test_thin_film_matches_cycles(drt, tmp_path, monkeypatch):
    scene = film_scene()
    drt_image, cycles0, cycles1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name="film")
                                   for engine, seed in ps.RUNS]
    figures = ps.parity(drt_image.rgb, cycles0.rgb, cycles1.rgb)
    print("thin film", figures)
    assert figures["ok"], ps.message("thin film", figures)
    monkeypatch.setattr(export_materials, "_thin_film", lambda *args: None)
    bare = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="bare")
    off = ps.parity(bare.rgb, cycles0.rgb, cycles1.rgb)
    print("film left out", off)
    assert not off["ok"], f"the scene with its thin film left out passes too: {off}"
