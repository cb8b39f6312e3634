"""DRT: a distribution ray tracing render engine for Blender."""


def register():
    from . import blender

    blender.register()


def unregister():
    from . import blender

    blender.unregister()
