"""The Light Paths panel's presets set scene.drt, and the render settings carry the Light Paths."""
import bpy

from drt_engine.blender.presets import PRESETS
from drt_engine.blender.properties import settings_from_scene


def test_presets_set_the_light_paths_the_render_reads(drt):
    scene = bpy.context.scene
    assert scene.drt.diffuse_bounces == 0  # the classic image by default
    for key, (_, _, values) in PRESETS.items():
        assert bpy.ops.drt.light_paths_preset(preset=key) == {"FINISHED"}
        settings = settings_from_scene(scene, scene.view_layers[0])
        assert {name: getattr(settings, name) for name in values} == values
    assert settings.diffuse_bounces == 128 and settings.min_light_bounces == 3  # Full GI, as Cycles' preset
    assert settings.glossy_bounces == settings.transmission_bounces == 128
    assert bpy.ops.drt.light_paths_preset(preset="DIRECT") == {"FINISHED"}
    assert scene.drt.diffuse_bounces == 0
