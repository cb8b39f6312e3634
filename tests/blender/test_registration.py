"""Registration: DRT appears in Blender with its settings and panels, and unregister removes all of it."""
from types import SimpleNamespace

import bpy
import pytest

import drt_engine
from drt_engine.blender import properties, ui
from drt_engine.blender.engine import DRTRenderEngine
from drt_engine.core.settings import PASSES, RenderSettings

# Blender 5.0 panels DRT must show: camera lens and depth of field, light, material
# slots and surface, world surface, output format and colour management.
REQUIRED_SHARED_PANELS = (
    "DATA_PT_lens",
    "DATA_PT_camera",
    "DATA_PT_camera_dof",
    "DATA_PT_camera_dof_aperture",
    "DATA_PT_EEVEE_light",
    "DATA_PT_spot",
    "EEVEE_MATERIAL_PT_context_material",
    "EEVEE_MATERIAL_PT_surface",
    "EEVEE_WORLD_PT_surface",
    "RENDER_PT_format",
    "RENDER_PT_output",
    "RENDER_PT_color_management",
)


def registered_panels_open_to_drt():
    return [
        p.__name__
        for p in bpy.types.Panel.__subclasses__()
        if p.is_registered and "DRT" in getattr(p, "COMPAT_ENGINES", ())
    ]


def engine_ids():
    return [getattr(cls, "bl_idname", None) for cls in bpy.types.RenderEngine.__subclasses__() if cls.is_registered]


def assert_registered():
    assert "DRT" in engine_ids()
    assert hasattr(bpy.types.Scene, "drt") and hasattr(bpy.types.ViewLayer, "drt")
    assert isinstance(bpy.context.scene.drt, properties.DRTSceneSettings)
    assert all(cls.is_registered for cls in ui.classes)
    open_panels = set(registered_panels_open_to_drt())
    assert set(REQUIRED_SHARED_PANELS) <= open_panels
    assert {cls.__name__ for cls in ui.classes} <= open_panels


def assert_unregistered():
    assert "DRT" not in engine_ids()
    assert not hasattr(bpy.types.Scene, "drt") and not hasattr(bpy.types.ViewLayer, "drt")
    assert registered_panels_open_to_drt() == []
    assert not any(cls.is_registered for cls in ui.classes + properties.classes)


def test_register_unregister_register(drt):
    assert_registered()
    for _ in range(2):
        drt_engine.unregister()
        assert_unregistered()
        drt_engine.register()
        assert_registered()


def test_unregister_leaves_other_engines_panels_alone(drt):
    before = {p.__name__: set(p.COMPAT_ENGINES) - {"DRT"} for p in bpy.types.Panel.__subclasses__()
              if p.is_registered and hasattr(p, "COMPAT_ENGINES") and p not in ui.classes}
    drt_engine.unregister()
    try:
        after = {p.__name__: set(p.COMPAT_ENGINES) for p in bpy.types.Panel.__subclasses__()
                 if p.is_registered and hasattr(p, "COMPAT_ENGINES")}
    finally:
        drt_engine.register()
    assert after == before


def test_engine_class_attributes(drt):
    assert DRTRenderEngine.bl_idname == "DRT"
    assert DRTRenderEngine.bl_label == "DRT"
    assert DRTRenderEngine.bl_use_shading_nodes_custom is False
    assert DRTRenderEngine.bl_use_preview is True
    assert DRTRenderEngine.bl_use_postprocess is True
    bpy.context.scene.render.engine = "DRT"
    assert bpy.context.scene.render.engine == "DRT"


def test_scene_settings_defaults(drt):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    drt_settings = bpy.context.scene.drt
    assert drt_settings.samples == 64
    assert drt_settings.seed == 0
    assert drt_settings.sampling_pattern == "SOBOL"
    assert drt_settings.max_depth == 8
    assert drt_settings.glossy_bounces == drt_settings.transmission_bounces == 8  # never binding at Total 8
    assert drt_settings.sample_clamp_direct == drt_settings.sample_clamp_indirect == 0.0
    assert drt_settings.threads == 0
    assert drt_settings.filter_type == "BLACKMAN_HARRIS"
    assert drt_settings.use_adaptive_sampling is False
    assert drt_settings.adaptive_threshold == pytest.approx(0.01)
    assert drt_settings.adaptive_min_samples == 0
    assert drt_settings.adaptive_mode == "NOISE"
    assert drt_settings.shadow_estimator == "MONTE_CARLO"
    assert drt_settings.time_limit == 0.0
    assert drt_settings.target_error == 0.0
    rna = properties.DRTSceneSettings.bl_rna.properties
    assert {i.identifier for i in rna["sampling_pattern"].enum_items} == {"GRID", "JITTERED", "SOBOL"}
    assert {i.identifier for i in rna["filter_type"].enum_items} == {"BOX", "GAUSSIAN", "BLACKMAN_HARRIS"}
    assert {i.identifier for i in rna["adaptive_mode"].enum_items} == {"NOISE", "CONTRAST"}
    assert {i.identifier for i in rna["shadow_estimator"].enum_items} == {"MONTE_CARLO", "RATIO"}
    assert rna["samples"].hard_min == 1
    drt_settings.samples = 0
    assert drt_settings.samples == 1
    for name in rna.keys():
        if name not in ("rna_type", "name"):
            assert len(rna[name].description) > 20, f"{name} needs a tooltip"


