"""The DRT RenderEngine: what Blender calls, forwarded to final.py (final renders and material
previews) and viewport.py (Rendered shading)."""
import bpy

from .final import render as final_render
from .properties import pass_layout, registered_passes, result_pass_name, view_layer_aovs
from .viewport import ViewportSession


class DRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "DRT"
    bl_label = "DRT"
    bl_use_shading_nodes_custom = False
    bl_use_preview = True
    bl_use_postprocess = True
    bl_use_eevee_viewport = True

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._viewport = None  # ViewportSession, made at the first view_update

    def render(self, depsgraph):
        final_render(self, depsgraph)

    def view_update(self, context, depsgraph):
        if self._viewport is None:
            self._viewport = ViewportSession(self)
        self._viewport.update(self, depsgraph)

    def view_draw(self, context, depsgraph):
        if self._viewport is not None:
            self._viewport.draw(self, context, depsgraph)

    def update_render_passes(self, scene=None, renderlayer=None):
        aovs = view_layer_aovs(renderlayer)
        for name in registered_passes(scene, renderlayer):
            self.register_pass(scene, renderlayer, result_pass_name(name), *pass_layout(name, aovs))


classes = (DRTRenderEngine,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
