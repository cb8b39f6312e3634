"""Exceptions the core raises with messages meant for the user."""


class DRTError(Exception):
    """Base class: the Blender layer reports these as errors, the CLI exits non-zero."""


class SceneError(DRTError):
    """The scene cannot be rendered as given (invalid light, camera, geometry...)."""


class RenderCancelled(DRTError):
    """The user or a stop rule ended the render; the image so far is still valid."""


class SettingsError(DRTError, ValueError):
    """Render settings that contradict each other (a sample range with adaptive sampling...)."""


class DenoiserError(DRTError):
    """OpenImageDenoise is missing, cannot be loaded, or reported an error."""
