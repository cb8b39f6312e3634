"""Evaluated objects into triangle meshes and instances, each distinct mesh once.

Which objects carry geometry follows Cycles (``object_is_geometry`` in
intern/cycles/blender/object.cpp): objects whose evaluated data is a Mesh. Curves,
surfaces, text and (in Blender 5.0) metaballs reach the renderer as separate Mesh
instances in ``depsgraph.object_instances``, so reading their own data as well
would count them twice. A metaball without such a mesh instance (older Blender)
is converted with ``to_mesh``.

Vertices stay in object space and are never flipped: for a negative-determinant
instance matrix the core flips the geometric normal itself, and transforms the
corner normals by the inverse transpose.
"""
from __future__ import annotations

import bpy
import numpy as np

from ...core.scene import Instance, Mesh
from ...core.shading.proctex.hash import hash_uint, hash_uint2, to_unit
from ..properties import lightgroup_of
from .materials import MaterialTable
from .shader_graph import ISLANDS, POINTINESS, find_rgba


def _read(collection, attribute, count, width, dtype):
    values = np.empty(count * width, dtype=dtype)
    collection.foreach_get(attribute, values)
    return values.reshape(count, width) if width > 1 else values


def _corner_normals(mesh, tri_vertices, tri_loops):
    """Shading normal per triangle corner, or None when every face is flat."""
    domain = mesh.normals_domain
    if domain == "FACE":
        return None
    if domain == "POINT":
        normals = _read(mesh.vertex_normals, "vector", len(mesh.vertices), 3, np.float32)
        return normals[tri_vertices]
    normals = _read(mesh.corner_normals, "vector", len(mesh.loops), 3, np.float32)
    return normals[tri_loops]


GENERIC = {"FLOAT": ("value", 1), "INT": ("value", 1), "BOOLEAN": ("value", 1), "INT8": ("value", 1),
           "FLOAT2": ("vector", 2), "FLOAT_VECTOR": ("vector", 3),
           "FLOAT_COLOR": ("color", 4), "BYTE_COLOR": ("color", 4), "QUATERNION": ("value", 4)}
"""Mesh attribute types Cycles reads for the Attribute node, as floats: (RNA field, components;
a quaternion's w first, as Blender stores it and Cycles reads it: w, x, y as the colour, z as alpha)."""


def _edges_to_points(mesh, values, boolean):
    """Blender's edge-to-point interpolation, which Cycles asks for: the mean of a vertex's edges'
    values (a boolean: whether any is true); 0 at a vertex without edges."""
    edges = _read(mesh.edges, "vertices", len(mesh.edges), 2, np.int64)
    total = np.zeros((len(mesh.vertices), values.shape[1]))
    count = np.zeros(len(mesh.vertices))
    for end in (0, 1):
        np.add.at(total, edges[:, end], values)
        np.add.at(count, edges[:, end], 1.0)
    if boolean:
        return (total > 0).astype(np.float32)
    return (total / np.maximum(count, 1.0)[:, None]).astype(np.float32)


def _generic_attributes(mesh, names, tri_vertices, tri_loops, out) -> None:
    """The attributes ``names`` (Geometry Nodes' float, integer, boolean, vector, 2D vector, colour
    and quaternion attributes on points, corners, faces or edges) per triangle corner into ``out``, where UV maps
    and colour attributes have not put them, as Cycles reads them: a face's value at its three
    corners, edges' carried to the points."""
    for name in names:
        attr = mesh.attributes.get(name)
        if name in out or attr is None or attr.data_type not in GENERIC:
            continue  # Cycles, too, reads no 2D integer or matrix attribute (measured: 0)
        field, width = GENERIC[attr.data_type]
        values = _read(attr.data, field, len(attr.data), width, np.float32).reshape(len(attr.data), width)
        if attr.domain == "EDGE":
            values = _edges_to_points(mesh, values, attr.data_type == "BOOLEAN")
        if attr.domain == "FACE":
            faces = _read(mesh.loop_triangles, "polygon_index", len(tri_loops), 1, np.int32)
            out[name] = np.repeat(values[faces][:, None], 3, axis=1)
        else:
            out[name] = values[tri_loops if attr.domain == "CORNER" else tri_vertices]


