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
        return all(getattr(scene, name) is getattr(mine, name)
                   for name in ("meshes", "instances", "materials", "lights", "world"))
