"""A scene prepared for tracing: everything that does not depend on the camera or the settings.

Embree scenes, triangle tables, textures, materials' shaders, lights and their tables are
built once and shared by every render of the scene (a viewport orbiting it, the frames of
an animation whose camera alone moves, a benchmark's repeated renders): ``Renderer(scene,
settings, prepared)`` with a SceneData whose camera may differ. Renders only read it, so
several may use it at once.

Embree's float32 coordinates are centred on the camera the scene is prepared with (float32
is most precise where the image needs it: a 10 µm object 10 µm from the camera while a
plane lies 1e8 m away, tests/numerics); another camera keeps that centre, so its precision
degrades only with its distance from the first (an orbit or a walk through the scene, not
a jump across 1e7 m, which deserves a scene prepared for it).
"""
from __future__ import annotations

import hashlib
from dataclasses import fields, is_dataclass, replace

import numpy as np

from . import microfacet as mf
from .accel import Geometry
from .errors import SceneError
from .lights import Lights
from .scene import SceneData
from .shading import MaterialShading, SurfaceAttributes, load_textures
from .validate import validate_scene


class PreparedScene:
    """The camera-independent parts of a render of ``scene`` (see the module's docstring)."""

    def __init__(self, scene: SceneData, center=None):
        if scene.camera is None:
            raise SceneError("the scene has no camera")
        validate_scene(scene)
        self.scene = scene
        self.geometry = Geometry(scene, scene.camera.matrix[:3, 3] if center is None else center)
        for mesh in scene.meshes:
            if len(mesh.material_indices) and (mesh.material_indices.max() >= len(scene.materials)
                                               or mesh.material_indices.min() < 0):
                raise SceneError(f"mesh {mesh.name!r} refers to a material that does not exist")
        self.warnings = list(scene.warnings) + self.geometry.warnings
        textures = load_textures(scene, self.warnings)
        self.shading = [MaterialShading(m, textures, self.warnings) for m in scene.materials]
        self.shaders = [sh.shader for sh in self.shading]
        # per material (and one past the end for none): casts shadow rays, continues (a material
        # with varying inputs may, whatever its fallback)
        self.lit = np.array([bool(sh.lobes) or m.varying for sh, m in zip(self.shaders, self.shading)] + [False])
        self.continues = np.array([sh.can_continue or m.varying for sh, m in zip(self.shaders, self.shading)]
                                  + [False])
        self.attributes = SurfaceAttributes(scene, self.geometry) if any(s.varying for s in self.shading) else None
        self.lights = Lights(scene, self.geometry, self.shading, textures)
        # per triangle: emission seen when hit (constant, or from a texture)
        self.glows = (mf.max3(self.lights.tri_emission) > 0) | np.isin(self.geometry.material, self.lights.textured)

    def serves(self, scene: SceneData) -> bool:
        """Whether ``scene`` is this prepared scene's with at most another camera."""
        mine = self.scene
        return all(getattr(scene, name) is getattr(mine, name) for name in _PREPARED_FIELDS)

    def adopt(self, scene: SceneData) -> SceneData:
        """``scene`` (equal to this one's but for the camera, see ``content_key``) on this one's
        parts, so a Renderer can use this prepared scene for it."""
        return replace(scene, **{name: getattr(self.scene, name) for name in _PREPARED_FIELDS})


_PREPARED_FIELDS = ("meshes", "instances", "materials", "lights", "world", "images")


def content_key(scene: SceneData) -> str | None:
    """A digest of everything a prepared scene is made from (not the camera, the film's
    transparency or the warnings): two scenes with one key can share a prepared scene, as the
    frames of an animation where only the camera moves do. None when the scene holds a value
    the digest does not know how to read (then nothing is shared)."""
    digest = hashlib.blake2b(digest_size=20)
    try:
        for name in _PREPARED_FIELDS:
            _feed(digest, getattr(scene, name))
    except TypeError:
        return None
    return digest.hexdigest()


def _feed(digest, value) -> None:
    if isinstance(value, np.ndarray):
        digest.update(f"a{value.dtype.str}{value.shape}".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif is_dataclass(value):
        digest.update(f"d{type(value).__name__}".encode())
        for f in fields(value):
            _feed(digest, getattr(value, f.name))
    elif isinstance(value, (list, tuple)):
        digest.update(f"l{len(value)}".encode())
        for item in value:
            _feed(digest, item)
    elif isinstance(value, dict):
        digest.update(f"m{len(value)}".encode())
        for key in sorted(value, key=repr):
            _feed(digest, key)
            _feed(digest, value[key])
    elif value is None or isinstance(value, (str, int, float, bool, np.generic)):
        digest.update(f"v{type(value).__name__}{value!r};".encode())
    else:
        raise TypeError(f"no digest for {type(value).__name__}")