def _corner_attributes(mesh, tri_vertices, tri_loops):
    """(UV maps and colour attributes by name, per triangle corner; the render UV map; the
    default colour attribute)."""
    out = {}
    render_uv = None
    if len(mesh.loops):
        for layer in mesh.uv_layers:
            out[layer.name] = _read(layer.uv, "vector", len(mesh.loops), 2, np.float32)[tri_loops]
            if layer.active_render:
                render_uv = out[layer.name]
    for attr in mesh.color_attributes:
        if attr.domain not in ("POINT", "CORNER"):
            continue
        values = _read(attr.data, "color", len(attr.data), 4, np.float32)
        out[attr.name] = values[tri_vertices if attr.domain == "POINT" else tri_loops]
    name = mesh.color_attributes.default_color_name
    return out, render_uv, out.get(name) if name else None


def _tangents(mesh, uv_maps, tri_loops, attributes, warnings):
    """MikkTSpace tangents (and bitangent signs) per corner for the UV maps Normal Maps use,
    as Blender computes them, under "tangent:<map>" ('' for the render UV map)."""
    render = next((uv.name for uv in mesh.uv_layers if uv.active_render), None)
    for name in uv_maps:
        layer = name or render
        if layer is None or layer not in mesh.uv_layers:
            missing = f"no UV map '{name}'" if name else "no UV map"
            warnings.append(f"mesh '{mesh.name}': {missing} for the tangents its materials read (Cycles then "
                            "derives them from a sphere mapping of the Generated coordinates, which DRT does not)")
            continue
        try:
            mesh.calc_tangents(uvmap=layer)
        except RuntimeError:
            warnings.append(f"mesh '{mesh.name}': no tangents for its n-gons (normal maps use triangle tangents)")
            return
        n = len(mesh.loops)
        tangent = _read(mesh.loops, "tangent", n, 3, np.float32)
        sign = _read(mesh.loops, "bitangent_sign", n, 1, np.float32)
        attributes["tangent:" + name] = np.concatenate([tangent, sign[:, None]], axis=1)[tri_loops]
        mesh.free_tangents()


def island_roots(edges: np.ndarray, vertex_count: int) -> np.ndarray:
    """Per vertex, the root of its island (the vertices its edges connect) as Cycles' DisjointSet
    finds it after joining the edges in order: union by rank, the first set's root kept on ties,
    path compression. The root, not just the island, decides Random Per Island's value."""
    parents = list(range(vertex_count))
    ranks = [0] * vertex_count

    def find(x):
        root = x
        while parents[root] != root:
            root = parents[root]
        while parents[x] != root:
            parents[x], x = root, parents[x]
        return root

    for a, b in edges.tolist():
        ra, rb = find(a), find(b)
        if ra == rb:
            continue
        if ranks[ra] < ranks[rb]:
            ra, rb = rb, ra
        parents[rb] = ra
        if ranks[ra] == ranks[rb]:
            ranks[ra] += 1
    return np.array([find(v) for v in range(vertex_count)], np.int64)


def random_per_island(mesh, tri_vertices) -> np.ndarray:
    """(T,) Cycles' Random Per Island of each loop triangle: the hash of its first vertex's island root."""
    edges = _read(mesh.edges, "vertices", len(mesh.edges), 2, np.int64)
    roots = island_roots(edges, len(mesh.vertices))[tri_vertices[:, 0]]
    values = {r: to_unit(hash_uint(r)) for r in np.unique(roots).tolist()}
    return np.array([values[r] for r in roots.tolist()], np.float32)


