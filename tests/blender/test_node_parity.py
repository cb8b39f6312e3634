"""Converter, colour and vector nodes, Fresnel and Layer Weight in DRT against Cycles: every node
and mode of tests/support/node_scenes.CASES as a tile of one emissive grid, and Fresnel and Layer
Weight as the colour of diffuse spheres seen at every angle, from the front and the back; Object
Info, a Wireframe in pixels, the material's Displacement (as bump), Light Path (on a mirror floor,
through glass and a transparent sheet), a Sky Texture world lighting a sphere on the ground, and
closures (Toon, Metallic, Principled Thin Film, Oren-Nayar, Translucent) under suns in scenes of their own.
The rule is the procedural textures' (procedural_scenes.parity):
DRT's worst 4x4-block difference from Cycles (seed 0) at most 1.5x Cycles' own between seeds 0 and
1, plus 0.002. Export is checked to evaluate every case without a warning, while a node DRT still
leaves out keeps its one warning.
"""
from __future__ import annotations

from dataclasses import replace

import bpy
import numpy as np
import pytest

from tests.support import node_scenes as ns
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support import sky_scenes
from tests.support.datablocks import new_material
from drt_engine.blender.export.materials import OREN_NAYAR_MATCHED_FROM, VERSION_BUMP, VERSION_OREN_NAYAR
from drt_engine.blender.export.shader_graph import (DISPLACEMENT_MATCHED_FROM, FALLOFF_WORLD_MATCHED_FROM,
                                                   VERSION_FALLOFF_WORLD)
from tests.support.export_helpers import render_export


@pytest.fixture(scope="module")
def grid(drt, tmp_path_factory):
    """Tiles of DRT seed 0, Cycles seeds 0 and 1, per case."""
    return ps.grid_tiles(ns.grid_scene(), len(ns.CASES), tmp_path_factory.mktemp("nodes"), "nodes")


def _cannot(data):
    return [w for w in data.warnings if "cannot evaluate" in w]


def _matches_cycles(scene, out, name, label):
    """Export ``scene`` without a warning, render it with DRT and Cycles (two seeds) and hold DRT
    to the parity rule over the whole image; DRT's render."""
    assert not _cannot(render_export(scene))
    drt_render, c0, c1 = ps.parity_renders(scene, out, name)
    rh.save_side_by_side(name, drt_render.rgb, c0.rgb)
    figures = ps.parity(drt_render.rgb, c0.rgb, c1.rgb)
    assert figures["ok"], ps.message(label, figures)
    return drt_render


def test_every_case_exports_without_a_warning(drt):
    assert not _cannot(render_export(ns.grid_scene()))
    assert not _cannot(render_export(ns.facing_scene()))


def test_a_node_left_out_keeps_its_one_warning(drt):
    """Point Info still has no handler: the socket it feeds keeps its value, with one warning naming it."""
    scene = ns.grid_scene(ns.CASES[:1])
    mat = new_material("Point Info")  # Point Info -> Fresnel's IOR -> Principled roughness
    tree = mat.node_tree
    info = tree.nodes.new("ShaderNodePointInfo")
    fresnel = tree.nodes.new("ShaderNodeFresnel")
    tree.links.new(info.outputs["Radius"], fresnel.inputs["IOR"])
    tree.links.new(fresnel.outputs[0], tree.nodes["Principled BSDF"].inputs["Roughness"])
    scene.objects[ns.CASES[0].name].data.materials[0] = mat
    warnings = _cannot(render_export(scene))
    assert len(warnings) == 1 and "Point Info" in warnings[0] and "Fresnel" not in warnings[0], warnings


@pytest.mark.parametrize("index", range(len(ns.CASES)), ids=[c.name for c in ns.CASES])
def test_node_matches_cycles(grid, index):
    figures = ps.tile_figures(grid, index)
    assert figures["ok"], ps.message(ns.CASES[index].name, figures)


