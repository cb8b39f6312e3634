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

An edited scene (the viewport after a user's edit) need not be prepared from scratch:
``update(scene)`` returns a prepared scene for it that shares every part the edit left alone
and rebuilds only what it touched (``update_geometry``, ``update_materials``,
``update_lights``). The prepared scene it starts from stays valid for renders still using it.
"""
from __future__ import annotations

import copy
import hashlib
from dataclasses import fields, is_dataclass, replace

import numpy as np

from ..errors import SceneError
from ..geometry.accel import Geometry
from ..integrator.shadow_catcher import catchers_only
from ..lights.collection import Lights
from ..scene import SceneData
from ..shading.surface import MaterialShading, SurfaceAttributes, load_textures
from ..validate import validate_scene


class PreparedScene:
    """The camera-independent parts of a render of ``scene`` (see the module's docstring)."""

    def __init__(self, scene: SceneData, center=None):
        if scene.camera is None:
            raise SceneError("the scene has no camera")
        validate_scene(scene)
        self.scene = scene
        self._keys = None  # what update() compares, made at the first update
        self._catchers = _UNMADE  # the shadow catchers' own prepared scene (``catchers``), made when asked
        self.geometry = self._geometry(scene, scene.camera.matrix[:3, 3] if center is None else center)
        self.texture_warnings: list[str] = []
        self.textures = load_textures(scene, self.texture_warnings)
        self.shading = [MaterialShading(m, self.textures, []) for m in scene.materials]
        self._shading_done()
        self._lights_done()

    # -- updates: each returns a new prepared scene sharing what did not change ---------
    def update(self, scene: SceneData) -> "PreparedScene":
        """A prepared scene for ``scene``, an edit of this one's, rebuilding only the parts
        whose source changed: the geometry when a mesh or an instance did, each material that
        changed (all of them with the images), the lights after any of these or a light or
        world edit. Meshes are compared by identity (an export that keeps unchanged meshes as
        the same objects spares their Embree scenes), everything else by content. The world's
        table is kept while the world and the images are unchanged."""
        if scene.camera is None:
            raise SceneError("the scene has no camera")
        validate_scene(scene)
        if self._keys is None:
            self._keys = _Keys(self.scene)
        old, keys = self._keys, _Keys(scene, self)
        if keys.images != old.images or len(scene.materials) != len(self.scene.materials):
            changed = range(len(scene.materials))
        else:
            changed = [i for i, (a, b) in enumerate(zip(keys.materials, old.materials)) if a != b]
        geometry = keys.meshes != old.meshes or keys.instances != old.instances
        world = self.lights.environment if (keys.world, keys.images) == (old.world, old.images) else None
        new = self
        if geometry:
            new = new.update_geometry(scene, world)
        if changed:
            new = new.update_materials(scene, changed, world)
        if not geometry and not changed and keys.lights != old.lights:
            new = new.update_lights(scene, world)
        if new is self:  # nothing to rebuild: the same parts for the new scene's objects
            new = self._copy(scene)
        new._keys = keys
        return new

    def update_geometry(self, scene: SceneData, world=None) -> "PreparedScene":
        """New meshes or instance transforms: a new top-level Embree scene and triangle tables
        (around the same centre) over the Embree scenes of the meshes left as they were (only an
        edited mesh's is built again), then the lights (emissive triangles); materials and
        textures are kept. ``world``, here and in the other updates: the world's table
        (lights.environment.Environment) when the world and the images are this scene's."""
        new = self._copy(scene)
        new.geometry = new._geometry(scene, self.geometry.center, self.geometry)
        new._shading_done()
        new._lights_done(world)
        return new

    def update_materials(self, scene: SceneData, indices, world=None) -> "PreparedScene":
        """Materials ``indices`` compiled again (with the images when every one is), then the
        lights (emissive materials); the geometry is kept."""
        new = self._copy(scene)
        indices = list(indices)
        if len(indices) == len(scene.materials):
            new.texture_warnings = []
            new.textures = load_textures(scene, new.texture_warnings)
            new.shading = [None] * len(scene.materials)
        else:
            new.shading = list(self.shading)
        for i in indices:
            new.shading[i] = MaterialShading(scene.materials[i], new.textures, [])
        new._shading_done()
        new._lights_done(world)
        return new

    def update_lights(self, scene: SceneData, world=None) -> "PreparedScene":
        """Lights or the world edited: the light tables again, everything else kept."""
        new = self._copy(scene)
        new._lights_done(world)
        return new

    def _copy(self, scene: SceneData) -> "PreparedScene":
        new = copy.copy(self)
        new.scene = scene
        new._keys, new._catchers = None, _UNMADE  # of the scene it was copied from
        return new

    @property
    def catchers(self) -> "PreparedScene | None":
        """The scene of the shadow catchers alone (core.integrator.shadow_catcher), prepared at the
        first render that asks and shared by every later one (the viewport's coarse and full images,
        its orbits, an animation's frames): this scene's materials, images, world table and mesh
        Embree scenes, a top level and lights of its own. None when no object is a catcher."""
        if self._catchers is _UNMADE:
            only = catchers_only(self.scene)
            self._catchers = None if only is None else self.update_geometry(only, self.lights.environment)
        return self._catchers

    # -- the steps of a preparation -------------------------------------------------------
    def _geometry(self, scene: SceneData, center, previous: Geometry | None = None) -> Geometry:
        for mesh in scene.meshes:
            if len(mesh.material_indices) and (mesh.material_indices.max() >= len(scene.materials)
                                               or mesh.material_indices.min() < 0):
                raise SceneError(f"mesh {mesh.name!r} refers to a material that does not exist")
        return Geometry(scene, center, previous)

    def _shading_done(self) -> None:
        """What follows from the materials (and the geometry, for surface attributes)."""
        self.shaders = [sh.shader for sh in self.shading]
        # per material (and one past the end for none): casts shadow rays, continues (a material
        # with varying inputs may, whatever its fallback)
        self.lit = np.array([bool(sh.lobes) or m.varying for sh, m in zip(self.shaders, self.shading)] + [False])
        # per material (and one past the end): Cycles raises its specular normals at rims (Bump Map Correction)
        self.raises = np.array([m.material.bump_correction for m in self.shading] + [True])
        self.continues = np.array([sh.can_continue or m.varying for sh, m in zip(self.shaders, self.shading)]
                                  + [False])
        # what shader programs read at hits: a varying material's, or the AOVs' of any with a program
        programs = any(s.material.program is not None for s in self.shading)
        self.attributes = SurfaceAttributes(self.scene, self.geometry) if programs else None

    def _lights_done(self, world=None) -> None:
        self.lights = Lights(self.scene, self.geometry, self.shading, self.textures, world)

    @property
    def warnings(self) -> list[str]:
        """The scene's, the geometry's, the images' and the materials' warnings (materials add
        theirs while rendering), each once."""
        found = self.scene.warnings + self.geometry.warnings + self.texture_warnings
        return list(dict.fromkeys(found + [w for sh in self.shading for w in sh.warnings]))

    def serves(self, scene: SceneData) -> bool:
        """Whether ``scene`` is this prepared scene's with at most another camera."""
        mine = self.scene
        return all(getattr(scene, name) is getattr(mine, name) for name in _PREPARED_FIELDS)

    def adopt(self, scene: SceneData) -> SceneData:
        """``scene`` (equal to this one's but for the camera, see ``content_key``) on this one's
        parts, so a Renderer can use this prepared scene for it."""
        return replace(scene, **{name: getattr(self.scene, name) for name in _PREPARED_FIELDS})


_PREPARED_FIELDS = ("meshes", "instances", "materials", "lights", "world", "images")
_UNMADE = object()  # PreparedScene.catchers not asked for yet


class _Keys:
    """What ``PreparedScene.update`` compares: meshes by identity, the rest by digest (per
    material; ``previous``'s digests are reused for the material objects it already had)."""

    def __init__(self, scene: SceneData, previous: "PreparedScene | None" = None):
        self.meshes = [id(mesh) for mesh in scene.meshes]
        self.instances = _digest(scene.instances)
        known = {} if previous is None else dict(zip(map(id, previous.scene.materials), previous._keys.materials))
        self.materials = [known.get(id(m)) or _digest(m) for m in scene.materials]
        self.images = _digest(scene.images)
        self.world = _digest(scene.world)
        self.lights = (_digest(scene.lights), self.world)


def _digest(value) -> str | object:
    """A digest of ``value`` (see content_key); a value it cannot read gets a fresh object, so it
    never equals another and counts as changed."""
    digest = hashlib.blake2b(digest_size=20)
    try:
        _feed(digest, value)
    except TypeError:
        return object()
    return digest.hexdigest()


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
