"""Per-hit materials: shader programs evaluated at the hits, bound to the BSDF lobes.

For each material with varying inputs, ``MaterialShading.bind`` evaluates the program
over all hits of the material in a wave and splits them into groups that share one
``MaterialShader``: colours and closure weights enter the lobes per hit exactly, the
other inputs (roughness, metallic, IOR, ...) are rounded to 1/256 (the precision of an
8-bit texture; coarser when several vary at once and a wave would need more than
MAX_GROUPS shaders) and each distinct combination gets its own shader, built once and
cached, since their energy tables are tabulated per lobe.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..base import vectors as vec
from ..base.constants import TINY
from ..bsdf.shader import MaterialShader, Tables
from ..geometry.camera import panorama_window
from ..scene import Closure, Material, SceneData
from . import geometrynodes as gn
from .nodes import Evaluator
from .textures import Texture

LINEAR_INPUTS = ("weight", "color", "coat_normal", "hair_tangent")
"""Inputs that enter the lobes per hit (a coat normal and a hair's strand as they are, their frames set
by the integrator);
the others key a cached shader, but for ``PER_HIT_INPUTS``."""
PER_HIT_INPUTS = ("normal", "emission", "tangent", "anisotropic_rotation")
"""Inputs read per hit outside the lobes: the shading frame's normal and tangent, emission."""
QUANTUM = 256.0
KEY_SCALE = {"thin_film_thickness": 1.0 / 256.0}
"""Keyed inputs rounded in other units than 1: a thin film's thickness (nm) in steps of 1 nm at QUANTUM."""
MIN_QUANTUM = 8.0
MAX_GROUPS = 64
CACHE_LIMIT = 4096
GRID_TABLES = Tables(grid=True)
EXACT_TABLES = Tables()


