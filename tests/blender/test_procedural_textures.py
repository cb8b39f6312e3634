"""Blender's procedural textures in DRT against Cycles: every texture and mode family as a
tile of one emissive grid (procedural_scenes.CASES), and one lit scene.

A case passes when DRT's worst 4x4-block difference from Cycles (seed 0) is at most 1.5x
Cycles' own worst between seeds 0 and 1, plus 0.002: what is left when both evaluate the
same texture is pixel-sampling noise, largest at cell edges and discontinuities. A wrong
hash, octave, seed or metric moves whole cells by far more. Image Texture's Box projection
is checked the same way on an emissive sphere.
"""
from __future__ import annotations

import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export


@pytest.fixture(scope="module")
def grid(drt, tmp_path_factory):
    """Tiles of DRT seed 0, Cycles seeds 0 and 1, per case."""
    return ps.grid_tiles(ps.grid_scene(), len(ps.CASES), tmp_path_factory.mktemp("procedural"), "grid")


def test_every_case_exports_without_a_warning(drt):
    data = render_export(ps.grid_scene())
    assert not [w for w in data.warnings if "cannot evaluate" in w], data.warnings


@pytest.mark.parametrize("index", range(len(ps.CASES)), ids=[c.name for c in ps.CASES])
def test_texture_matches_cycles(grid, index):
    figures = ps.tile_figures(grid, index)
    assert figures["ok"], ps.message(ps.CASES[index].name, figures)


def test_lit_scene_matches_cycles(drt, tmp_path):
    scene = ps.lit_scene()
    drt_render, c0, c1 = ps.parity_renders(scene, tmp_path, "lit")
    figures = ps.parity(drt_render.rgb, c0.rgb, c1.rgb)
    rh.save_side_by_side("procedural-lit", drt_render.rgb, c0.rgb)
    assert figures["ok"], figures


@pytest.mark.parametrize("blend", [0.0, 0.3])  # as bench/texture_parity.BOX_BLENDS
def test_image_box_projection_matches_cycles(drt, tmp_path, blend):
    scene = ps.box_scene(blend=blend)
    assert not [w for w in render_export(scene).warnings if "projection" in w]
    drt_render, c0, c1 = ps.parity_renders(scene, tmp_path, "box")
    figures = ps.parity(drt_render.rgb, c0.rgb, c1.rgb)
    rh.save_side_by_side(f"box-projection-{blend}", drt_render.rgb, c0.rgb)
    assert figures["ok"], figures
