"""Files saved by older DRT versions, brought up to date when they are loaded.

A scene's single *Clamp* (``scene.drt.clamp``, a whole sample's largest value) became Cycles' Clamp
Direct and Clamp Indirect: its value, kept in the file as an ID property the settings no longer
declare, is copied into both and dropped."""
import bpy
from bpy.app.handlers import persistent


def update_scene(scene) -> bool:
    """Bring one scene's DRT settings up to date; True when something changed."""
    drt = scene.drt
    clamp = drt.get("clamp")
    if clamp is None:
        return False
    drt.sample_clamp_direct = drt.sample_clamp_indirect = float(clamp)
    del drt["clamp"]
    return True


@persistent
def _loaded(_filepath):
    for scene in bpy.data.scenes:
        update_scene(scene)


def register():
    bpy.app.handlers.load_post.append(_loaded)


def unregister():
    if _loaded in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_loaded)