class SurfaceContext:
    """Coordinates of a batch of hits for shader programs; ``shifted`` moves them on the surface.
    ``light_path``: the rays that reached them (core.shading.lightpath.RayPath; None: light samples);
    ``occlusion``: the Ambient Occlusion node's rays from them (core.shading.occlusion; None where
    Cycles does not trace them: light samples, shadow rays)."""

    def __init__(self, attrs: "SurfaceAttributes", prim, bary, pos, normal, width=None, direction=None,
                 light_path=None, occlusion=None):
        self.attrs = attrs
        self.prim = prim
        self.bary = bary
        self.pos = pos
        self.normal = normal
        self.width = width
        self.pixel_width = width
        """The pixel's footprint across the ray, kept by ``shifted`` (which drops ``width``, so
        that lookups there filter no further)."""
        self.direction = direction
        self.light_path = light_path
        self.occlusion = occlusion
        self.n = len(prim)

    def shifted(self, dp):
        db = self.attrs.bary_shift(self.prim, dp)
        out = SurfaceContext(self.attrs, self.prim, self.bary + db, self.pos + dp, self.normal, None,
                             self.direction, self.light_path, self.occlusion)
        out.pixel_width = self.pixel_width
        return out

    def turned(self, normal):
        """The same hits with ``normal`` as their shading normal (a displacement's bump)."""
        out = SurfaceContext(self.attrs, self.prim, self.bary, self.pos, normal, self.width, self.direction,
                             self.light_path, self.occlusion)
        out.pixel_width = self.pixel_width
        return out

    def coord(self, name, uv_map=""):
        a = self.attrs
        if name == "uv":
            uv = a.corner(self.prim, self.bary, ("uv", uv_map))
            return np.concatenate([uv[:, :2], np.zeros((self.n, 1))], axis=1)
        if name == "position":
            return self.pos
        if name == "normal_world":
            return self.normal
        if name == "incoming":
            return -self.direction if self.direction is not None else self.normal
        if name == "normal":
            return a.object_normal(self.prim, self.normal)
        if name == "true_normal":  # the triangle's normal, turned to face the ray as Cycles' Ng
            ng = a.geometry.world_normals(self.prim)[0]
            return np.where(self.backfacing()[:, None], -ng, ng)
        if name == "reflection":  # the incoming direction mirrored about the shading normal
            wi = self.coord("incoming")
            return 2.0 * np.einsum("ij,ij->i", self.normal, wi)[:, None] * self.normal - wi
        if name == "camera":  # Cycles' camera space: z looks forward
            m = np.linalg.inv(self.camera_matrix())
            return self.pos @ m[:3, :3].T + m[:3, 3]
        if name == "window":
            return self._window()
        if name == "parametric":  # Cycles' (1 - u - v, u, 0): the weights of the triangle's first two corners
            return np.concatenate([self.bary[:, :2], np.zeros((self.n, 1))], axis=1)
        if name in ("dpdu", "dpdv"):  # Cycles' sd->dPdu, dPdv: the edges from the first corner, turned on back faces
            edge = a.edges(self.prim)[0 if name == "dpdu" else 1]
            return np.where(self.backfacing()[:, None], -edge, edge)
        if name == "tangent":
            return self.tangent_node("RADIAL", "Z")
        p = a.object_position(self.prim, self.bary)
        if name == "generated":
            lo, size = a.texspace(self.prim)
            return np.where(size > 0, (p - lo) / np.maximum(size, 1e-30), 0.0)
        return p  # "object"

    def attribute(self, name):
        return self.attrs.corner(self.prim, self.bary, ("color", name))

    def ambient_occlusion(self, normal, distance, samples, inside, only_local):
        """(N,) the Ambient Occlusion node's AO (core.shading.occlusion); 1 where no rays are traced."""
        if self.occlusion is None:
            return np.ones(self.n)
        return self.occlusion.unoccluded(normal, distance, samples, inside, only_local)

    def bevel(self, radius, samples):
        """(N, 3) the Bevel node's normal (core.shading.bevel); the shading normal where no rays are traced."""
        if self.occlusion is None:
            return np.array(self.normal, float)
        return self.occlusion.bevel(radius, samples)

    def instance_attribute(self, key):
        """(N, 4) RGBA of an Object or Instancer attribute of each hit's object (0 where it has none)."""
        return self.attrs.instance_attribute(self.prim, key)

    def attribute_width(self, name):
        """(N,) components of attribute ``name`` on each hit's mesh (0 where it has none)."""
        return self.attrs.width(self.prim, name)

    def tangent_node(self, direction, axis="Z", uv_map=""):
        """Cycles' svm_node_tangent (and Geometry's Tangent, its radial z): around ``axis`` through
        the Generated coordinates' centre, or the UV map's tangent (zero where the mesh has none),
        carried to the world as a normal and made perpendicular to the shading normal."""
        if direction == "UV_MAP":
            t, _, found = self.attrs.object_tangent(self.prim, self.bary, uv_map)
            t = np.where(found[:, None], t, 0.0)
        else:
            t = gn.radial_tangent(axis, self.coord("generated"))
        return gn.surface_tangent(t, self.normal, self.object_matrix())

    def object_tangent(self, uv_map):
        """(N, 3) object-space tangents of the UV map and their bitangent signs, as Vector
        Displacement reads them: the mesh's exported ones, else (no UV map) Cycles' fallback, the
        triangle's normalised dP/du (its second corner less its first, in the world) with sign 1."""
        t, sign, found = self.attrs.object_tangent(self.prim, self.bary, uv_map)
        if not found.all():
            corners = self.attrs.world_corners(self.prim)
            t = np.where(found[:, None], t, vec.normalize(corners[:, 1] - corners[:, 0], 1e-300))
        return t, sign

    def object_info(self):
        """Object Info's outputs per hit: location, colour, alpha, pass index, random."""
        return self.attrs.object_info(self.prim)

    def wireframe(self, size, pixel_size):
        """Cycles' Wireframe over the hits' triangles (mid-shutter); in pixels through the
        pixel's footprint (0 where there is none, as Cycles' light samples)."""
        width = None
        if pixel_size:
            width = self.pixel_width if self.pixel_width is not None else np.zeros(self.n)
        return gn.wireframe(self.pos, self.attrs.world_corners(self.prim), size, width)

    def _window(self):
        """Cycles' camera_world_to_ndc: the point projected into the camera's full frame, (0, 0)
        at its bottom left and (1, 1) at its top right, z 0 (a panorama's: its own projection's
        inverse, core.geometry.camera)."""
        cam = self.attrs.scene.camera
        if cam.type == "PANO":
            return np.concatenate([panorama_window(cam, self.pos), np.zeros((self.n, 1))], axis=1)
        m = np.linalg.inv(cam.matrix)
        p = self.pos @ m[:3, :3].T + m[:3, 3]
        s = p[:, :2] / np.where(p[:, 2:] < 0, -p[:, 2:], TINY) if cam.type == "PERSP" else p[:, :2]
        left, right, bottom, top = cam.frame
        return np.stack([(s[:, 0] - left) / (right - left), (s[:, 1] - bottom) / (top - bottom),
                         np.zeros(self.n)], axis=1)

    def backfacing(self):
        """Whether each hit sees the back of its triangle (Cycles' SD_BACKFACING): the ray
        against the triangle's world normal at mid-shutter."""
        if self.direction is None:
            return np.zeros(self.n, bool)
        return np.einsum("ij,ij->i", self.direction, self.attrs.geometry.world_normals(self.prim)[0]) > 0

    def object_matrix(self):
        """(N, 4, 4) object-to-world transforms of the hits' objects."""
        return self.attrs.object_matrix(self.prim)

    def camera_matrix(self):
        """(4, 4) camera-to-world transform in Cycles' camera space (Blender's camera axes with z
        negated: z looks forward), at mid-shutter."""
        return self.attrs.scene.camera.matrix @ np.diag([1.0, 1.0, -1.0, 1.0])

    def footprint(self):
        """World-space vectors spanning a pixel's footprint on the surface (major, minor axis)."""
        if self.width is None:
            return None, None
        n = self.normal
        d = self.direction
        cos = np.abs(np.einsum("ij,ij->i", d, n))
        along = d - n * np.einsum("ij,ij->i", d, n)[:, None]
        fallback = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
        along = np.where((np.linalg.norm(along, axis=1) > 1e-9)[:, None], along, fallback)
        major = vec.normalize(along, 1e-300)
        minor = vec.normalize(np.cross(n, major), 1e-300)
        w = self.width[:, None]
        return major * w / np.maximum(cos, 1e-2)[:, None], minor * w

    def tangent(self, uv_map):
        return self.attrs.tangent(self.prim, self.normal, uv_map, self.bary)

    def bump_step(self, filter_width):
        """The bump's finite-difference step: ``filter_width`` of the pixel footprint (Cycles' Filter
        Width), at least a few ulps of the position."""
        w = self.width if self.width is not None else np.zeros(self.n)
        return np.maximum(filter_width * w, 1e-6 * (1.0 + np.abs(self.pos).max(axis=1)))


