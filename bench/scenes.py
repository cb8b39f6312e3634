"""The sample scenes as both benchmarks load them: resized, and exported with their motion.

Exporting with ``frame_set`` matters: without it the motion-blur scene has no motion for
DRT while Cycles blurs it, and the two would render different images.
"""
from __future__ import annotations

from pathlib import Path

import bpy

from drt_engine.blender.export import export_scene
from drt_engine.core.settings import RenderSettings

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("cornell_box", "glossy_spheres", "dof_row", "motion_blur")


def load(name, width, height=None):
    """The sample scene at ``width`` pixels (its own aspect unless ``height``) and its SceneData."""
    bpy.ops.wm.open_mainfile(filepath=str(ROOT / "sample_scenes" / f"{name}.blend"), load_ui=False)
    scene = bpy.context.scene
    r = scene.render
    aspect = r.resolution_y / r.resolution_x
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height or max(4, round(width * aspect)), 100
    r.use_border = False
    frame_set = lambda frame, sub: scene.frame_set(frame, subframe=sub)  # noqa: E731
    return scene, export_scene(bpy.context.evaluated_depsgraph_get(), frame_set=frame_set)


def settings(scene, **kw) -> RenderSettings:
    """DRT's settings for the scene: its depth, diffuse bounces and pixel filter, Combined only unless
    ``kw`` says."""
    base = dict(max_depth=scene.drt.max_depth, diffuse_bounces=scene.drt.diffuse_bounces, filter_type=scene.drt.filter_type,
                filter_size=scene.render.filter_size, passes=("Combined",))
    base.update(kw)
    return RenderSettings(**base)