def test_every_pass_has_a_toggle(drt):
    toggles = properties.BLENDER_PASS_TOGGLES | properties.DRT_PASS_TOGGLES | properties.CYCLES_PASS_TOGGLES
    assert set(toggles) == set(PASSES) - {"Combined"}
    view_layer_props = bpy.types.ViewLayer.bl_rna.properties
    for name, attr in properties.BLENDER_PASS_TOGGLES.items():
        assert attr in view_layer_props, f"ViewLayer.{attr} (pass {name}) missing"
    for attr in properties.DRT_PASS_TOGGLES.values():
        assert attr in properties.DRTViewLayerSettings.bl_rna.properties
    for attr in properties.CYCLES_PASS_TOGGLES.values():
        assert attr in bpy.context.scene.view_layers[0].cycles.bl_rna.properties


def test_settings_from_scene(drt):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    view_layer = scene.view_layers[0]
    d = scene.drt
    d.samples, d.seed, d.sampling_pattern, d.max_depth = 9, 7, "JITTERED", 3
    d.sample_clamp_direct, d.sample_clamp_indirect, d.threads, d.filter_type = 4.5, 1.5, 2, "GAUSSIAN"
    d.filter_glossy = 0.5
    d.use_adaptive_sampling, d.adaptive_threshold, d.adaptive_min_samples = True, 0.05, 16
    d.adaptive_mode = "CONTRAST"
    d.time_limit, d.target_error = 12.0, 0.02
    scene.render.filter_size = 2.25
    view_layer.use_pass_z = True
    view_layer.use_pass_environment = True
    view_layer.drt.use_pass_noise = True
    view_layer.use_pass_mist = view_layer.use_pass_object_index = view_layer.use_pass_material_index = True
    view_layer.pass_alpha_threshold = 0.25
    settings = properties.settings_from_scene(scene, view_layer)
    assert settings == RenderSettings(
        samples=9, seed=7, sampling_pattern="JITTERED", max_depth=3, sample_clamp_direct=4.5,
        sample_clamp_indirect=1.5, filter_glossy=0.5, threads=2,
        filter_type="GAUSSIAN", filter_size=2.25,
        passes=("Combined", "Depth", "Env", "Noise", "Mist", "IndexOB", "IndexMA"), pass_alpha_threshold=0.25,
        use_adaptive_sampling=True, adaptive_threshold=pytest.approx(0.05), adaptive_min_samples=16,
        adaptive_mode="CONTRAST", time_limit=12.0, target_error=pytest.approx(0.02),
        weighted_denoising_normal=bpy.app.version >= (5, 2, 0),  # as this Blender's Cycles writes it
        vector_background=bpy.app.version >= properties.VECTOR_BACKGROUND_FROM,  # likewise
    )
    view_layer.use_pass_z = view_layer.use_pass_environment = view_layer.drt.use_pass_noise = False
    view_layer.use_pass_mist = view_layer.use_pass_object_index = view_layer.use_pass_material_index = False
    assert properties.settings_from_scene(scene, view_layer).passes == ("Combined",)


class RecordingLayout:
    """Enough of UILayout to run a panel's draw in background mode and record what it shows."""

    def __init__(self, drawn):
        self.drawn = drawn

    def column(self, **kwargs):
        return RecordingLayout(self.drawn)

    row = column

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{type(data).__name__} has no property {name!r}"
        self.drawn.add(name)

    def template_list(self, list_type, list_id, data, name, active_data, active_name, **kwargs):
        assert hasattr(bpy.types, list_type), f"no UI list {list_type}"
        self.prop(data, name)
        self.prop(active_data, active_name)

    def prop_search(self, data, name, search_data, search_name, **kwargs):
        self.prop(data, name)
        self.prop(search_data, search_name)

    def template_curve_mapping(self, data, name, **kwargs):
        self.prop(data, name)

    def operator(self, idname, **kwargs):
        module, name = idname.split(".")
        assert name in dir(getattr(bpy.ops, module)), f"no operator {idname}"
        return SimpleNamespace()  # its properties, which a panel may set

    def separator(self, **kwargs):
        pass

    def label(self, **kwargs):
        pass


def test_drt_panels_draw_existing_properties(drt):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    camera = bpy.data.cameras.new("Panorama")
    camera.type = "PANO"
    context = SimpleNamespace(scene=scene, view_layer=scene.view_layers[0], engine="DRT", camera=camera,
                              object=bpy.data.objects.new("Empty", None), world=bpy.data.worlds.new("World"))
    drawn = set()
    for panel in ui.classes:
        assert panel.poll(context)
        fake = SimpleNamespace(layout=RecordingLayout(drawn))
        for method in ("draw_header", "draw"):
            if hasattr(panel, method):
                getattr(panel, method)(fake, context)
    scene_settings = set(properties.DRTSceneSettings.bl_rna.properties.keys()) - {"rna_type", "name"}
    assert scene_settings <= drawn
    assert set(properties.BLENDER_PASS_TOGGLES.values()) | set(properties.DRT_PASS_TOGGLES.values()) <= drawn
    assert "aovs" in drawn  # the Shader AOV list
    assert {"lightgroups", "lightgroup"} <= drawn  # the Light Groups list, an object's and the world's group
    assert {"use_motion_blur", "motion_blur_shutter", "motion_blur_position", "filter_size",
            "film_transparent", "panorama_type", "motion_blur_shutter_curve", "rolling_shutter_type"} <= drawn
    for panorama, settings in ui.PANORAMA_SETTINGS.items():  # each type's settings are the camera's
        if panorama in camera.bl_rna.properties["panorama_type"].enum_items.keys():
            camera.panorama_type = panorama
            ui.DRT_PT_camera_panorama.draw(SimpleNamespace(layout=RecordingLayout(drawn)), context)
            assert {name for name, _ in settings} <= drawn
