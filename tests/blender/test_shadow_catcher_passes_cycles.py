"""Light passes and light groups with a shadow catcher, against Cycles: test_shadow_catcher_cycles'
scene (a red diffuse cube floating over a catcher ground under an area light, a sun and a blue-grey
world; here the ground reaches the top of the view) over an opaque film with the Shadow Catcher
pass, the area light in group ``key``, the sun in ``sun``, the world in ``sky``. Cycles' film
writes no light pass and no group for a path that met a catcher (the path split there and the one
split off: light_passes.h), so the ground's pixels hold none of the ground's light (without the
catcher, its diffuse light in DiffDir, its specular layer's in GlossDir); Env holds the world behind
the ground too (the split-off path shades its Background pass there over an opaque film). Each
light pass, Emit, Env and each group pass is within procedural_scenes.parity's rule (DRT's worst
4x4-block difference from Cycles seed 0 within 1.5x Cycles' own seed-0-against-seed-1 worst plus
0.002) of Cycles', and the groups sum to Combined (the matte, over an opaque film with the pass) in
Cycles' render and in DRT's, as Blender receives them."""
from __future__ import annotations

import bpy
import pytest

from tests.blender.test_shadow_catcher_cycles import SAMPLES, catcher_scene
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

LIGHT = ("DiffDir", "DiffInd", "GlossDir", "GlossInd", "DiffCol", "GlossCol", "Emit", "Env")
GROUPS = {"key": "Area", "sun": "Sun"}


def grouped_scene():
    """The catcher scene over an opaque film with the Shadow Catcher pass, every emitter in a group."""
    scene = catcher_scene(transparent=False, catcher_pass=True)
    # the ground to the top of the view: the cube's outline against it, not against the world (where
    # a pixel's DiffDir over its DiffCol is the light or 0 as one sample decides, in Cycles as in DRT)
    bpy.data.objects["Ground"].scale = (5.0, 5.0, 1.0)
    layer = scene.view_layers[0]
    for group, light in GROUPS.items():
        layer.lightgroups.add(name=group)
        bpy.data.objects[light].lightgroup = group
    layer.lightgroups.add(name="sky")
    scene.world.lightgroup = "sky"
    return scene


@pytest.fixture(scope="module")
def renders(drt, tmp_path_factory):
    """DRT seed 0, Cycles seeds 0 and 1 (procedural_scenes.RUNS), the light passes on."""
    out = tmp_path_factory.mktemp("catcher_passes")
    scene = grouped_scene()
    return [rh.render(scene, engine, SAMPLES, seed, out, passes=LIGHT, name="catcher_passes")
            for engine, seed in ps.RUNS]


def _group_sum(render):
    return sum(render.passes[f"Combined_{group}"] for group in (*GROUPS, "sky"))


@pytest.mark.parametrize("name", LIGHT + tuple(f"Combined_{group}" for group in GROUPS))
def test_each_pass_matches_cycles(renders, name):
    drt, cycles0, cycles1 = renders
    figures = ps.parity(drt.passes[name], cycles0.passes[name], cycles1.passes[name])
    print(name, {k: round(v, 4) for k, v in figures.items() if k != "ok"})
    assert figures["ok"], ps.message(name, figures)


def test_groups_sum_to_combined_as_in_cycles(renders):
    """Cycles' groups, every emitter in one, sum to its Combined here (the matte: what paths bring
    before a catcher), not to the whole scene's light; so do DRT's (float32 EXR: to 1e-4 per block)."""
    for render in renders:
        worst = ps.worst_block(_group_sum(render), render.rgb)
        print("groups - Combined", round(worst, 6))
        assert worst < 1e-4
