"""Everything that touches Blender: settings, panels, the RenderEngine and the scene export."""
from . import engine, properties, ui

_modules = (properties, engine, ui)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