class SurfaceAttributes:
    """Per-triangle access to the meshes' corner data through ``Geometry.source_of``.

    Corner data depends on the mesh only, so hits are grouped by mesh (ten thousand instances of
    one mesh are one group); what depends on the instance (its transform, Object Info, its
    attributes) is gathered per hit from arrays over the instances, made once."""

    def __init__(self, scene: SceneData, geometry):
        self.scene = scene
        self.geometry = geometry
        instances = scene.instances
        self._mesh_of = np.array([instance.mesh for instance in instances], np.int64)
        self._matrix = np.array([instance.matrix for instance in instances]).reshape(-1, 4, 4)
        self._color = np.array([instance.color for instance in instances]).reshape(-1, 4)
        self._pass_index = np.array([instance.pass_index for instance in instances], np.float64)
        self._random = np.array([instance.random for instance in instances], np.float64)
        self._instance_values = {}  # attribute key -> (instances, 4)
        self._texspaces = {}  # id(mesh) -> (corner, size); the scene outlives this object

    def _instances(self, prim):
        """The instance of each hit."""
        return self.geometry.source_of(prim)[:, 0]

    def _groups(self, prim):
        """(hits, mesh, their triangles in it) per mesh the hits ``prim`` are on."""
        source = self.geometry.source_of(prim)
        mesh = self._mesh_of[source[:, 0]]
        order = np.argsort(mesh, kind="stable")
        bounds = np.flatnonzero(np.diff(mesh[order])) + 1
        for sel in np.split(order, bounds) if len(order) else ():
            yield sel, self.scene.meshes[mesh[sel[0]]], source[sel, 1]

    def corner(self, prim, bary, key):
        kind, name = key
        width = 2 if kind == "uv" else 4
        out = np.zeros((len(prim), width))
        for sel, mesh, tri in self._groups(prim):
            if name:
                data = mesh.attributes.get(name)
            else:
                data = mesh.uvs if kind == "uv" else mesh.colors
            if data is None or data.shape[2] < (2 if kind == "uv" else 1):
                continue
            values = np.einsum("ni,nij->nj", bary[sel], data[tri].astype(np.float64))
            if kind == "color" and values.shape[1] == 1:  # a float attribute: its colour is grey, as Cycles'
                values = np.repeat(values, 3, axis=1)
            out[sel, :values.shape[1]] = values[:, :width]
            if kind == "color" and values.shape[1] < 4:
                out[sel, 3] = 1.0
        return out

    def instance_attribute(self, prim, key):
        values = self._instance_values.get(key)
        if values is None:
            none = np.zeros(4)
            values = self._instance_values[key] = np.array(
                [instance.attributes.get(key, none) for instance in self.scene.instances]).reshape(-1, 4)
        return values[self._instances(prim)]

    def width(self, prim, name):
        out = np.zeros(len(prim), np.int64)
        for sel, mesh, _ in self._groups(prim):
            data = mesh.attributes.get(name) if name else mesh.colors
            out[sel] = 0 if data is None else data.shape[2]
        return out

    def object_position(self, prim, bary):
        out = np.zeros((len(prim), 3))
        for sel, mesh, tri in self._groups(prim):
            out[sel] = np.einsum("ni,nij->nj", bary[sel], mesh.vertices[mesh.triangles[tri]])
        return out

    def object_matrix(self, prim):
        return self._matrix[self._instances(prim)]

    def object_normal(self, prim, normal):
        m = self._matrix[self._instances(prim), :3, :3]
        return vec.normalize(np.einsum("nj,njk->nk", normal, m), 1e-300)

    def texspace(self, prim):
        lo = np.zeros((len(prim), 3))
        size = np.ones((len(prim), 3))
        for sel, mesh, _ in self._groups(prim):
            lo[sel], size[sel] = self._texspace_of(mesh)
        return lo, size

    def _texspace_of(self, mesh):
        """(corner, size) of the mesh's texture space: its own, or its bounds, found once a render."""
        found = self._texspaces.get(id(mesh))
        if found is None:
            if mesh.texspace is not None:
                loc, half = (np.asarray(x, float) for x in mesh.texspace)
            else:
                a, b = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
                loc, half = 0.5 * (a + b), 0.5 * (b - a)
            found = self._texspaces[id(mesh)] = (loc - half, 2.0 * half)
        return found

    def world_corners(self, prim):
        """(N, 3, 3) world-space corners (mid-shutter) of triangles ``prim``."""
        return self.geometry.world_corners(prim)

    def edges(self, prim):
        """World-space edges (mid-shutter) of triangles ``prim`` from their first corner."""
        p = self.world_corners(prim)
        return p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]

    def object_info(self, prim):
        """Per hit: the object's location (mid-shutter), colour, alpha, pass index and random number."""
        inst = self._instances(prim)
        color = self._color[inst]
        return self._matrix[inst, :3, 3], color[:, :3], color[:, 3].copy(), self._pass_index[inst], self._random[inst]

    def object_tangent(self, prim, bary, uv_map):
        """Object-space MikkTSpace tangents of the UV map interpolated at the hits, their bitangent
        signs, and where the mesh has them."""
        n = len(prim)
        t, sign, found = np.zeros((n, 3)), np.ones(n), np.zeros(n, bool)
        for sel, mesh, tri in self._groups(prim):
            data = mesh.attributes.get("tangent:" + uv_map)
            if data is not None:
                v = np.einsum("ni,nij->nj", bary[sel], data[tri].astype(np.float64))
                t[sel], sign[sel], found[sel] = v[:, :3], np.where(v[:, 3] < 0, -1.0, 1.0), True
        return t, sign, found

    def bary_shift(self, prim, dp):
        """Barycentric change for a world-space step dp in the triangle's plane."""
        e1, e2 = self.edges(prim)
        a11 = np.einsum("ij,ij->i", e1, e1)
        a12 = np.einsum("ij,ij->i", e1, e2)
        a22 = np.einsum("ij,ij->i", e2, e2)
        r1 = np.einsum("ij,ij->i", e1, dp)
        r2 = np.einsum("ij,ij->i", e2, dp)
        det = a11 * a22 - a12 * a12
        det = np.where(np.abs(det) > 1e-300, det, 1e-300)
        b1 = (a22 * r1 - a12 * r2) / det
        b2 = (a11 * r2 - a12 * r1) / det
        return np.stack([-(b1 + b2), b1, b2], axis=1)

    def tangent(self, prim, normal, uv_map, bary=None):
        """Unit tangent along +u of the UV map, orthogonal to ``normal``, and the bitangent sign:
        the mesh's exported MikkTSpace tangents where it has them, else the triangle's dP/du."""
        t, sign = self._triangle_tangent(prim, normal, uv_map)
        if bary is None:
            return t, sign
        inst = None
        for sel, mesh, tri in self._groups(prim):
            data = mesh.attributes.get("tangent:" + uv_map)
            if data is None:
                continue
            inst = self._instances(prim) if inst is None else inst
            m = self._matrix[inst[sel], :3, :3]
            v = np.einsum("ni,nij->nj", bary[sel], data[tri].astype(np.float64))
            world = np.einsum("nkj,nj->nk", m, v[:, :3])
            world -= normal[sel] * np.einsum("ij,ij->i", world, normal[sel])[:, None]
            ok = np.linalg.norm(world, axis=1) > 1e-12
            t[sel[ok]] = vec.normalize(world[ok], 1e-300)
            det = np.linalg.det(m)
            sign[sel] = np.where(v[:, 3] < 0, -1.0, 1.0) * np.where(det == 0.0, 1.0, np.sign(det))
        return t, sign

    def _triangle_tangent(self, prim, normal, uv_map):
        bary = np.tile([1.0, 0.0, 0.0], (len(prim), 1))
        uv0 = self.corner(prim, bary, ("uv", uv_map))
        uv1 = self.corner(prim, np.tile([0.0, 1.0, 0.0], (len(prim), 1)), ("uv", uv_map))
        uv2 = self.corner(prim, np.tile([0.0, 0.0, 1.0], (len(prim), 1)), ("uv", uv_map))
        du1, dv1 = (uv1 - uv0).T
        du2, dv2 = (uv2 - uv0).T
        det = du1 * dv2 - du2 * dv1
        det = np.where(np.abs(det) > 1e-20, det, 1e-20)
        e1, e2 = self.edges(prim)
        dpdu = (e1 * dv2[:, None] - e2 * dv1[:, None]) / det[:, None]
        dpdv = (e2 * du1[:, None] - e1 * du2[:, None]) / det[:, None]
        t = vec.normalize(dpdu - normal * np.einsum("ij,ij->i", dpdu, normal)[:, None], 1e-300)
        sign = np.where(np.einsum("ij,ij->i", np.cross(normal, t), dpdv) < 0, -1.0, 1.0)
        return t, sign


