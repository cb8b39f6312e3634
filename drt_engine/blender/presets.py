"""The Light Paths panel's presets: classic distribution ray tracing and Cycles' Full Global
Illumination (its presets/cycles/integrator/full_global_illumination.py, in DRT's settings). The
classic preset keeps mirrors and glass followed to the Total (glossy and transmission 8, the
defaults), not Cycles' Direct Light's 1 and 2, which would darken the classic image's mirrors."""
import bpy

PRESETS = {
    "DIRECT": ("Direct light (DRT)", "Diffuse surfaces take direct light only: the classic image",
               {"max_depth": 8, "diffuse_bounces": 0, "glossy_bounces": 8, "transmission_bounces": 8,
                "min_light_bounces": 0, "min_transparent_bounces": 0, "max_transparent_bounces": 8}),
    "FULL_GI": ("Full global illumination", "Light bounces off every surface, paths ended by Russian "
                "roulette (Cycles' preset of that name)",
                {"max_depth": 128, "diffuse_bounces": 128, "glossy_bounces": 128, "transmission_bounces": 128,
                 "min_light_bounces": 3, "min_transparent_bounces": 8, "max_transparent_bounces": 128}),
}


class DRT_OT_light_paths_preset(bpy.types.Operator):
    """Set the Light Paths to a preset"""

    bl_idname = "drt.light_paths_preset"
    bl_label = "Light Paths Preset"
    bl_options = {"REGISTER", "UNDO"}

    preset: bpy.props.EnumProperty(items=[(key, name, text) for key, (name, text, _) in PRESETS.items()])

    def execute(self, context):
        for name, value in PRESETS[self.preset][2].items():
            setattr(context.scene.drt, name, value)
        return {"FINISHED"}


class DRT_MT_light_paths_presets(bpy.types.Menu):
    bl_label = "Light Paths Presets"

    def draw(self, context):
        for key, (name, _, _) in PRESETS.items():
            self.layout.operator(DRT_OT_light_paths_preset.bl_idname, text=name).preset = key