def hash_string(name: str) -> int:
    """Cycles' hash_string (util/hash.h) of a name's UTF-8 bytes, each unsigned (as Blender's
    Cycles hashes them: measured with a non-ASCII object name)."""
    h = 0
    for byte in name.encode("utf-8"):
        h = (h * 37 + byte) & 0xFFFFFFFF
    return h


def object_random(name: str, random_id: int | None = None) -> float:
    """Object Info's Random as Cycles (blender/object.cpp, scene/object.cpp): an object's is the
    hash of its name, an instance's the depsgraph's random id, as a float in [0, 1]."""
    word = hash_uint2(hash_string(name), 0) if random_id is None else random_id & 0xFFFFFFFF
    return to_unit(word)


FLT_EPSILON = float(np.finfo(np.float32).eps)


def welded(positions: np.ndarray) -> np.ndarray:
    """Per vertex, the vertex it is welded to for Pointiness (itself if none), as Cycles'
    attr_create_pointiness: in order of coordinate sums, each vertex points to the first later
    one whose sum is within 3 FLT_EPSILON and whose squared distance is below FLT_EPSILON, and
    chains are followed to their end."""
    n = len(positions)
    order = np.argsort(positions.sum(axis=1), kind="stable")
    sums = positions.sum(axis=1)[order]
    found = np.full(n, -1, np.int64)
    for j in range(1, n):
        k = np.flatnonzero((found[:n - j] < 0) & (sums[j:] - sums[:n - j] <= 3 * FLT_EPSILON))
        if len(k) == 0:
            break
        close = ((positions[order[k + j]] - positions[order[k]]) ** 2).sum(axis=1) < FLT_EPSILON
        found[k[close]] = order[k[close] + j]
    orig = np.arange(n)
    orig[order] = np.where(found >= 0, found, order)
    while True:
        nxt = orig[orig]
        if np.array_equal(nxt, orig):
            return orig
        orig = nxt