def test_fresnel_and_layer_weight_on_spheres_match_cycles(drt, tmp_path):
    scene = ns.facing_scene()
    drt_render, c0, c1 = ps.parity_renders(scene, tmp_path, "facing")
    rh.save_side_by_side("fresnel-layer-weight", drt_render.rgb, c0.rgb)
    for name, side, part in ns.facing_parts(c0.rgb.shape[0] // 2):
        figures = ps.parity(drt_render.rgb[part], c0.rgb[part], c1.rgb[part])
        assert figures["ok"], ps.message(f"{name} ({side})", figures)


class _Socket:
    def __init__(self, identifier, value=0.0):
        self.identifier = self.name = identifier
        self.default_value = value
        self.is_linked = False
        self.enabled = True
        self.type = "RGBA" if isinstance(value, tuple) else "VALUE"


class _LegacyNode:
    """Stands in for Blender 4.x's Separate/Combine RGB and HSV nodes (5.0 opens them as
    Separate/Combine Color): their sockets, unlinked."""

    def __init__(self, inputs, outputs):
        self.inputs = [_Socket(k, v) for k, v in inputs.items()]
        self.outputs = [_Socket(k) for k in outputs]
        self.name = "legacy"


def test_legacy_separate_and_combine_nodes_compile_as_their_colour_modes(drt):
    from drt_engine.blender.export.nodes import Issues
    from drt_engine.blender.export.shader_graph import Compiler, ImageTable
    from drt_engine.core.shading.nodes import DirectionContext, Evaluator, rgb_to_hsv

    def evaluate(kind, inputs, outputs, output):
        compiler = Compiler(ImageTable([]), Issues())
        node = _LegacyNode(inputs, outputs)
        ref = getattr(compiler, "_node_" + kind)(node, node.outputs[outputs.index(output)])
        return Evaluator(compiler.program, DirectionContext(np.zeros((1, 3))), [])(ref)[0]
    colour = (0.2, 0.5, 0.9, 1.0)
    assert np.isclose(evaluate("ShaderNodeSeparateRGB", {"Image": colour}, ("R", "G", "B"), "G"), 0.5)
    hsv = [evaluate("ShaderNodeSeparateHSV", {"Color": colour}, ("H", "S", "V"), k) for k in "HSV"]
    assert np.allclose(hsv, rgb_to_hsv(np.array([colour[:3]]))[0])
    rgb = evaluate("ShaderNodeCombineRGB", {"R": 0.1, "G": 0.2, "B": 0.3}, ("Image",), "Image")
    assert np.allclose(rgb, [0.1, 0.2, 0.3])
    back = evaluate("ShaderNodeCombineHSV", dict(zip("HSV", hsv)), ("Color",), "Color")
    assert np.allclose(back, colour[:3])


def test_translucent_under_a_white_world_matches_cycles(drt, tmp_path):
    """Lit by a uniform world alone, from behind, by the Translucent's own rays and the world's
    sample drawn from its lobe (core.integrator.world_lobes): with neither, as once, it was black."""
    _matches_cycles(ns.translucent_world_scene(), tmp_path, "translucent-world", "Translucent under a white world")


def test_a_translucent_seen_through_a_translucent_matches_cycles(drt, tmp_path):
    """The far square of ``translucent_pair_scene`` is lit through the near one by a Translucent ray,
    which Cycles traces at diffuse bounces 0: it is as bright as Cycles' (light sampling alone, blocked
    by the near square, left it dark), and the parity rule holds over the whole image."""
    _matches_cycles(ns.translucent_pair_scene(), tmp_path, "translucent-pair", "Two Translucent squares")


def test_pointiness_matches_cycles(drt, tmp_path):
    """Pointiness of a bumpy icosphere whose sharp edges are split: Cycles' per-vertex angle,
    blur and welding of the split vertices."""
    _matches_cycles(ns.pointiness_scene(), tmp_path, "pointiness", "Pointiness")


def test_object_instancer_and_view_layer_attributes_match_cycles(drt, tmp_path):
    drt_render = _matches_cycles(ns.attribute_scene(), tmp_path, "attributes",
                                 "Object, Instancer and View Layer attributes")
    centre = drt_render.rgb[ps.TILE // 2, ps.TILE // 2::ps.TILE]
    assert np.allclose(centre, [[0.2, 0.7, 0.4], [2.0, 0.35, 0.0], [0.6] * 3, [0.3, 0.3, 0.9], [0.9, 0.5, 0.1]],
                       atol=1e-3)


def test_mirror_ball_environment_matches_cycles(drt, tmp_path):
    _matches_cycles(ns.mirror_ball_scene(), tmp_path, "mirror-ball", "Environment Texture, Mirror Ball")


@pytest.mark.parametrize("name", list(sky_scenes.CASES))
def test_sky_texture_lighting_a_scene_matches_cycles(drt, tmp_path, name):
    """The sky seen above the horizon and the ground below it, and the light of sky and sun
    disc on a diffuse sphere and ground (the sphere's shadow is the disc's penumbra)."""
    if not sky_scenes.offered(sky_scenes.CASES[name]["sky_type"]):
        pytest.skip("this Blender has no such sky type")
    _matches_cycles(sky_scenes.sky_scene(sky_scenes.CASES[name]), tmp_path, "sky", f"Sky Texture, {name}")


def test_every_sky_type_this_blender_offers_renders_and_is_compared(drt):
    """No sky type is left out: each one this Blender's node offers exports without a warning and
    has a case above (Blender 4's Nishita, Preetham and Hosek / Wilkie; 5's scattering models)."""
    offered = bpy.types.ShaderNodeTexSky.bl_rna.properties["sky_type"].enum_items.keys()
    assert set(offered) <= {props["sky_type"] for props in sky_scenes.CASES.values()}
    for sky_type in offered:
        assert not _cannot(render_export(sky_scenes.sky_scene({"sky_type": sky_type}))), sky_type


def test_box_projection_of_a_udim_image_reads_tile_1001(drt):
    """As Cycles: Box projection's coordinates always fall in tile 1001, the only tile it loads."""
    scene = ns.grid_scene(ns.CASES[:1])
    mat = scene.objects[ns.CASES[0].name].data.materials[0]
    image = mat.node_tree.nodes.new("ShaderNodeTexImage")
    image.image, image.projection = ns._udim_tiles(), "BOX"
    emission = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
    mat.node_tree.links.new(image.outputs["Color"], emission.inputs["Color"])
    data = render_export(scene)
    (node,) = [n for m in data.materials if m.program is not None for n in m.program.nodes if n.op == "image"]
    assert node.params["tiles"] is None and data.images[node.params["image"]].path.endswith("tiles.1001.exr")


def test_object_info_matches_cycles(drt, tmp_path):
    """Random (the hash of plain, numbered and non-ASCII names; an instance's own), Object and
    Material Index, colour, alpha and location."""
    _matches_cycles(ns.object_info_scene(), tmp_path, "object-info", "Object Info")


def test_light_path_matches_cycles(drt, tmp_path):
    """Is Camera Ray driving a surface's and the world's Mix Shader, Ray Length, Glossy Depth and Ray
    Depth driving a diffuse colour, seen straight and in a sharp mirror."""
    _matches_cycles(ns.light_path_scene(), tmp_path, "light-path", "Light Path")


def test_light_path_through_transparent_and_glass_matches_cycles(drt, tmp_path):
    """Is Camera Ray through a transparent sheet, Transparent and Transmission Depth, Is Transmission
    and Is Singular Ray through a sharp glass slab, on emissive spheres."""
    _matches_cycles(ns.light_path_glass_scene(), tmp_path, "light-path-glass", "Light Path through glass")


def test_light_falloff_matches_cycles(drt, tmp_path):
    """Quadratic (smoothed) and Linear (its Strength linked) on emissive spheres seen straight and in
    a sharp mirror (each ray's own length), and Linear at the world (Strength as is). A Blender whose
    Cycles computes it otherwise at the world (4.2's) has it named in the world's warning."""
    if bpy.app.version < FALLOFF_WORLD_MATCHED_FROM:
        warnings = _cannot(render_export(ns.light_falloff_scene()))
        assert len(warnings) == 1 and warnings[0].startswith("World") and VERSION_FALLOFF_WORLD in warnings[0], \
            warnings
        return
    _matches_cycles(ns.light_falloff_scene(), tmp_path, "light-falloff", "Light Falloff")


def test_wireframe_in_pixels_matches_cycles(drt, tmp_path):
    _matches_cycles(ns.wireframe_scene(), tmp_path, "wireframe-pixels", "Wireframe in pixels")


def test_displacement_renders_as_cycles_bump(drt, tmp_path):
    """The Displacement socket as Cycles' "Bump Only": the shading normal bumped by the
    displacement's height along the normal (0.32 off with it left out). A Blender whose Cycles
    bumps it otherwise (4.2's) has the displacement named in each material's warning."""
    if bpy.app.version < DISPLACEMENT_MATCHED_FROM:
        warnings = _cannot(render_export(ns.displacement_scene()))
        assert warnings and all(f"({VERSION_BUMP})" in w for w in warnings), warnings
        return
    _matches_cycles(ns.displacement_scene(), tmp_path, "displacement", "Displacement as bump")


def test_true_displacement_renders_as_bump_with_one_warning(drt):
    scene = ns.displacement_scene()
    mat = bpy.data.materials["World space"]
    mat.displacement_method = "BOTH"
    warnings = _displacement_warnings(scene)
    assert len(warnings) == 1 and "World space" in warnings[0] and "Both" in warnings[0], warnings
    material = next(m for m in render_export(scene).materials if m.name == "World space")
    assert material.displacement is not None


def test_surface_point_nodes_in_the_world_are_named_in_its_warning(drt):
    """The world has no triangle or surface point to read: Camera Data there is named; it has no
    object either, and Object Info gives 0 there, as in Cycles."""
    scene = ns.grid_scene(ns.CASES[:1])
    tree = scene.world.node_tree
    camera = tree.nodes.new("ShaderNodeCameraData")
    tree.links.new(camera.outputs["View Vector"], tree.nodes["Background"].inputs["Color"])
    warnings = _cannot(render_export(scene))
    assert len(warnings) == 1 and "Camera Data in the world" in warnings[0], warnings
    info = tree.nodes.new("ShaderNodeObjectInfo")
    tree.links.new(info.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    tree.links.new(info.outputs["Random"], tree.nodes["Background"].inputs["Strength"])
    data = render_export(scene)
    assert not _cannot(data) and data.world.program is None and not np.any(data.world.radiance)


def test_a_wireframe_feeding_the_displacement_is_named(drt):
    """Cycles takes a Wireframe's derivative inside a bump by its own rule, which DRT does not."""
    scene = ns.displacement_scene()
    tree = bpy.data.materials["World space"].node_tree
    wire = tree.nodes.new("ShaderNodeWireframe")
    displace = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeDisplacement")
    tree.links.new(wire.outputs[0], displace.inputs["Height"])
    warnings = _displacement_warnings(scene)
    assert len(warnings) == 1 and "Wireframe feeding the displacement" in warnings[0], warnings


def _displacement_warnings(scene):
    """The export's warnings but those naming only the bump a Blender before
    DISPLACEMENT_MATCHED_FROM gives every displaced material."""
    return [w for w in _cannot(render_export(scene)) if f"({VERSION_BUMP})" not in w]


def test_geometry_nodes_attributes_are_exported_only_when_read(drt):
    """An attribute no material reads stays out of the export; a 2D integer one (which Cycles reads
    as 0: measured) stays out even when read."""
    case = next(c for c in ns.CASES if c.name == "Attribute float on points")
    scene = ns.grid_scene([case])
    mesh = scene.objects[case.name].data
    mesh.attributes.new("unread", "FLOAT", "POINT")
    mesh.attributes.new("turn", "INT32_2D", "POINT")
    tree = mesh.materials[0].node_tree
    turn = tree.nodes.new("ShaderNodeAttribute")
    turn.attribute_name = "turn"
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    tree.links.new(turn.outputs["Fac"], emission.inputs["Strength"])
    data = render_export(scene)
    assert any(n.op == "attribute" and n.params["name"] == "turn" for m in data.materials if m.program
               for n in m.program.nodes)
    (exported,) = data.meshes
    assert exported.attributes["height"].shape[1:] == (3, 1)
    assert "unread" not in exported.attributes and "turn" not in exported.attributes


def test_tangents_asked_of_a_mesh_without_uv_map_are_named(drt):
    """Cycles derives such tangents from a sphere mapping of the Generated coordinates; DRT does not."""
    case = next(c for c in ns.CASES if c.name == "Vector Displacement object space")
    scene = ns.grid_scene([replace(case, name="No UV map", build=ns._vector_displacement("TANGENT"))])
    warnings = [w for w in render_export(scene).warnings if "no UV map" in w]
    assert len(warnings) == 1 and "No UV map" in warnings[0], warnings


CLOSURE_CASES = [c for c in ns.CLOSURES if bpy.app.version >= c.since]


@pytest.fixture(scope="module")
def closures(drt, tmp_path_factory):
    """DRT seed 0, Cycles seeds 0 and 1 of the closure scene, and the export's warnings."""
    scene = ns.closure_scene(CLOSURE_CASES)
    warnings = _cannot(render_export(scene))
    renders = ps.parity_renders(scene, tmp_path_factory.mktemp("closures"), "closures")
    rh.save_side_by_side("closures", renders[0].rgb, renders[1].rgb)
    return warnings, renders


@pytest.mark.parametrize("case", CLOSURE_CASES, ids=[c.name for c in CLOSURE_CASES])
def test_closure_matches_cycles(closures, case):
    """Each closure's square of the scene, without its edge pixels (the pixel filter's reach into the
    next square): DRT against Cycles by the parity rule, exported without a warning. A Blender whose
    Cycles computes Oren-Nayar otherwise (4.2's) names it in the material's warning instead."""
    warnings, renders = closures
    named = [w for w in warnings if f"Material '{case.name}'" in w]
    if case.oren_nayar and bpy.app.version < OREN_NAYAR_MATCHED_FROM:
        assert len(named) == 1 and VERSION_OREN_NAYAR in named[0], warnings
        return
    assert not named, warnings
    part = ns.closure_part(CLOSURE_CASES.index(case), renders[0].rgb.shape[0])
    figures = ps.parity(*(r.rgb[part] for r in renders))
    print(f"{case.name}: {figures}")
    assert figures["ok"], ps.message(case.name, figures)
