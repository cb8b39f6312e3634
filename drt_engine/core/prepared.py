"""A scene prepared for tracing: everything that does not depend on the camera or the settings.

Embree scenes, triangle tables, textures, materials' shaders, lights and their tables are
built once and shared by every render of the scene (a viewport orbiting it, the frames of
an animation whose camera alone moves, a benchmark's repeated renders): ``Renderer(scene,
settings, prepared)`` with a SceneData whose camera may differ. Renders only read it, so
several may use it at once.
"""
from __future__ import annotations

import numpy as np

from . import microfacet as mf
from .accel import Geometry
from .errors import SceneError
from .lights import Lights
from .scene import SceneData
from .shading import MaterialShading, SurfaceAttributes, load_textures
from .validate import validate_content


def geometry_center(scene: SceneData) -> np.ndarray:
    """Where Embree's float32 coordinates are centred: the median, weighted by triangles, of the
    objects' bounding-box centres. Near where most of the detail is, whatever a few far objects
    or the camera do, so precision far from the origin holds (tests/numerics) and the centre
    does not change when the camera moves."""
    centres, weights = [], []
    for inst in scene.instances:
        mesh = scene.meshes[inst.mesh]
        if len(mesh.triangles) == 0 or len(mesh.vertices) == 0:
            continue
        v = mesh.vertices[np.isfinite(mesh.vertices).all(axis=1)]
        if len(v) == 0:
            continue
        m = inst.matrices[len(inst.matrices) // 2]
        box = 0.5 * (v.min(axis=0) + v.max(axis=0))
        c = m[:3, :3] @ box + m[:3, 3]
        if np.isfinite(c).all():
            centres.append(c)
            weights.append(len(mesh.triangles))
    if not centres:
        return np.zeros(3)
    centres, weights = np.array(centres), np.array(weights, float)
    out = np.empty(3)
    for axis in range(3):
        order = np.argsort(centres[:, axis], kind="stable")
        cum = np.cumsum(weights[order])
        out[axis] = centres[order[np.searchsorted(cum, 0.5 * cum[-1])], axis]
    return out


class PreparedScene:
    """The camera-independent parts of a render of ``scene`` (see the module's docstring)."""

    def __init__(self, scene: SceneData):
        validate_content(scene)
        self.scene = scene
        self.geometry = Geometry(scene, geometry_center(scene))
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
