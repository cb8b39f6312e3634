"""DRT's panels, and Blender's own panels opened to DRT through their COMPAT_ENGINES.

DRT reads the camera, lights, materials, world and output settings Blender already
has, so it shows Blender's panels for them rather than copies. Panels are found by
class name and missing ones are skipped: names move between Blender 4.2 and 5.0.
"""
import bpy

from .oidn import unavailable_reason
from .presets import DRT_MT_light_paths_presets, DRT_OT_light_paths_preset

ENGINE = "DRT"

SHARED_PANELS = (
    # camera: lens, sensor, depth of field
    "DATA_PT_context_camera",
    "DATA_PT_lens",
    "DATA_PT_camera",
    "DATA_PT_camera_dof",
    "DATA_PT_camera_dof_aperture",
    # light: type, colour, power, radius, shape and size, spot cone
    "DATA_PT_context_light",
    "DATA_PT_EEVEE_light",
    "DATA_PT_spot",
    "DATA_PT_area",
    # material: slots and the surface node tree
    "EEVEE_MATERIAL_PT_context_material",
    "MATERIAL_PT_preview",
    "EEVEE_MATERIAL_PT_surface",
    # world: the surface node tree
    "WORLD_PT_context_world",
    "EEVEE_WORLD_PT_surface",
    # output and colour
    "RENDER_PT_format",
    "RENDER_PT_frame_range",
    "RENDER_PT_output",
    "RENDER_PT_color_management",
    "VIEWLAYER_PT_layer",
)
"""Blender panels DRT needs, by class name."""

GENERIC_MARKER = "BLENDER_RENDER"
"""Blender tags engine-agnostic panels (mesh data, physics, particles...) with this name."""

GENERIC_EXCLUDED = (
    "DATA_PT_light",  # type only; DATA_PT_EEVEE_light draws the full light
    "NODE_DATA_PT_light",
    "RENDER_PT_freestyle",  # DRT draws no Freestyle lines and no grease pencil
    "MATERIAL_PT_freestyle_line",
    "RENDER_PT_gpencil",
)
GENERIC_EXCLUDED_PREFIXES = (
    "VIEWLAYER_PT_freestyle",
    "RENDER_PT_grease_pencil",
    "RENDER_PT_simplify",  # registered before DRT's panels, it would sit above Sampling (Cycles hides it too)
)


_opened: list[type] = []
"""Panels whose COMPAT_ENGINES got DRT from us, so unregister takes it out of exactly those."""


def _shared_panels() -> list[type]:
    named = (getattr(bpy.types, name, None) for name in SHARED_PANELS)
    panels = [p for p in named if p is not None and hasattr(p, "COMPAT_ENGINES")]
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        name = panel.__name__
        if engines and GENERIC_MARKER in engines and name not in GENERIC_EXCLUDED:
            if not name.startswith(GENERIC_EXCLUDED_PREFIXES):
                panels.append(panel)
    return list(dict.fromkeys(panels))