VIEW_OPS = ("fresnel", "layer_weight", "backfacing", "normal_map")  # normal maps turn round on back faces
VIEW_COORDS = ("incoming", "reflection", "true_normal")


def views(program, refs) -> bool:
    """Whether the program outputs ``refs`` depend on the direction the hit is seen from (or on the
    pixel's footprint there, as a Wireframe in pixels)."""
    stack, seen = [r[0] for r in refs], set()
    while stack:
        i = stack.pop()
        if i in seen:
            continue
        seen.add(i)
        node = program.nodes[i]
        if node.op in VIEW_OPS or (node.op == "coord" and node.params.get("name") in VIEW_COORDS) \
                or (node.op == "wireframe" and node.params.get("pixel_size")):
            return True
        stack.extend(r[0] for r in node.inputs if r is not None)
    return False


class MaterialShading:
    """One material: its constant shader, or its program and the shaders bound per hit."""

    def __init__(self, material: Material, textures: list[Texture], warnings: list[str] | None = None):
        self.material = material
        self.textures = textures
        self.shader = MaterialShader(material)
        self.displaced = material.program is not None and material.displacement is not None
        self.varying = material.program is not None and (any(c.inputs for c in material.closures) or self.displaced)
        self.normal_ref = next((c.inputs["normal"] for c in material.closures if "normal" in c.inputs), None)
        self.coat_normal = any("coat_normal" in c.inputs for c in material.closures)
        self.tangent_of = next((c for c in material.closures if "tangent" in c.inputs), None)
        """The anisotropic closure whose tangent, turned about the normal, the hits' shading frame
        takes (export names any other anisotropic closure whose tangent differs)."""
        self.emitters = [c for c in material.closures if c.kind in ("EMISSION", "PRINCIPLED")
                         and ("emission" in c.inputs or ("weight" in c.inputs and np.any(c.emission > 0)))]
        self.varying_emission = material.program is not None and bool(self.emitters)
        self._cache: dict[bytes, MaterialShader] = {}
        self.coarsened = False
        self.warnings = warnings if warnings is not None else []  # the renderer's, added to while rendering
        if self.varying_emission and views(material.program, [r for c in self.emitters for k, r in c.inputs.items()
                                                               if k in ("emission", "weight")]):
            self.warnings.append(f"material '{material.name}': its emission uses Fresnel, Layer Weight, the "
                                 "incoming or reflected direction, which side is seen or a Wireframe in pixels, "
                                 "which DRT's emission does not see yet: evaluated as if seen along the surface "
                                 "normal, without a pixel footprint")

    @property
    def emission(self):
        return self.shader.emission

    def emission_at(self, ctx: SurfaceContext) -> np.ndarray:
        """(N, 3) emitted radiance of a material with varying emission at the points of ``ctx``."""
        ev = Evaluator(self.material.program, self._displaced(ctx), self.textures)
        total = np.zeros((ctx.n, 3))
        for c in self.material.closures:
            if c.kind not in ("EMISSION", "PRINCIPLED"):
                continue
            e = np.asarray(ev(c.inputs["emission"]), float) if "emission" in c.inputs else c.emission
            w = np.asarray(ev(c.inputs["weight"]), float) if "weight" in c.inputs else c.weight
            total += w * e
        return total

    def outputs(self, ctx: SurfaceContext, refs) -> list:
        """The program outputs ``refs`` at the hits of ``ctx``, after the displacement's bump (as the
        closures' inputs see them)."""
        ev = Evaluator(self.material.program, self._displaced(ctx), self.textures)
        return [ev(ref) for ref in refs]

    def bind(self, ctx: SurfaceContext):
        """[(hit indices, shader bound to them)], the per-hit shading normal (or None), the
        per-hit tangent of an anisotropic material (or None; ``tangent``) and the smooth normal
        the closures' own normal replaced (the hits' or their displacement's; None where they
        have none: what bump shadowing compares, core.bsdf.bump_shadowing)."""
        if not self.varying:
            return [(np.arange(ctx.n), self.shader)], None, None, None
        ctx = self._displaced(ctx)
        ev = Evaluator(self.material.program, ctx, self.textures)
        normal = ev(self.normal_ref) if self.normal_ref is not None else ctx.normal if self.displaced else None
        smooth = ctx.normal if self.normal_ref is not None or self.coat_normal else None
        tangent = None if self.tangent_of is None else self.tangent(ev, ctx.normal if normal is None else normal)
        linear = {}
        keyed = []
        for i, c in enumerate(self.material.closures):
            for name, ref in c.inputs.items():
                if name in PER_HIT_INPUTS:
                    continue
                value = np.asarray(ev(ref), float)
                if name in LINEAR_INPUTS:
                    linear.setdefault(i, {})[name] = np.broadcast_to(
                        value if value.ndim == 2 else value[:, None], (ctx.n, 3))
                else:
                    v = value if value.ndim == 2 else value[:, None]
                    keyed.append((i, name, v * KEY_SCALE[name] if name in KEY_SCALE else v))
        if keyed:
            keys, inverse, keyed = self._quantise(keyed)
        else:
            keys, inverse = np.zeros((1, 0)), np.zeros(ctx.n, np.int64)
        out = []
        for k, key in enumerate(keys):
            rows = np.flatnonzero(inverse == k)
            shader = self._shader_for(key, keyed, linear)
            values = {i: {name: v[rows] for name, v in d.items()} for i, d in linear.items()}
            out.append((rows, shader.bind(values) if values else shader))
        return out, normal, tangent, smooth

    def tangent(self, ev, normal):
        """(N, 3) world tangents of the anisotropic closure: its Tangent input turned about the
        normal by its rotation (turns), as Cycles' rotate_around_axis (Rodrigues' formula)."""
        c = self.tangent_of
        t = np.asarray(ev(c.inputs["tangent"]), float)
        turns = ev(c.inputs["anisotropic_rotation"]) if "anisotropic_rotation" in c.inputs else c.anisotropic_rotation
        turns = np.broadcast_to(np.asarray(turns, float).reshape(-1), (len(t),))
        if not np.any(turns != 0.0):
            return t
        n = vec.normalize(np.asarray(normal, float), 1e-300)
        angle = (2.0 * np.pi * turns)[:, None]
        cos, sin = np.cos(angle), np.sin(angle)
        return t * cos + np.cross(n, t) * sin + n * vec.dot(n, t)[:, None] * (1.0 - cos)

    def _displaced(self, ctx: SurfaceContext) -> SurfaceContext:
        """The hits with their normal bumped by the material's displacement, as Cycles evaluates
        its bump before the surface shader (whose nodes then see the bumped normal)."""
        if not self.displaced:
            return ctx
        return ctx.turned(Evaluator(self.material.program, ctx, self.textures)(self.material.displacement))

    def _quantise(self, keyed):
        """Distinct rounded values of the keyed inputs: steps of 1/QUANTUM, coarsened by halves
        while a wave would need more than MAX_GROUPS shaders (several textured inputs at once)."""
        table = np.concatenate([k[2] for k in keyed], axis=1)
        quantum = QUANTUM
        while True:
            keys, inverse = np.unique(np.round(table * quantum) / quantum, axis=0, return_inverse=True)
            if len(keys) <= MAX_GROUPS or quantum <= MIN_QUANTUM:
                break
            quantum /= 2
        if quantum < QUANTUM and not self.coarsened:
            self.coarsened = True
            film = (f" (a thin film's thickness: of {256.0 / quantum:g} nm)"
                    if any(name in KEY_SCALE for _, name, _ in keyed) else "")
            self.warnings.append(f"material '{self.material.name}': its textured inputs other than colours "
                              f"were rounded to steps of 1/{int(quantum)}{film}")
        return keys, inverse.reshape(-1), keyed

    def _shader_for(self, key, keyed, linear) -> MaterialShader:
        token = key.tobytes()
        shader = self._cache.get(token)
        if shader is not None:
            return shader
        closures = [replace(c, inputs={}) for c in self.material.closures]
        col = 0
        for i, name, v in keyed:
            width = v.shape[1]
            value = key[col:col + width]
            col += width
            if name in KEY_SCALE:
                value = value / KEY_SCALE[name]
            setattr(closures[i], name, float(value[0]) if width == 1 else np.resize(value, 3))
        for i, d in linear.items():
            for name in d:
                setattr(closures[i], name, np.ones(3))
        closures = [Closure(**{f: getattr(c, f) for f in c.__dataclass_fields__}) for c in closures]
        varying = {i: tuple(d) for i, d in linear.items()}
        shader = MaterialShader(Material(self.material.name, closures), varying, GRID_TABLES if keyed else EXACT_TABLES)
        if len(self._cache) < CACHE_LIMIT:
            self._cache[token] = shader
        return shader


def load_textures(scene: SceneData, warnings: list[str]) -> list[Texture]:
    textures = [Texture(image) for image in scene.images]
    for t in textures:
        if t.error:
            warnings.append(f"image '{t.name}' could not be read ({t.error}): rendered magenta")
    return textures
