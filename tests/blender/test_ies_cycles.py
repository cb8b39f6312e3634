"""IES Texture and lights' node trees against Cycles: a floor lit through IES profiles
(tests/support/ies_scenes) by point, spot, sphere and area lights whose node trees read them and by
an emissive sphere whose material does, and by a point light through Light Falloff, each emitter
alone held to the node parity rule (procedural_scenes.parity); a profile Cycles cannot read is
named, and so is a light tree that reads what a light has not. A Blender whose Cycles looks profiles
up otherwise (4.2's) has each IES Texture named in its warning."""
from __future__ import annotations

import bpy
import pytest

from drt_engine.blender.export.shader_graph import IES_MATCHED_FROM, VERSION_IES
from tests.support import ies_scenes
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export


def test_every_emitter_exports_its_tree(drt):
    data = render_export(ies_scenes.ies_scene())
    assert sum(light.program is not None for light in data.lights) == 5
    if bpy.app.version < IES_MATCHED_FROM:
        assert len(data.warnings) == 5 and all(VERSION_IES in w for w in data.warnings), data.warnings
    else:
        assert not data.warnings, data.warnings


@pytest.mark.parametrize("label", list(ies_scenes.CASES))
def test_a_floor_lit_through_ies_profiles_matches_cycles(drt, tmp_path, label):
    """Each emitter alone, so that one light's noise in Cycles hides no other's error."""
    if bpy.app.version < IES_MATCHED_FROM:
        pytest.skip(f"this Blender's Cycles looks IES profiles up otherwise: the node is named ({VERSION_IES})")
    _matches_cycles(ies_scenes.CASES[label], tmp_path, f"IES Texture, {label}")


def test_light_falloff_in_a_lights_tree_matches_cycles(drt, tmp_path):
    """Light Falloff's Linear output (smoothed) as a point light's strength: the distance to the
    lit point, which without it read 1 (half the light here)."""
    _matches_cycles(ies_scenes.FALLOFF, tmp_path, "Light Falloff in a light's tree")


def _matches_cycles(name, out, label):
    drt_render, c0, c1 = ps.parity_renders(ies_scenes.lit_by(name), out, "ies")
    rh.save_side_by_side(f"ies-{name.replace(' ', '-')}", drt_render.rgb, c0.rgb)
    figures = ps.parity(drt_render.rgb, c0.rgb, c1.rgb)
    assert figures["ok"], ps.message(label, figures)


def test_a_profile_cycles_cannot_read_is_named(drt):
    scene = ies_scenes.ies_scene()
    spot = scene.objects["IES spot"].data.node_tree.nodes["IES Texture"]
    spot.filepath = "//no-such-profile.ies"
    warnings = [w for w in render_export(scene).warnings if "IES spot" in w]
    assert len(warnings) == 1 and "no-such-profile.ies" in warnings[0] and "100 x Strength" in warnings[0], warnings


def test_a_light_tree_reading_what_a_light_has_not_is_named(drt):
    """UV coordinates mean nothing at a light in DRT: the tree's strength keeps its default, named."""
    scene = ies_scenes.ies_scene()
    tree = scene.objects["Falloff point"].data.node_tree
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    separate = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(coordinates.outputs["UV"], separate.inputs[0])
    tree.links.new(separate.outputs["X"], tree.nodes["Emission"].inputs["Strength"])
    data = render_export(scene)
    warnings = [w for w in data.warnings if "Falloff point" in w]
    assert len(warnings) == 1 and "uv coordinates" in warnings[0], data.warnings
    light = next(light for light in data.lights if light.name == "Falloff point")
    assert light.program is None and light.intensity[0] > 0