def split(layout):
    """``layout`` in Blender's property-split style (labels left, no keyframe dots)."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout


class DRTButtonsPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class DRT_PT_sampling(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = split(self.layout)
        drt = context.scene.drt
        col = layout.column(align=True)
        col.prop(drt, "preview_samples")
        col.prop(drt, "samples", text="Render")
        col = layout.column()
        col.prop(drt, "sampling_pattern")
        col.prop(drt, "seed")
        col = layout.column()
        col.prop(drt, "time_limit")
        col.prop(drt, "target_error")


class DRT_PT_sampling_adaptive(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Adaptive Sampling"
    bl_parent_id = "DRT_PT_sampling"

    def draw_header(self, context):
        self.layout.prop(context.scene.drt, "use_adaptive_sampling", text="")

    def draw(self, context):
        layout = split(self.layout)
        drt = context.scene.drt
        layout.active = drt.use_adaptive_sampling
        col = layout.column()
        col.prop(drt, "adaptive_mode")
        row = col.row()
        row.active = drt.adaptive_mode == "NOISE"
        row.prop(drt, "adaptive_threshold")
        col.prop(drt, "adaptive_min_samples")


class DRT_PT_sampling_denoise(DRTButtonsPanel, bpy.types.Panel):
    """Cycles' Denoise settings: final renders and the viewport, greyed with the reason where
    Blender has no OpenImageDenoise."""
    bl_label = "Denoise"
    bl_parent_id = "DRT_PT_sampling"

    def draw(self, context):
        layout = split(self.layout)
        drt = context.scene.drt
        reason = unavailable_reason()
        col = layout.column(heading="Denoise")
        col.enabled = reason is None
        col.prop(drt, "use_denoising", text="Render")
        col.prop(drt, "use_preview_denoising", text="Viewport")
        col = layout.column()
        col.enabled = reason is None
        col.active = drt.use_denoising
        col.prop(drt, "denoising_prefilter")
        col.prop(drt, "denoising_quality")
        col = layout.column()
        col.enabled = reason is None
        col.active = drt.use_preview_denoising
        col.prop(drt, "preview_denoising_prefilter")
        col.prop(drt, "preview_denoising_quality")
        col.prop(drt, "preview_denoising_start_sample")
        if reason is not None:
            layout.label(text=reason, icon="INFO")


class DRT_PT_sampling_range(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Sample Range"
    bl_parent_id = "DRT_PT_sampling"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = split(self.layout)
        drt = context.scene.drt
        col = layout.column()
        col.prop(drt, "sample_offset", text="Offset")
        col.prop(drt, "sample_count", text="Count")


class DRT_PT_light_paths(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Light Paths"

    def draw_header_preset(self, context):
        self.layout.menu(DRT_MT_light_paths_presets.__name__, text="", icon="PRESET")

    def draw(self, context):
        layout = split(self.layout)
        drt = context.scene.drt
        col = layout.column(align=True)
        col.prop(drt, "max_depth", text="Total")
        col.prop(drt, "diffuse_bounces")
        col.prop(drt, "glossy_bounces")
        col.prop(drt, "transmission_bounces")
        col.prop(drt, "max_transparent_bounces")
        col = layout.column(align=True)
        col.active = drt.diffuse_bounces > 0  # Russian roulette ends only paths with diffuse bounces
        col.prop(drt, "min_light_bounces")
        col.prop(drt, "min_transparent_bounces")
        col = layout.column()
        col.prop(drt, "sample_clamp_direct", text="Clamp Direct")
        col.prop(drt, "sample_clamp_indirect", text="Clamp Indirect")
        col.prop(drt, "shadow_estimator")


class DRT_PT_light_paths_caustics(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Caustics"
    bl_parent_id = "DRT_PT_light_paths"

    def draw(self, context):
        layout = split(self.layout)
        layout.column().prop(context.scene.drt, "filter_glossy")


class DRT_PT_film(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Film"

    def draw(self, context):
        layout = split(self.layout)
        scene = context.scene
        col = layout.column()
        col.prop(scene.drt, "filter_type")
        col.prop(scene.render, "filter_size", text="Width")
        col.prop(scene.render, "film_transparent", text="Transparent")


class DRT_PT_motion_blur(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Motion Blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.render, "use_motion_blur", text="")

    def draw(self, context):
        layout = split(self.layout)
        render = context.scene.render
        layout.active = render.use_motion_blur
        col = layout.column()
        if hasattr(render, "motion_blur_position"):
            col.prop(render, "motion_blur_position", text="Position")
        col.prop(render, "motion_blur_shutter")
        cycles = getattr(context.scene, "cycles", None)  # Cycles' rolling shutter, which DRT renders too
        if cycles is not None:
            col.prop(cycles, "rolling_shutter_type", text="Rolling Shutter")
            sub = col.column()
            sub.active = cycles.rolling_shutter_type != "NONE"
            sub.prop(cycles, "rolling_shutter_duration", text="Duration")


class DRT_PT_motion_blur_curve(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Shutter Curve"
    bl_parent_id = "DRT_PT_motion_blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        render = context.scene.render
        self.layout.active = render.use_motion_blur
        self.layout.template_curve_mapping(render, "motion_blur_shutter_curve")


PANORAMA_SETTINGS = {  # panorama type -> (camera property, label) as Cycles' Lens panel shows them
    "EQUIRECTANGULAR": (("latitude_min", "Latitude Min"), ("latitude_max", "Max"),
                        ("longitude_min", "Longitude Min"), ("longitude_max", "Max")),
    "FISHEYE_EQUIDISTANT": (("fisheye_fov", None),),
    "FISHEYE_EQUISOLID": (("fisheye_lens", "Lens"), ("fisheye_fov", None)),
    "FISHEYE_LENS_POLYNOMIAL": (("fisheye_fov", None),) + tuple((f"fisheye_polynomial_k{i}", f"K{i}") for i in range(5)),
    "CENTRAL_CYLINDRICAL": (("central_cylindrical_range_v_min", "Height Min"), ("central_cylindrical_range_v_max", "Max"),
                            ("central_cylindrical_range_u_min", "Longitude Min"),
                            ("central_cylindrical_range_u_max", "Max"), ("central_cylindrical_radius", "Cylinder Radius")),
}


class DRT_PT_camera_panorama(DRTButtonsPanel, bpy.types.Panel):
    """The panoramic camera's projection and its settings: Blender's Lens panel shows them to Cycles only."""
    bl_label = "Panorama"
    bl_context = "data"
    bl_parent_id = "DATA_PT_lens"

    @classmethod
    def poll(cls, context):
        camera = getattr(context, "camera", None)
        return context.engine in cls.COMPAT_ENGINES and camera is not None and camera.type == "PANO"

    def draw(self, context):
        col = split(self.layout).column()
        camera = context.camera
        col.prop(camera, "panorama_type")
        for name, label in PANORAMA_SETTINGS.get(camera.panorama_type, ()):
            col.prop(camera, name, **({} if label is None else {"text": label}))


class DRT_PT_performance(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Performance"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = split(self.layout)
        layout.prop(context.scene.drt, "threads")


class DRT_PT_passes(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = split(self.layout)
        view_layer = context.view_layer
        col = layout.column(heading="Data", align=True)
        col.prop(view_layer, "use_pass_z")
        col.prop(view_layer, "use_pass_normal")
        col.prop(view_layer, "use_pass_position")
        col.prop(view_layer, "use_pass_mist")
        sub = col.column()
        sub.active = not context.scene.render.use_motion_blur  # as Cycles: with motion blur the pass is 0
        sub.prop(view_layer, "use_pass_vector")
        col.prop(view_layer.drt, "use_pass_denoising_data")
        col = layout.column(heading="Indexes", align=True)
        col.prop(view_layer, "use_pass_object_index")
        col.prop(view_layer, "use_pass_material_index")
        col.prop(view_layer, "pass_alpha_threshold")
        for heading, kind in (("Diffuse", "diffuse"), ("Glossy", "glossy"), ("Transmission", "transmission")):
            col = layout.column(heading=heading, align=True)  # Cycles' Light passes, as its panel lays them out
            col.prop(view_layer, f"use_pass_{kind}_direct", text="Direct")
            col.prop(view_layer, f"use_pass_{kind}_indirect", text="Indirect")
            col.prop(view_layer, f"use_pass_{kind}_color", text="Color")
        col = layout.column(heading="Light", align=True)
        col.prop(view_layer, "use_pass_emit", text="Emission")
        col.prop(view_layer, "use_pass_environment")
        if hasattr(view_layer, "cycles"):  # Cycles' add-on's toggle, as its Light panel shows it
            col.prop(view_layer.cycles, "use_pass_shadow_catcher")
        col = layout.column(heading="Sampling", align=True)
        col.prop(view_layer.drt, "use_pass_sample_count")
        col.prop(view_layer.drt, "use_pass_noise")


class DRT_PT_passes_cryptomatte(DRTButtonsPanel, bpy.types.Panel):
    """The view layer's Cryptomatte passes and their levels (as Cycles' panel)."""

    bl_label = "Cryptomatte"
    bl_context = "view_layer"
    bl_parent_id = "DRT_PT_passes"

    def draw(self, context):
        view_layer = context.view_layer
        col = split(self.layout).column(heading="Include", align=True)
        col.prop(view_layer, "use_pass_cryptomatte_object", text="Object")
        col.prop(view_layer, "use_pass_cryptomatte_material", text="Material")
        col.prop(view_layer, "use_pass_cryptomatte_asset", text="Asset")
        col.prop(view_layer, "pass_cryptomatte_depth", text="Levels")


class DRT_PT_passes_aov(DRTButtonsPanel, bpy.types.Panel):
    """The view layer's shader AOVs: passes the materials' AOV Output nodes write (as Cycles' panel)."""

    bl_label = "Shader AOV"
    bl_context = "view_layer"
    bl_parent_id = "DRT_PT_passes"

    def draw(self, context):
        view_layer = context.view_layer
        row = split(self.layout).row()
        row.template_list("VIEWLAYER_UL_aov", "aovs", view_layer, "aovs", view_layer, "active_aov_index", rows=3)
        buttons = row.column(align=True)
        buttons.operator("scene.view_layer_add_aov", icon="ADD", text="")
        buttons.operator("scene.view_layer_remove_aov", icon="REMOVE", text="")
        aov = view_layer.active_aov
        if aov is not None and not aov.is_valid:
            self.layout.label(text="Conflicts with another render pass with the same name", icon="ERROR")


class DRT_PT_passes_lightgroups(DRTButtonsPanel, bpy.types.Panel):
    """The view layer's light groups: a pass Combined_<group> each (as Cycles' panel)."""

    bl_label = "Light Groups"
    bl_context = "view_layer"
    bl_parent_id = "DRT_PT_passes"

    def draw(self, context):
        view_layer = context.view_layer
        row = split(self.layout).row()
        row.template_list("UI_UL_list", "lightgroups", view_layer, "lightgroups", view_layer,
                          "active_lightgroup_index", rows=3)
        buttons = row.column(align=True)
        buttons.operator("scene.view_layer_add_lightgroup", icon="ADD", text="")
        buttons.operator("scene.view_layer_remove_lightgroup", icon="REMOVE", text="")


def _lightgroup_field(layout, idblock, view_layer) -> None:
    """An object's or world's Light Group, chosen among the view layer's (a new name can be added)."""
    row = split(layout).row(align=True)
    row.prop_search(idblock, "lightgroup", view_layer, "lightgroups", text="Light Group",
                    results_are_suggestions=True)
    add = row.column(align=True)
    add.enabled = bool(idblock.lightgroup) and idblock.lightgroup not in view_layer.lightgroups
    add.operator("scene.view_layer_add_lightgroup", icon="ADD", text="").name = idblock.lightgroup


class DRT_PT_object_lightgroup(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Light Group"
    bl_context = "object"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.object is not None

    def draw(self, context):
        _lightgroup_field(self.layout, context.object, context.view_layer)


class DRT_PT_world_lightgroup(DRTButtonsPanel, bpy.types.Panel):
    bl_label = "Light Group"
    bl_context = "world"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.world is not None

    def draw(self, context):
        _lightgroup_field(self.layout, context.world, context.view_layer)


PRESET_CLASSES = (DRT_OT_light_paths_preset, DRT_MT_light_paths_presets)
"""The Light Paths panel's preset menu and what it runs."""

classes = (
    DRT_PT_sampling,
    DRT_PT_sampling_adaptive,
    DRT_PT_sampling_denoise,
    DRT_PT_sampling_range,
    DRT_PT_light_paths,
    DRT_PT_light_paths_caustics,
    DRT_PT_film,
    DRT_PT_motion_blur,
    DRT_PT_motion_blur_curve,
    DRT_PT_camera_panorama,
    DRT_PT_performance,
    DRT_PT_passes,
    DRT_PT_passes_cryptomatte,
    DRT_PT_passes_aov,
    DRT_PT_passes_lightgroups,
    DRT_PT_object_lightgroup,
    DRT_PT_world_lightgroup,
)


def register():
    for cls in PRESET_CLASSES + classes:
        bpy.utils.register_class(cls)
    for panel in _shared_panels():
        if ENGINE not in panel.COMPAT_ENGINES:
            panel.COMPAT_ENGINES.add(ENGINE)
            _opened.append(panel)


def unregister():
    while _opened:
        _opened.pop().COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(PRESET_CLASSES + classes):
        bpy.utils.unregister_class(cls)