def pointiness(positions: np.ndarray, normals: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(V,) Cycles' Pointiness (blender/mesh.cpp attr_create_pointiness): duplicate vertices
    welded, per vertex the angle between its (welded) normal and the mean direction of its edges
    over pi, then blurred with its edge neighbours."""
    n = len(positions)
    orig = welded(positions)
    normal = np.zeros((n, 3))
    np.add.at(normal, orig, normals)
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = (normal / np.where(length > 0, length, 1.0))[orig]
    pairs = np.unique(np.sort(orig[edges], axis=1), axis=0)  # each welded edge once
    v0, v1 = pairs[:, 0], pairs[:, 1]
    d = positions[v1] - positions[v0]
    dl = np.linalg.norm(d, axis=1, keepdims=True)
    d = np.where(dl > 0, d / np.where(dl > 0, dl, 1.0), 0.0)
    accum = np.zeros((n, 3))
    np.add.at(accum, v0, d)
    np.add.at(accum, v1, -d)
    count = np.bincount(v0, minlength=n) + np.bincount(v1, minlength=n)
    mean = accum / np.maximum(count, 1)[:, None]
    raw = np.where((count > 0) & (orig == np.arange(n)),
                   np.arccos(np.clip((normal * mean).sum(axis=1), -1.0, 1.0)) / np.pi, 0.0)
    data = raw.copy()
    np.add.at(data, v0, raw[v1])
    np.add.at(data, v1, raw[v0])
    data /= count + 1
    return data[orig].astype(np.float32)


def mesh_from_blender(mesh, name: str, slot_materials: np.ndarray, tangent_maps=(), warnings=None,
                      islands=False, pointy=False, generic=()) -> Mesh | None:
    """Triangulated copy of a Blender mesh; None for a mesh without faces.

    ``slot_materials`` maps the object's material slots to scene material indices;
    a face's slot index is clamped to the slots present, as Cycles does. ``tangent_maps``:
    UV maps whose tangents the materials' Normal Map nodes need; ``generic``: the names of other
    attributes their Attribute nodes read.
    """
    triangles = mesh.loop_triangles
    count = len(triangles)
    if count == 0:
        return None
    vertices = _read(mesh.vertices, "co", len(mesh.vertices), 3, np.float32)
    tri_vertices = _read(triangles, "vertices", count, 3, np.int32)
    tri_loops = _read(triangles, "loops", count, 3, np.int32)
    slots = _read(triangles, "material_index", count, 1, np.int32)
    materials = slot_materials[np.clip(slots, 0, len(slot_materials) - 1)]
    attributes, uvs, colors = _corner_attributes(mesh, tri_vertices, tri_loops)
    _generic_attributes(mesh, generic, tri_vertices, tri_loops, attributes)
    if tangent_maps and len(mesh.loops):
        _tangents(mesh, tangent_maps, tri_loops, attributes, warnings if warnings is not None else [])
    if islands:  # the same value at the three corners: read back exactly
        attributes[ISLANDS] = np.repeat(random_per_island(mesh, tri_vertices)[:, None, None], 3, axis=1).repeat(4, axis=2)
    if pointy:
        edges = _read(mesh.edges, "vertices", len(mesh.edges), 2, np.int64)
        normals = _read(mesh.vertex_normals, "vector", len(mesh.vertices), 3, np.float32)
        per_vertex = pointiness(vertices.astype(np.float64), normals.astype(np.float64), edges)
        attributes[POINTINESS] = np.repeat(per_vertex[tri_vertices][:, :, None], 4, axis=2)
    return Mesh(
        name=name,
        vertices=vertices,
        triangles=tri_vertices,
        material_indices=materials,
        corner_normals=_corner_normals(mesh, tri_vertices, tri_loops),
        uvs=uvs,
        attributes=attributes,
        colors=colors,
        texspace=(tuple(mesh.texspace_location), tuple(mesh.texspace_size)),
    )


class MeshCache:
    """Exported meshes kept from one viewport export to the next, so an edit that leaves a mesh
    alone (a transform, a material, a light) neither reads it from Blender again nor makes the
    core rebuild it (core.render.prepared compares meshes by identity).

    Keyed as GeometryExporter keys meshes (the evaluated datablock, the slots' materials) and
    the tangent maps its materials need; ``forget`` drops what the depsgraph reports as new
    geometry, and each export keeps only what it used."""

    def __init__(self):
        self._meshes: dict = {}  # key -> (Mesh, original object name, mesh name)
        self._used: set = set()

    def get(self, key):
        found = self._meshes.get(key)
        if found is not None:
            self._used.add(key)
            return found[0]
        return None

    def put(self, key, mesh, obj) -> None:
        self._meshes[key] = (mesh, obj.original.name, obj.data.name if obj.data is not None else "")
        self._used.add(key)

    def forget(self, names) -> None:
        """Drop the meshes of objects or mesh datablocks named in ``names``."""
        names = set(names)
        self._meshes = {k: v for k, v in self._meshes.items() if v[1] not in names and v[2] not in names}

    def finish(self) -> None:
        """End of an export: forget the meshes it did not use (deleted or changed objects)."""
        self._meshes = {k: v for k, v in self._meshes.items() if k in self._used}
        self._used = set()


class GeometryExporter:
    """Collects meshes and instances; a mesh shared by several instances is exported once.

    Meshes are keyed on the evaluated mesh datablock (shared by linked duplicates,
    collection instances and geometry-nodes instances of the same geometry) and on
    the scene materials of the object's slots, since object-linked slots can give
    the same mesh different materials.
    """

    def __init__(self, materials: MaterialTable, material_override=None, cache: MeshCache | None = None,
                 view_layer=None, light_groups: dict | None = None):
        self.materials = materials
        self.view_layer = view_layer  # whose holdout collections make their objects holdouts
        self.light_groups = light_groups or {}  # the view layer's light groups, name -> index
        self.cache = cache
        self.material_override = material_override
        self.meshes: list[Mesh] = []
        self.instances: list[Instance] = []
        self.keys: list = []
        """Per instance, the key that finds it again at other shutter times."""
        self._mesh_index: dict[tuple, int] = {}
        self._metaballs: list = []
        self._meshed: set[int] = set()
        self._info: dict[bytes, bool] = {}  # slot materials -> whether they read Object Info
        self._attributes_read: dict[bytes, list] = {}  # slot materials -> instance attributes they read

    def _slot_materials(self, obj) -> np.ndarray:
        """Scene material index per slot, as Cycles' ``find_used_shaders``."""
        slots = obj.material_slots
        if self.material_override is not None:
            return np.full(max(len(slots), 1), self.materials.index(self.material_override), np.int32)
        if len(slots) == 0:
            return np.zeros(1, np.int32)
        return np.array([self.materials.index(slot.material) for slot in slots], np.int32)

    def add(self, obj, matrix: np.ndarray, key=None, parent=None, random_id=None) -> None:
        """Add one evaluated object placed by ``matrix`` (``parent``: the object instancing it,
        ``random_id``: the depsgraph's random id of that instance); non-geometry objects are ignored."""
        if obj.type == "META":
            self._metaballs.append((obj, matrix, key))
        elif isinstance(obj.data, bpy.types.Mesh):
            self._meshed.add(obj.original.as_pointer())
            self._place(obj, matrix, ("mesh", obj.data.as_pointer()), key, parent, random_id)

    def finish(self) -> None:
        """Add metaballs that the depsgraph did not already hand over as mesh instances."""
        for obj, matrix, key in self._metaballs:
            if obj.original.as_pointer() not in self._meshed:
                self._place(obj, matrix, ("meta", obj.original.as_pointer()), key)
        self._metaballs.clear()
        if self.cache is not None:
            self.cache.finish()

    def _instance_attributes(self, obj, parent, slot_materials) -> dict:
        """The Object and Instancer attributes the slots' materials read, looked up as Blender
        does for Cycles: the instancing object first (Instancer only), the object, its data."""
        out = {}
        for key in self._attribute_keys(slot_materials):
            kind, name = key.split(":", 1)
            owners = ([parent] if kind == "INSTANCER" else []) + [obj, obj.data]
            out[key] = find_rgba(owners, name)
        return out

    def _attribute_keys(self, slot_materials) -> list:
        """The instance attributes the slots' materials read, found once per set of slots (ten
        thousand instances of one object would otherwise scan its programs ten thousand times)."""
        key = slot_materials.tobytes()
        found = self._attributes_read.get(key)
        if found is None:
            programs = [self.materials.materials[i].program for i in set(slot_materials.tolist())]
            found = self._attributes_read[key] = list(dict.fromkeys(
                n.params["key"] for p in programs if p is not None for n in p.nodes if n.op == "instance_attribute"))
        return found

    def _place(self, obj, matrix, source, key, parent=None, random_id=None) -> None:
        slot_materials = self._slot_materials(obj)
        mesh_key = source + (slot_materials.tobytes(),)
        index = self._mesh_index.get(mesh_key)
        if index is None:
            index = self._mesh_index[mesh_key] = self._export(obj, slot_materials)
        if index >= 0:
            random = 0.0
            if self._reads_object_info(slot_materials):
                random = object_random(obj.name, random_id)
            self.instances.append(Instance(mesh=index, matrices=matrix[None], name=obj.name,
                                           attributes=self._instance_attributes(obj, parent, slot_materials),
                                           color=tuple(obj.color), pass_index=obj.pass_index, random=random,
                                           holdout=self._holdout(parent or obj),
                                           shadow_catcher=_shadow_catcher(obj, parent),
                                           lightgroup=lightgroup_of(obj, self.light_groups),
                                           asset=asset_name(obj), **ray_visibility(obj, parent)))
            self.keys.append(key)

    def _holdout(self, obj) -> bool:
        """Whether Cycles holds the object out: its Holdout, or a holdout collection of the view
        layer; an instance takes its instancer's (Cycles' sync_object reads the parent's)."""
        return bool(obj.holdout_get(view_layer=self.view_layer))

    def _reads_object_info(self, slot_materials) -> bool:
        """Whether the slots' materials have an Object Info node, found once per set of slots (an
        object's random number is then worth hashing its name for)."""
        key = slot_materials.tobytes()
        found = self._info.get(key)
        if found is None:
            programs = [self.materials.materials[i].program for i in set(slot_materials.tolist())]
            found = self._info[key] = any(n.op == "object_info" for p in programs if p is not None for n in p.nodes)
        return found

    def _tangent_maps(self, slot_materials) -> set:
        """The UV maps whose tangents the slots' materials read (tangent-space normal maps and
        vector displacement, the Tangent node's UV map direction)."""
        maps = set()
        for index in set(slot_materials.tolist()):
            program = self.materials.materials[index].program
            if program is not None:
                maps |= {n.params.get("map", "") for n in program.nodes if n.params.get("tangents")}
        return maps

    def _needs(self, slot_materials, name) -> bool:
        """Whether the materials of these slots read the attribute ``name``."""
        programs = [self.materials.materials[i].program for i in set(slot_materials.tolist())]
        return any(n.op == "attribute" and n.params.get("name") == name
                   for p in programs if p is not None for n in p.nodes)

    def _attribute_names(self, slot_materials) -> tuple:
        """The mesh attributes the slots' materials read by name (Attribute, Color Attribute)."""
        programs = [self.materials.materials[i].program for i in set(slot_materials.tolist())]
        return tuple(sorted({n.params["name"] for p in programs if p is not None for n in p.nodes
                             if n.op == "attribute" and n.params["name"] not in (ISLANDS, POINTINESS)}))

    def _export(self, obj, slot_materials) -> int:
        maps = self._tangent_maps(slot_materials)
        islands, pointy = self._needs(slot_materials, ISLANDS), self._needs(slot_materials, POINTINESS)
        generic = self._attribute_names(slot_materials)
        warnings = self.materials.warnings
        cache_key = None
        if self.cache is not None and obj.type != "META":
            cache_key = (obj.data.as_pointer(), slot_materials.tobytes(), tuple(sorted(maps)), islands, pointy, generic)
            mesh = self.cache.get(cache_key)
            if mesh is not None:
                self.meshes.append(mesh)
                return len(self.meshes) - 1
        if obj.type == "META":
            try:
                mesh = mesh_from_blender(obj.to_mesh(), obj.name, slot_materials, maps, warnings, islands, pointy,
                                         generic)
            finally:
                obj.to_mesh_clear()
        else:
            mesh = mesh_from_blender(obj.data, obj.data.name, slot_materials, maps, warnings, islands, pointy, generic)
        if mesh is None:
            return -1
        if cache_key is not None:
            self.cache.put(cache_key, mesh, obj)
        self.meshes.append(mesh)
        return len(self.meshes) - 1


RAY_KINDS = ("camera", "shadow", "diffuse", "glossy", "transmission")


def asset_name(obj) -> str:
    """Cryptomatte's asset of ``obj``: its top-level parent's name, empty for an object without a
    parent (its own name; Cycles' sync_object)."""
    top = obj.parent
    while top is not None and top.parent is not None:
        top = top.parent
    return "" if top is None else top.name


def ray_visibility(obj, parent=None) -> dict:
    """The object's ray visibility as ``Instance`` fields; an instance is seen by the rays that see
    both it and its instancer, as Cycles syncs it (object_ray_visibility of both)."""
    return {f"visible_{kind}": bool(getattr(obj, f"visible_{kind}", True))
            and (parent is None or bool(getattr(parent, f"visible_{kind}", True))) for kind in RAY_KINDS}


def _shadow_catcher(obj, parent) -> bool:
    """Whether Cycles makes the object a shadow catcher: its own flag or its instancer's (sync_object)."""
    return bool(obj.is_shadow_catcher or (parent is not None and parent.is_shadow_catcher))
