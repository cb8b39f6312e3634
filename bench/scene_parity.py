"""Measure DRT's scene settings against Cycles and write the figures into docs/scene-parity.md.

Renders the scenes tests/blender's Cycles comparisons hold DRT to for what a scene sets up
(issue "Scenes as users set them up"): transparent shadows, objects' and lights' ray visibility,
holdouts, shadow catchers (Combined and the Shadow Catcher pass), light and shadow linking, light
groups (Combined and each group's pass), every panoramic camera this Blender offers and the
shutter curve, each with DRT (seed 0) and Cycles (seeds 0 and 1) at its test's samples. Writes
docs/scene_parity.json and replaces the page's block between the markers below with each case's
worst 4x4-block difference from Cycles (RGBA where the test compares alpha) beside Cycles' own
between its two seeds. Run from the repository root: .venv/bin/python bench/scene_parity.py
(``make scene-parity``).
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(1, str(ROOT / "tests" / "blender"))  # as pytest has it: a test there imports its conftest

import bpy  # noqa: E402

import drt_engine  # noqa: E402
from bench.texture_parity import publish, row  # noqa: E402
from tests.blender import test_holdout_cycles as holdout  # noqa: E402
from tests.blender import test_light_groups_cycles as groups  # noqa: E402
from tests.blender import test_light_linking_cycles as linking  # noqa: E402
from tests.blender import test_panorama_cycles as panorama  # noqa: E402
from tests.blender import test_ray_visibility_cycles as visibility  # noqa: E402
from tests.blender import test_shadow_catcher_cycles as catcher  # noqa: E402
from tests.blender import test_shutter_curve_cycles as shutter  # noqa: E402
from tests.blender import test_transparent_shadows_cycles as shadows  # noqa: E402
from tests.support import procedural_scenes as ps  # noqa: E402
from tests.support import render_helpers as rh  # noqa: E402

MARK_BEGIN, MARK_END = "<!-- scene parity: begin -->", "<!-- scene parity: end -->"
JSON_PATH = ROOT / "docs" / "scene_parity.json"
PAGE = ROOT / "docs" / "scene-parity.md"


def _combined(build, samples, out, name, rgba=True) -> dict:
    """The figures of Combined (RGBA, or RGB where the test compares colour alone) of ``build()``."""
    scene = build()
    renders = [rh.render(scene, engine, samples, seed, out, name=name) for engine, seed in ps.RUNS]
    return ps.parity(*(r.passes["Combined"] if rgba else r.rgb for r in renders))


def measure() -> dict:
    cases = {}
    with tempfile.TemporaryDirectory() as out:
        out = Path(out)
        cases["Transparent shadows (alpha-mapped and tinted quads)"] = _combined(
            shadows.shadow_scene, shadows.SAMPLES, out, "shadows")
        for build in (visibility.mirror_scene, visibility.shadow_scene, visibility.light_scene):
            cases[f"Ray visibility: {build.__name__.replace('_', ' ')}"] = _combined(
                build, visibility.SAMPLES, out, build.__name__)
        for transparent in (True, False):
            cases[f"Holdout (object and closure), Film Transparent {transparent}"] = _combined(
                lambda: holdout.holdout_scene(transparent), holdout.SAMPLES, out, "holdout")
        for transparent in (True, False):
            for with_pass in (False, True):
                scene = catcher.catcher_scene(transparent, with_pass)
                images = [catcher.catcher_render(scene, engine, seed, out, "catcher", with_pass)
                          for engine, seed in ps.RUNS]
                label = f"Film Transparent {transparent}, Shadow Catcher pass {'on' if with_pass else 'off'}"
                cases[f"Shadow catcher: Combined, {label}"] = ps.parity(*(i[0] for i in images))
                if with_pass:
                    cases[f"Shadow catcher: the pass, Film Transparent {transparent}"] = ps.parity(
                        *(i[1] for i in images))
        for build in (linking.linking_scene, linking.shadow_scene):
            cases[f"Light linking: {build.__name__.replace('_', ' ')}"] = _combined(
                build, linking.SAMPLES, out, build.__name__, rgba=False)
        scene = groups.groups_scene()
        renders = [rh.render(scene, engine, groups.SAMPLES, seed, out, name="groups") for engine, seed in ps.RUNS]
        cases["Light groups: Combined"] = ps.parity(*(r.rgb for r in renders))
        for group in groups.GROUPS:
            name = f"Combined_{group}"
            cases[f"Light groups: {name}"] = ps.parity(*(r.passes[name] for r in renders))
        for case in panorama.CASES:
            cases[f"Panoramic camera: {case.replace('_', ' ')}"] = _combined(
                lambda: panorama.case_scene(case), panorama.SAMPLES, out, case)
        for case, settings in shutter.CASES.items():
            cases[f"Shutter: {case.replace('_', ' ')}"] = _combined(
                lambda: shutter.sliding_edge_scene(*settings), shutter.SAMPLES, out, case)
    return {"blender": bpy.app.version_string, "cases": cases}


def table(figures: dict) -> str:
    rows = [f"Measured by `bench/scene_parity.py` (Blender {figures['blender']}; each scene at its test's "
            "samples): the worst 4x4-block difference of DRT from Cycles (RGBA but for light linking and light "
            "groups), beside Cycles' own worst between two seeds; a case passes at 1.5x that plus 0.002.", "",
            "| scene setting | DRT vs Cycles | Cycles vs Cycles | within |", "|---|---|---|---|"]
    rows += [row(name, f) for name, f in figures["cases"].items()]
    return "\n".join(rows) + "\n"


def main() -> None:
    drt_engine.register()
    figures = measure()
    publish(figures, JSON_PATH, (MARK_BEGIN, MARK_END), table(figures), PAGE)


if __name__ == "__main__":
    main()
