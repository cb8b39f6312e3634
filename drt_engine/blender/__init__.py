"""Everything that touches Blender: settings, panels, the RenderEngine, the scene export, and the
bpy calls of the headless CLI (batch.py)."""
import bpy

from ..core.base import jit
from . import engine, properties, ui, versioning

_modules = (properties, versioning, engine, ui)


def _kernel_cache():
    """Compiled kernels go to the extension's user folder, which Blender keeps writable across
    updates; loaded as a plain add-on or module (the tests, the CLI) they stay in the user's cache."""
    top = __package__.rsplit(".", 1)[0]
    if not top.startswith("bl_ext."):
        return
    try:
        jit.use_cache_dir(bpy.utils.extension_path_user(top, create=True))
    except (ValueError, OSError):
        pass


def register():
    _kernel_cache()
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
