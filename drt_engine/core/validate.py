"""Non-finite numbers in a scene, found before rendering and named for the user.

A NaN that reaches the tracer does not fail loudly: it becomes a black pixel, a wrong
error message ("geometry too far from the camera") or a NaN in one pass. Each part of
the scene is checked here once, and the first bad value is reported by where it is.
Triangles with non-finite vertices are not an error: the geometry drops them with a
warning.
"""
from __future__ import annotations

from dataclasses import fields

import numpy as np

from .errors import SceneError
from .scene import Closure, SceneData

_CLOSURE_FIELDS = tuple(f.name for f in fields(Closure) if f.type in ("float", "np.ndarray"))
"""The closure's numeric fields (its colours, weights and factors), in declaration order."""


def _finite(value) -> bool:
    return bool(np.isfinite(np.asarray(value, dtype=np.float64)).all())


def validate_scene(scene: SceneData) -> None:
    """Raise SceneError naming the first non-finite camera, light, world or material value."""
    validate_camera(scene.camera)
    validate_content(scene)


def validate_camera(cam) -> None:
    if not _finite(cam.matrices):
        raise SceneError("The camera has a location or rotation that is not a finite number")
    for name in ("frame", "clip_start", "clip_end", "aperture_radius", "focus_distance", "aperture_ratio"):
        if not _finite(getattr(cam, name)):
            raise SceneError(f"The camera's {name.replace('_', ' ')} is not a finite number")


def validate_content(scene: SceneData) -> None:
    """The scene's lights, world and materials (what a prepared scene holds, whatever the camera)."""
    for light in scene.lights:
        matrices = light.matrix if light.matrices is None else light.matrices
        if not _finite(matrices):
            raise SceneError(f"Light '{light.name}' has a location or rotation that is not a finite number")
    radiance = scene.world.radiance
    if not _finite(radiance) or (radiance < 0).any():
        raise SceneError(f"The world's colour times strength {radiance.tolist()} must be finite and not negative")
    for material in scene.materials:
        for closure in material.closures:
            for name in _CLOSURE_FIELDS:
                if not _finite(getattr(closure, name)):
                    raise SceneError(f"Material '{material.name}': the {name.replace('_', ' ')} of its "
                                     f"{closure.kind.lower()} shader is not a finite number")
