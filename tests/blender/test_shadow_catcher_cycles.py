"""Shadow catchers against Cycles on a scene built for them: a red diffuse cube floating over a ground
plane that is a shadow catcher, under an area light, a sun and a blue-grey world (the cube floats so
its shadows lie apart from its outline: on a pixel where the cube meets its own shadow the pass
jumps between 1, no sample split, and the shadow, one sample deciding, in Cycles as in DRT).
Combined (RGBA) with Film Transparent on and off, with and without the view layer's Shadow Catcher
pass (without it Combined carries Cycles' approximate shadow), and that pass, against Cycles by
procedural_scenes.parity's rule: DRT's worst 4x4-block difference from Cycles seed 0 within 1.5x
Cycles' own seed-0-against-seed-1 worst plus 0.002. Each comparison also renders DRT with the
catcher flag ignored (the ground then a plain object, the pass all 1) and asserts it is far out.
Measured (64 x 48, 128 samples), worst block / limit (Cycles' seeds), flag ignored:
Combined, Film Transparent on: 0.0103 / 0.0509 (0.0326), ignored 3.01; off: 0.0093 / 0.0490 (0.0313),
ignored 2.60 (approximate shadow) and 3.01 (with the pass); the pass, Film Transparent on:
0.0150 / 0.0244 (0.0149), off: 0.0312 / 0.0880 (0.0574), ignored 0.544."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material

WIDTH, HEIGHT = 64, 48
SAMPLES = 128


def catcher_scene(transparent: bool, catcher_pass: bool):
    scene = ps.dark_scene(WIDTH, (0.0, -6.0, 4.0), 35.0, transparent)
    scene.render.resolution_y = HEIGHT
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.3, 0.35, 0.45, 1.0)
    background.inputs["Strength"].default_value = 1.0
    ground = new_material("Ground")
    ground.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, ground, "Ground", size=5.0).is_shadow_catcher = True
    cube, _ = ps.closure_material("Cube", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.2, 0.1, 1.0))
    ps.add_primitive(bpy.ops.mesh.primitive_cube_add, cube, "Cube", size=0.8, location=(-0.2, 0.3, 1.1),
                     rotation=(0.0, 0.0, 0.5))
    ps.add_light(scene, "Area", "AREA", 300.0, (1.5, 1.0, 3.0), size=1.0)
    ps.add_light(scene, "Sun", "SUN", 2.0, (-2.5, 2.0, 5.0))
    scene.view_layers[0].cycles.use_pass_shadow_catcher = catcher_pass
    return scene


def catcher_render(scene, engine, seed, tmp_path, name, catcher_pass):
    """Combined and, when asked, the Shadow Catcher pass of one render."""
    r = rh.render(scene, engine, SAMPLES, seed, tmp_path, name=name)
    images = [r.passes["Combined"]]
    if catcher_pass:
        channels = rh.read_channels(tmp_path / f"{name}-{engine.lower()}-{seed}.exr")
        images.append(rh._pass(channels, scene.view_layers[0].name, "Shadow Catcher", "RGB"))
    return images


@pytest.mark.parametrize("catcher_pass", [False, True])
@pytest.mark.parametrize("transparent", [True, False])
def test_shadow_catcher_matches_cycles(drt, tmp_path, transparent, catcher_pass):
    """Combined (RGBA) with Film Transparent on and off, Cycles' approximate shadow in it without the
    Shadow Catcher pass, and that pass, against Cycles; with the flag ignored each is far out."""
    scene = catcher_scene(transparent, catcher_pass)
    drt_images, cycles0, cycles1 = (catcher_render(scene, engine, seed, tmp_path, "catcher", catcher_pass)
                                    for engine, seed in ps.RUNS)
    bpy.data.objects["Ground"].is_shadow_catcher = False
    ignored = catcher_render(scene, "DRT", 0, tmp_path, "ignored", catcher_pass)
    ignored[1:] = [np.ones_like(image) for image in ignored[1:]]  # no catcher: Cycles' pass reads 1
    for name, image, c0, c1, off in zip(("Combined", "Shadow Catcher"), drt_images, cycles0, cycles1, ignored):
        figures = ps.parity(image, c0, c1)
        label = f"{name}, Film Transparent {transparent}, Shadow Catcher pass {catcher_pass}"
        print(label, {k: round(v, 4) for k, v in figures.items() if k != "ok"},
              "ignored", round(ps.worst_block(off, c0), 4))
        assert figures["ok"], ps.message(label, figures)
        assert ps.worst_block(off, c0) > 5 * figures["limit"], f"{label}: the flag ignored is not far out"
