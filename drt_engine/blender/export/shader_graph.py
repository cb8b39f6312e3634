"""Shader node subgraphs compiled into a core ``Program`` (plain data, no bpy in the core).

``Compiler.value(socket)`` gives a socket's constant value when nothing varying feeds it,
or a reference ``(node, output)`` into the program. Node groups are inlined, reroutes and
muted nodes passed through. A node the core cannot evaluate yields its socket's default
value and one line in the owner's warning naming the node type.
"""
from __future__ import annotations

import bpy
import mathutils
import numpy as np

from ...core.base.colour import LUMINANCE
from ...core.scene import Program, TextureImage
from ...core.shading import nodes as sn
from ...core.shading import ies, lightpath, proctex, sky
from ...core.shading.textures import MAGENTA, openimageio_available
from .image_sequence import frame_number, frame_path
from .nodes import Issues, find_input, follow

DISPLACEMENT_FILTER_WIDTH = 0.1
"""The pixel footprint's share Cycles' bump of the Displacement socket differentiates over (the
Bump node's Filter Width default; matched against Blender 5.0's and 5.2's Cycles)."""

DISPLACEMENT_MATCHED_FROM = (4, 5)
"""The first Blender whose Cycles bumps the Displacement socket as DRT does: 4.2's differs (worst
4x4 block 0.043 on the tests' displacement scene against a limit of 0.013, 0.065 with the whole
footprint as its step); before this version the displacement is named in the material's warning."""

FALLOFF_WORLD_MATCHED_FROM = (5, 0)
"""The first Blender whose Cycles gives a world's Light Falloff as DRT does (Strength as is at the
world's FLT_MAX ray length; measured with 5.0's and 5.2's Cycles): 4.2's differs (worst 4x4 block
0.27 on the tests' Light Falloff scene against a limit of 0.043)."""
VERSION_FALLOFF_WORLD = "this Blender's Light Falloff at the world: rendered as Cycles 5.0+ computes it"

IES_MATCHED_FROM = (5, 0)
"""The first Blender whose Cycles reads and looks up an IES profile as DRT does (measured with 5.0's
and 5.2's Cycles): 4.2's takes the table's unwrapped ends as 0 and differs on the tests' lit floor
(worst 4x4 block 0.074 against a limit of 0.044, a delta point light's image mean 1% apart)."""
VERSION_IES = "this Blender's IES Texture: rendered as Cycles 5.0+ computes it"

FISHEYE_WINDOW_MATCHED_FROM = (4, 3)
"""The first Blender whose Cycles gives Texture Coordinate's Window under a fisheye as DRT does,
the image point of the ray (measured in 4.3.2, 5.0 and 5.2); 4.2's Cycles mirrors u about the
image's centre there (worst 4x4 block 0.88 on the panorama tests' Window scene)."""
VERSION_FISHEYE_WINDOW = "Window under this Blender's fisheye camera: rendered as Cycles 4.3+ computes it"

ISLANDS = "geometry:random_per_island"
POINTINESS = "geometry:pointiness"
"""The corner attributes the geometry export adds for Geometry's Random Per Island and Pointiness
(RGBA all the value)."""
RAMP_TABLE_SIZE = 256
"""Cycles' RAMP_TABLE_SIZE: colour ramps and curves reach its kernel as this many + 1 samples."""
COLORSPACES_AS_IS = ("Non-Color", "Linear Rec.709", "Linear", "Raw", "Linear CIE-XYZ E", "Linear CIE-XYZ D65",
                     "Generic Data")


def _property_rgba(owner, name):
    """Blender's find_property_rgba: a custom property ``name`` of ``owner``, else the RNA path
    ``name`` from it, as RGBA (a number n as (n, n, n, 1), up to 4 numbers over (0, 0, 0, 1));
    None when there is no such number."""
    if owner is None:
        return None
    value = None
    try:
        if name in owner.keys():
            value = owner[name]
    except (TypeError, AttributeError):  # a struct without custom properties
        pass
    if value is None:
        try:
            value = owner.path_resolve(name)
        except (KeyError, ValueError, TypeError, AttributeError):
            return None
    if isinstance(value, str):
        return None
    if isinstance(value, (bool, int, float)):
        return np.array([value, value, value, 1.0], float)
    try:
        values = [float(v) for v in value]
    except (TypeError, ValueError):
        return None
    if not 0 < len(values) <= 4:
        return None
    rgba = np.array([0.0, 0.0, 0.0, 1.0])
    rgba[:len(values)] = values
    return rgba


def find_rgba(owners, name) -> np.ndarray:
    """The first of ``owners`` (objects, datablocks, view layers) that has the attribute, as RGBA;
    zero when none has (Blender's BKE_object_dupli_find_rgba_attribute and
    BKE_view_layer_find_rgba_attribute, which Cycles reads)."""
    for owner in owners:
        rgba = _property_rgba(owner, name)
        if rgba is not None:
            return rgba
    return np.zeros(4)


def texture_mapping_matrix(mapping) -> np.ndarray | None:
    """(4, 4) of a texture node's Texture Mapping as Cycles' TextureMapping::compute_transform
    (None when it changes nothing): the axes picked first, then scale, rotation (Euler XYZ) and
    translation (Point), their inverse (Texture), without translation (Vector), or the inverse
    transpose (Normal, normalised after). Cycles reads no min/max from Blender."""
    if mapping is None:
        return None
    axes = (mapping.mapping_x, mapping.mapping_y, mapping.mapping_z)
    if not any(mapping.translation) and not any(mapping.rotation) and tuple(mapping.scale) == (1.0, 1.0, 1.0) \
            and axes == ("X", "Y", "Z"):
        return None
    pick = np.zeros((4, 4))
    pick[3, 3] = 1.0
    for row, axis in enumerate(axes):
        if axis != "NONE":
            pick[row, "XYZ".index(axis)] = 1.0
    kind = mapping.vector_type
    scale = np.array(mapping.scale, float)
    if kind in ("TEXTURE", "NORMAL"):  # kept invertible
        scale = np.where(np.abs(scale) < 1e-5, np.where(scale < 0, -1e-5, 1e-5), scale)
    linear = np.eye(4)
    linear[:3, :3] = np.array(mathutils.Euler(mapping.rotation, "XYZ").to_matrix()) @ np.diag(scale)
    full = linear.copy()
    full[:3, 3] = mapping.translation
    mat = {"POINT": full, "TEXTURE": np.linalg.inv(full), "VECTOR": linear,
           "NORMAL": np.linalg.inv(linear).T}[kind]
    return mat @ pick


def is_ref(value) -> bool:
    return isinstance(value, tuple)


class ImageTable:
    """Images used by the scene's programs, each exported once (a sequence's, once per frame shown)."""

    def __init__(self, warnings: list[str], frame: int = 1):
        self.images: list[TextureImage] = []
        self.warnings = warnings
        self.frame = frame  # the scene's, for image sequences
        self._index: dict = {}

    def index(self, image, user=None) -> int:
        """The index of ``image`` as a node with image user ``user`` shows it at this frame."""
        number = None
        if image.source == "SEQUENCE" and user is not None and image.packed_file is None:
            number = frame_number(user, self.frame)
        key = image.as_pointer() if number is None else (image.as_pointer(), number)
        found = self._index.get(key)
        if found is None:
            found = self._index[key] = len(self.images)
            self.images.append(self._export(image, number))
        return found

    def tiles(self, image) -> dict | None:
        """A UDIM image read from files: tile number -> image index (each tile a file, "<UDIM>" in
        its path replaced by the number); None for any other image."""
        if image.source != "TILED" or image.packed_file is not None or "<UDIM>" not in image.filepath:
            return None
        key = ("tiles", image.as_pointer())
        found = self._index.get(key)
        if found is None:
            found = self._index[key] = {}
            colorspace = self._colorspace(image)
            path = bpy.path.native_pathsep(bpy.path.abspath(image.filepath, library=image.library))
            for tile in image.tiles:
                found[int(tile.number)] = len(self.images)
                self.images.append(TextureImage(f"{image.name}.{tile.number}",
                                                path=path.replace("<UDIM>", str(tile.number)), colorspace=colorspace))
        return found

    def _colorspace(self, image) -> str:
        space = image.colorspace_settings.name
        if space != "sRGB" and space not in COLORSPACES_AS_IS:
            self.warnings.append(f"image '{image.name}': colour space {space} used as linear")
        return "sRGB" if space == "sRGB" else "Non-Color"

    def _export(self, image, number=None) -> TextureImage:
        """``number``: the frame of a sequence shown."""
        colorspace = self._colorspace(image)
        # Blender's own pixels where they are the only source, or where OpenImageIO is missing (not a
        # sequence's: Blender's loaded frame may not be the one shown, and its file names the reason)
        if image.packed_file is not None or image.source == "GENERATED" or (
                number is None and not openimageio_available()):
            w, h = image.size
            if w * h > 0:
                pixels = np.empty(w * h * 4, np.float32)
                image.pixels.foreach_get(pixels)
                # byte images hold encoded values; float images are linear already
                return TextureImage(image.name, pixels=pixels.reshape(h, w, 4),
                                    colorspace=colorspace if not image.is_float else "Non-Color")
        if number is not None:
            path = frame_path(bpy.path.abspath(image.filepath, library=image.library), number)
            return TextureImage(f"{image.name} frame {number}", path=bpy.path.native_pathsep(path),
                                colorspace=colorspace)
        if image.source not in ("FILE", "TILED"):
            self.warnings.append(f"image '{image.name}': {image.source.lower()} images are not supported")
        elif image.source == "TILED" and (image.packed_file is not None or "<UDIM>" not in image.filepath):
            self.warnings.append(f"image '{image.name}': packed or generated UDIM tiles are not supported "
                                 "(its first tile used everywhere)")
        path = bpy.path.abspath(image.filepath, library=image.library)
        return TextureImage(image.name, path=bpy.path.native_pathsep(path), colorspace=colorspace)


def _ies_text(node) -> tuple:
    """(the IES Texture's profile text or None, what it names): its Text datablock or its file."""
    if node.mode == "INTERNAL":
        text = node.ies
        return (text.as_string() if text is not None else None), f"text '{text.name if text else ''}'"
    path = bpy.path.native_pathsep(bpy.path.abspath(node.filepath, library=getattr(node.id_data, "library", None)))
    try:
        with open(path, encoding="latin-1") as f:
            return f.read(), f"file '{node.filepath}'"
    except OSError:
        return None, f"file '{node.filepath}'"


def _socket_kind(socket) -> str:
    return {"VALUE": "float", "INT": "float", "BOOLEAN": "float", "RGBA": "color"}.get(socket.type, "vector")


def _const(value):
    if isinstance(value, (int, float, bool)):
        return float(value)
    return np.array(value[:], dtype=np.float64)


def _fit(value, kind):
    """A constant in the shape of a socket kind (Blender's implicit conversions)."""
    if kind == "float":
        if isinstance(value, np.ndarray):
            return float(LUMINANCE @ value[:3]) if len(value) == 4 else float(value[:3].mean())
        return value
    if isinstance(value, float):
        return np.full(3, value)
    return np.asarray(value, float)[:3]


class Compiler:
    """Compiles the sockets of one material or world into one program."""

    def __init__(self, images: ImageTable, issues: Issues, world: bool = False, layer=None, pass_index=0):
        self.layer = layer  # (scene, view layer) for View Layer attributes
        self.pass_index = pass_index  # the material's, Object Info's Material Index
        self.program = Program()
        self.images = images
        self.issues = issues
        self.world = world
        self._memo: dict = {}
        self._groups: list = []  # stack of group nodes being inlined

    # -- references and constants ---------------------------------------------------
    def ref(self, value, kind=None):
        if is_ref(value):
            return value
        return self.program.add("const", value=value if kind is None else _fit(value, kind)), 0

    def op(self, name, inputs=(), **params):
        """A program node; a missing input (None) is 0, as an unconnected socket of value 0."""
        return self.program.add(name, [self.ref(0.0 if x is None else x) for x in inputs], **params)

    def mul(self, a, b):
        """a * b for two colours, folded when both are constant."""
        if not is_ref(a) and not is_ref(b):
            return np.asarray(a, float) * np.asarray(b, float)
        a3 = a if is_ref(a) else self.ref(_fit(a, "vector"))
        b3 = b if is_ref(b) else self.ref(_fit(b, "vector"))
        return self.op("vector_math", (a3, b3, np.zeros(3), 1.0), operation="MULTIPLY"), 0

    def scale(self, a, s):
        """Colour a times scalar s, folded when both are constant."""
        if not is_ref(a) and not is_ref(s):
            return np.asarray(a, float) * s
        a3 = a if is_ref(a) else self.ref(_fit(a, "vector"))
        return self.op("vector_math", (a3, np.zeros(3), np.zeros(3), s), operation="SCALE"), 0

    def emitted(self, node, weight):
        """An Emission or Background node's colour x strength, times the colour ``weight``."""
        color = self.value(find_input(node, "Color"), "color")
        return self.scale(self.mul(weight, color), self.value(find_input(node, "Strength"), "float"))

    def add_all(self, parts):
        """A reference to the sum of the colours ``parts`` (constants and references)."""
        total = self.ref(np.zeros(3))
        for p in parts:
            total = self.op("vector_math", (total, p if is_ref(p) else self.ref(_fit(p, "vector")), np.zeros(3), 1.0),
                            operation="ADD"), 0
        return total

    def clamp01(self, a):
        if not is_ref(a):
            return float(np.clip(a, 0.0, 1.0))
        return self.op("clamp", (a, 0.0, 1.0), type="MINMAX"), 0

    def one_minus(self, a):
        if not is_ref(a):
            return 1.0 - a
        return self.op("math", (self.ref(1.0), a, self.ref(0.0)), operation="SUBTRACT"), 0

    # -- sockets ----------------------------------------------------------------------
    def value(self, socket, kind=None, groups=None):
        """Constant or reference for an input socket, in ``kind`` ("float", "color", "vector"); ``groups``:
        the group nodes (outermost first) the socket's node sits inside, when not those being inlined."""
        kind = kind or _socket_kind(socket)
        default = _fit(_const(socket.default_value), kind) if hasattr(socket, "default_value") else None
        source = follow(socket, self._groups if groups is None else groups)
        if source is None:
            return default
        node, output, stack = source
        if node is None:  # an unlinked input of a group node: its value there
            return _fit(_const(output.default_value), kind) if hasattr(output, "default_value") else default
        saved, self._groups = self._groups, stack
        try:
            out = self._output(node, output)
        finally:
            self._groups = saved
        return default if out is None else self._convert(out, _socket_kind(output), kind)

    def _convert(self, value, have, want):
        if have == want or (have != "float" and want != "float"):
            return value
        if not is_ref(value):
            if want == "float" and have == "color":
                return float(LUMINANCE @ np.asarray(value, float)[:3])
            return _fit(value, want)
        kind = "float_to_vector" if have == "float" else ("color_to_float" if have == "color" else "vector_to_float")
        return self.program.add("convert", [value], kind=kind), 0

    def _output(self, node, output):
        key = (node.as_pointer(), output.identifier, tuple(g.as_pointer() for g in self._groups))
        if key not in self._memo:
            self._memo[key] = self._compile(node, output)
        return self._memo[key]

    def _in(self, node, name, kind=None):
        socket = next((s for s in node.inputs if s.identifier == name and s.enabled), None)
        if socket is None:
            socket = node.inputs.get(name)
        return self.value(socket, kind) if socket is not None else None

    def _unsupported(self, node, what=None):
        self.issues.add(f"'{node.name}' ({what or node.bl_label} node, its input's default value used)")
        return None

    # -- nodes ------------------------------------------------------------------------
    def _compile(self, node, output):
        kind = node.bl_idname
        if node.mute:
            inputs = [link.from_socket for link in node.internal_links if link.to_socket == output]
            return self.value(inputs[0], _socket_kind(output)) if inputs else None
        handler = getattr(self, "_node_" + kind, None)
        if handler is None:
            return self._unsupported(node)
        return handler(node, output)

    def _node_ShaderNodeRGB(self, node, output):
        return _const(output.default_value)[:3]

    def _node_ShaderNodeValue(self, node, output):
        return float(output.default_value)

    def _node_ShaderNodeGroup(self, node, output):
        tree = node.node_tree
        if tree is None:
            return None
        out = next((n for n in tree.nodes if n.bl_idname == "NodeGroupOutput" and n.is_active_output), None)
        out = out or next((n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"), None)
        if out is None:
            return None
        socket = next((s for s in out.inputs if s.identifier == output.identifier), None)
        if socket is None:
            return None
        self._groups.append(node)
        try:
            return self.value(socket, _socket_kind(output))
        finally:
            self._groups.pop()

    def _coord(self, name, uv_map=""):
        return self.program.add("coord", name=name, map=uv_map), 0

    def geometry_tangent(self):
        """Geometry's Tangent, what Cycles links to an unlinked Tangent socket (ShaderGraph's
        default_inputs), one program node however many closures read it."""
        key = "geometry tangent"
        if key not in self._memo:
            self._memo[key] = self._coord("tangent")
        return self._memo[key]

    def triangle_edge(self, name):
        """Cycles' sd->dPdu ("dpdu") or sd->dPdv ("dpdv") of the hit triangle, the strand a hair
        closure on a mesh shades about, one program node however many closures read it."""
        if name not in self._memo:
            self._memo[name] = self._coord(name)
        return self._memo[name]

    def _node_ShaderNodeTexCoord(self, node, output):
        name = output.identifier
        if self.world:
            return self._coord("generated")
        if getattr(node, "object", None) is not None and name == "Object":
            # Cycles: the world position in the other object's space (its inverse world matrix)
            matrix = np.linalg.inv(np.array(node.object.matrix_world, float))[:3]
            return self.op("affine", (self._coord("position"),), matrix=matrix), 0
        table = {"Generated": "generated", "UV": "uv", "Object": "object", "Normal": "normal", "Camera": "camera",
                 "Reflection": "reflection", "Window": "window"}
        if name not in table:
            return self._unsupported(node, f"Texture Coordinate {name}")
        if name == "Window" and bpy.app.version < FISHEYE_WINDOW_MATCHED_FROM and self._fisheye():
            self.issues.add(f"'{node.name}' ({VERSION_FISHEYE_WINDOW})")
        return self._coord(table[name])

    def _fisheye(self) -> bool:
        camera = self.layer[0].camera if self.layer is not None else None
        return (camera is not None and camera.type == "CAMERA" and camera.data.type == "PANO"
                and camera.data.panorama_type.startswith("FISHEYE"))

    def _node_ShaderNodeUVMap(self, node, output):
        return self._coord("uv", node.uv_map)

    def _node_ShaderNodeNewGeometry(self, node, output):
        if output.identifier == "Backfacing":
            return self.op("backfacing"), 0
        if output.identifier in ("Random Per Island", "Pointiness"):
            name = ISLANDS if output.identifier == "Random Per Island" else POINTINESS
            return self.program.add("attribute", name=name), 2  # its alpha: the value itself
        table = {"Position": "position", "Normal": "normal_world", "Incoming": "incoming",
                 "True Normal": "true_normal", "Parametric": "parametric", "Tangent": "tangent"}
        name = table.get(output.identifier)
        if name is None:
            return self._unsupported(node, f"Geometry {output.identifier}")
        return self._coord(name)

    def _attribute(self, name, output):
        i = self.program.add("attribute", name=name)
        return i, {"Color": 0, "Vector": 0, "Fac": 1, "Alpha": 2}.get(output.identifier, 0)

    def _node_ShaderNodeAttribute(self, node, output):
        kind = node.attribute_type
        which = {"Color": 0, "Vector": 0, "Fac": 1, "Alpha": 2}.get(output.identifier, 0)
        if kind in ("OBJECT", "INSTANCER"):  # per object: the geometry export looks them up
            return self.program.add("instance_attribute", key=f"{kind}:{node.attribute_name}"), which
        if kind == "VIEW_LAYER":
            if self.layer is None:
                return self._unsupported(node, "View Layer Attribute")
            scene, view_layer = self.layer
            rgba = find_rgba([view_layer, scene, scene.world], node.attribute_name)
            return (rgba[:3], float(rgba[:3].mean()), float(rgba[3]))[which]
        return self._attribute(node.attribute_name, output)

    def _node_ShaderNodeVertexColor(self, node, output):
        return self._attribute(node.layer_name, output)

    def _vector_or(self, node, default):
        """The node's Vector input when linked, else the ``default`` coordinates (a name or a
        reference), through the node's Texture Mapping (its panel hidden in Blender's UI, older
        files set it)."""
        socket = node.inputs.get("Vector")
        if socket is not None and socket.is_linked:
            vector = self.ref(self.value(socket, "vector"))
        else:
            vector = self._coord(default) if isinstance(default, str) else default
        matrix = texture_mapping_matrix(getattr(node, "texture_mapping", None))
        if matrix is None:
            return vector
        vector = self.op("affine", (vector,), matrix=matrix[:3]), 0
        if node.texture_mapping.vector_type == "NORMAL":
            vector = self.op("vector_math", (vector, np.zeros(3), np.zeros(3), 1.0), operation="NORMALIZE"), 0
        return vector

    def _no_image(self, node, output):
        """Cycles renders a texture node without an image in magenta (measured), as a missing file."""
        self.issues.add(f"'{node.name}' has no image (magenta)")
        return MAGENTA[:3].astype(float) if output.identifier == "Color" else 1.0

    def _node_ShaderNodeTexImage(self, node, output):
        if node.image is None:
            return self._no_image(node, output)
        interpolation = node.interpolation
        vector = self._vector_or(node, "generated" if self.world else "uv")
        tiles = self.images.tiles(node.image)
        first = (tiles[1001] if 1001 in tiles else min(tiles.items())[1]) if tiles else self.images.index(
            node.image, node.image_user)
        if node.projection == "BOX":
            tiles = None  # Cycles: Box projection's coordinates always fall in tile 1001
        i = self.program.add("image", [vector], image=first, interpolation=interpolation,
                             extension=node.extension, projection=node.projection,
                             blend=float(node.projection_blend), tiles=tiles)
        return i, 0 if output.identifier == "Color" else 1

    def _node_ShaderNodeTexEnvironment(self, node, output):
        if node.image is None:
            return self._no_image(node, output)
        if node.projection not in ("EQUIRECTANGULAR", "MIRROR_BALL"):
            return self._unsupported(node, f"Environment Texture {node.projection.title()} projection")
        vector = self._vector_or(node, "generated")
        i = self.program.add("environment", [vector], image=self.images.index(node.image, node.image_user),
                             interpolation=node.interpolation, projection=node.projection)
        return i, 0 if output.identifier == "Color" else 1

    def _node_ShaderNodeTexSky(self, node, output):
        if node.sky_type not in sky.SKY_TYPES:
            return self._unsupported(node, f"Sky Texture {node.sky_type.replace('_', ' ').title()}")
        vector = self._vector_or(node, "generated")
        return self.program.add("sky", [vector], sky_type=node.sky_type, sun_disc=bool(node.sun_disc),
                                sun_size=float(node.sun_size), sun_intensity=float(node.sun_intensity),
                                sun_elevation=float(node.sun_elevation), sun_rotation=float(node.sun_rotation),
                                altitude=float(node.altitude), air_density=float(node.air_density),
                                aerosol_density=float(_aerosol_density(node)),
                                ozone_density=float(node.ozone_density), sun_direction=tuple(node.sun_direction),
                                turbidity=float(node.turbidity), ground_albedo=float(node.ground_albedo)), 0

    def _node_ShaderNodeTexIES(self, node, output):
        """Cycles' IES Texture: unless its Vector is linked, the incoming direction carried into the
        object's space as a normal is (Cycles' LINK_TEXTURE_INCOMING: Geometry Incoming through a
        Vector Transform), at a light the direction from the light toward the lit point; a profile
        Cycles cannot read (no text, no file, not LM-63) gives its constant ``ies.UNREADABLE`` and is
        named."""
        text, where = _ies_text(node)
        profile = ies.parse(text) if text else None
        if profile is None:
            self.issues.add(f"'{node.name}' ({where} is no IES profile Cycles can read: {ies.UNREADABLE:g} "
                            "x Strength, as Cycles gives)")
        if bpy.app.version < IES_MATCHED_FROM:
            self.issues.add(f"'{node.name}' ({VERSION_IES})")
        incoming = self.op("vector_transform", (self._coord("incoming"),), type="NORMAL",
                           **{"from": "WORLD", "to": "OBJECT"}), 0
        vector = self._vector_or(node, incoming)
        return self.op("ies", (vector, self._in(node, "Strength", "float")), profile=profile), 0

    def _node_ShaderNodeMapping(self, node, output):
        v = self._in(node, "Vector", "vector")
        loc = self._in(node, "Location", "vector")
        rot = self._in(node, "Rotation", "vector")
        scale = self._in(node, "Scale", "vector")
        return self.op("mapping", (v, np.zeros(3) if loc is None else loc, rot, scale), type=node.vector_type), 0

    def _node_ShaderNodeMath(self, node, output):
        if node.operation not in sn.MATH_OPS:
            return self._unsupported(node, f"Math {node.operation.title()}")
        a, b, c = (self.value(s, "float") for s in list(node.inputs)[:3])
        return self.op("math", (a, b, c), operation=node.operation, clamp=node.use_clamp), 0

    def _node_ShaderNodeVectorMath(self, node, output):
        if node.operation not in sn.VECTOR_MATH_OPS:
            return self._unsupported(node, f"Vector Math {node.operation.title()}")
        a, b, c = (self.value(s, "vector") for s in list(node.inputs)[:3])
        scale = self._in(node, "Scale", "float")
        i = self.op("vector_math", (a, b, c, 1.0 if scale is None else scale), operation=node.operation)
        return i, 0 if output.identifier == "Vector" else 1

    def _mix(self, node, data_type, blend, fac, a, b, clamp_factor, clamp_result):
        if data_type == "RGBA" and blend not in sn.BLEND_MODES:
            return self._unsupported(node, f"Mix {blend.title()}")
        return self.op("mix", (fac, a, b), data_type=data_type, blend=blend, clamp_factor=clamp_factor,
                       clamp_result=clamp_result), 0

    def _node_ShaderNodeMix(self, node, output):
        t = node.data_type
        if t not in ("FLOAT", "VECTOR", "RGBA"):
            return self._unsupported(node, f"Mix {t.title()}")
        suffix = {"FLOAT": "Float", "VECTOR": "Vector", "RGBA": "Color"}[t]
        kind = {"FLOAT": "float", "VECTOR": "vector", "RGBA": "color"}[t]
        vector_fac = t == "VECTOR" and node.factor_mode == "NON_UNIFORM"
        fac = self._in(node, "Factor_Vector" if vector_fac else "Factor_Float", "vector" if vector_fac else "float")
        a = self._in(node, "A_" + suffix, kind)
        b = self._in(node, "B_" + suffix, kind)
        return self._mix(node, t, node.blend_type, fac, a, b, node.clamp_factor, node.clamp_result)

    def _node_ShaderNodeMixRGB(self, node, output):
        fac = self._in(node, "Fac", "float")
        return self._mix(node, "RGBA", node.blend_type, fac, self._in(node, "Color1", "color"),
                         self._in(node, "Color2", "color"), True, node.use_clamp)

    def _node_ShaderNodeInvert(self, node, output):
        return self.op("invert", (self._in(node, "Fac", "float"), self._in(node, "Color", "color"))), 0

    def _node_ShaderNodeGamma(self, node, output):
        return self.op("gamma", (self._in(node, "Color", "color"), self._in(node, "Gamma", "float"))), 0

    def _node_ShaderNodeHueSaturation(self, node, output):
        names = ("Hue", "Saturation", "Value", "Fac")
        args = [self._in(node, n, "float") for n in names] + [self._in(node, "Color", "color")]
        return self.op("hsv", args), 0

    def _node_ShaderNodeRGBToBW(self, node, output):
        return self.op("rgb_to_bw", (self._in(node, "Color", "color"),)), 0

    def _separate(self, node, output, mode, names):
        socket = node.inputs[0]
        i = self.op("separate", (self.value(socket, "vector"),), mode=mode)
        return i, names.index(output.identifier) if output.identifier in names else 0

    def _node_ShaderNodeSeparateColor(self, node, output):
        return self._separate(node, output, node.mode, ("Red", "Green", "Blue"))

    def _node_ShaderNodeSeparateXYZ(self, node, output):
        return self._separate(node, output, "RGB", ("X", "Y", "Z"))

    def _combine(self, node, mode):
        args = [self.value(s, "float") for s in list(node.inputs)[:3]]
        return self.op("combine", args, mode=mode), 0

    def _node_ShaderNodeCombineColor(self, node, output):
        return self._combine(node, node.mode)

    def _node_ShaderNodeCombineXYZ(self, node, output):
        return self._combine(node, "RGB")

    def _node_ShaderNodeValToRGB(self, node, output):
        ramp = node.color_ramp
        fac = self._in(node, "Fac", "float")
        out = 0 if output.identifier == "Color" else 1
        if ramp.interpolation not in ("LINEAR", "CONSTANT", "EASE") or ramp.color_mode != "RGB":
            # B-Spline, Cardinal, HSV and HSL blending: Blender's own values baked as Cycles bakes
            # every ramp (blender/util.h colorramp_to_array), read back linearly
            table = [ramp.evaluate(i / RAMP_TABLE_SIZE)[:] for i in range(RAMP_TABLE_SIZE + 1)]
            return self.op("ramp", (fac,), interpolation="TABLE", table=np.array(table, float),
                           interpolate=ramp.interpolation != "CONSTANT"), out
        elements = sorted(ramp.elements, key=lambda e: e.position)
        interpolation = ramp.interpolation if ramp.interpolation in ("CONSTANT", "EASE") else "LINEAR"
        i = self.op("ramp", (fac,), positions=[e.position for e in elements],
                    colors=[list(e.color) for e in elements], interpolation=interpolation)
        return i, out

    def _node_ShaderNodeTexChecker(self, node, output):
        args = (self._vector_or(node, "generated"), self._in(node, "Color1", "color"),
                self._in(node, "Color2", "color"), self._in(node, "Scale", "float"))
        return self.op("checker", args), 0 if output.identifier == "Color" else 1

    # -- procedural textures (core.shading.proctex) ------------------------------------------
    def _procedural(self, node, output, op, **params):
        """A procedural texture node: its vector (Generated coordinates when unlinked, as in
        Cycles), its other sockets in core.shading.proctex's order, and the output's index."""
        kinds = {"Vector": "vector", "Color1": "color", "Color2": "color", "Mortar": "color", "Orientation 3D": "vector"}
        args = [self._vector_or(node, "generated")]
        args += [self._in(node, name, kinds.get(name, "float")) for name in proctex.INPUTS[op][1:]]
        return self.op(op, args, **params), proctex.OUTPUTS[op].index(output.identifier)

    def _node_ShaderNodeTexNoise(self, node, output):
        return self._procedural(node, output, "noise", dims=int(node.noise_dimensions[0]), type=node.noise_type,
                                normalize=bool(node.normalize), color=output.identifier == "Color")

    def _node_ShaderNodeTexVoronoi(self, node, output):
        return self._procedural(node, output, "voronoi", dims=int(node.voronoi_dimensions[0]),
                                feature=node.feature, metric=node.distance, normalize=bool(node.normalize),
                                hash=proctex.HASH_PCG if bpy.app.version >= (5, 0, 0) else "lookup3")

    def _node_ShaderNodeTexWave(self, node, output):
        return self._procedural(node, output, "wave", type=node.wave_type, bands=node.bands_direction,
                                rings=node.rings_direction, profile=node.wave_profile)

    def _node_ShaderNodeTexGradient(self, node, output):
        return self._procedural(node, output, "gradient", type=node.gradient_type)

    def _node_ShaderNodeTexMagic(self, node, output):
        return self._procedural(node, output, "magic", depth=int(node.turbulence_depth))

    def _node_ShaderNodeTexWhiteNoise(self, node, output):
        return self._procedural(node, output, "white_noise", dims=int(node.noise_dimensions[0]))

    def _node_ShaderNodeTexGabor(self, node, output):
        return self._procedural(node, output, "gabor", dims=int(node.gabor_type[0]))

    def _node_ShaderNodeTexBrick(self, node, output):
        return self._procedural(node, output, "brick", offset=float(node.offset),
                                offset_frequency=int(node.offset_frequency), squash=float(node.squash),
                                squash_frequency=int(node.squash_frequency))

    def _node_ShaderNodeNormalMap(self, node, output):
        args = (self._in(node, "Strength", "float"), self._in(node, "Color", "color"))
        return self.op("normal_map", args, map=node.uv_map, space=node.space, tangents=node.space == "TANGENT"), 0

    def _bump_height(self, height, owner):
        """A bump's height; a Wireframe feeding it is named: Cycles takes that node's derivative by
        its own rule there (svm_node_wireframe's bump offsets), not DRT's finite difference."""
        stack, seen = [height[0]], set()
        while stack:
            i = stack.pop()
            if i not in seen:
                seen.add(i)
                node = self.program.nodes[i]
                if node.op == "wireframe":
                    self.issues.add(f"a Wireframe feeding {owner} (its bump as a plain difference)")
                    break
                stack.extend(r[0] for r in node.inputs if r is not None)
        return height

    def _node_ShaderNodeBump(self, node, output):
        height = self._bump_height(self.ref(self._in(node, "Height", "float"), "float"), f"'{node.name}'")
        normal_socket = node.inputs.get("Normal")
        normal = self.ref(self.value(normal_socket, "vector")) if normal_socket.is_linked else None
        # a Blender before the Filter Width input bumped over the whole pixel footprint (Blender's
        # versioning sets 1.0 on the nodes of older files)
        width = self._in(node, "Filter Width", "float") if node.inputs.get("Filter Width") else 1.0
        refs = (self.ref(self._in(node, "Strength", "float")), self.ref(self._in(node, "Distance", "float")),
                height, normal, self.ref(width))
        return self.program.add("bump", refs, invert=node.invert), 0

    def _node_ShaderNodeClamp(self, node, output):
        args = [self._in(node, n, "float") for n in ("Value", "Min", "Max")]
        return self.op("clamp", args, type=node.clamp_type), 0

    def _node_ShaderNodeMapRange(self, node, output):
        if node.data_type == "FLOAT_VECTOR":
            names = ("Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3", "To_Max_FLOAT3", "Steps_FLOAT3")
            args = [self.value(next(s for s in node.inputs if s.identifier == n), "vector") for n in names]
            return self.op("map_range_vector", args, type=node.interpolation_type, clamp=node.clamp), 0
        names = ("Value", "From Min", "From Max", "To Min", "To Max", "Steps")
        args = [self._in(node, n, "float") for n in names]
        return self.op("map_range", args, type=node.interpolation_type, clamp=node.clamp), 0

    # -- converters, colour and vector nodes that need tables or the shading point ----------------
    def _normal_in(self, node):
        """The node's Normal input when linked; unlinked, the hit's shading normal (no input)."""
        socket = node.inputs.get("Normal")
        return [self.ref(self.value(socket, "vector"))] if socket is not None and socket.is_linked else []

    def _node_ShaderNodeFresnel(self, node, output):
        return self.op("fresnel", [self._in(node, "IOR", "float")] + self._normal_in(node)), 0

    def _node_ShaderNodeLayerWeight(self, node, output):
        i = self.op("layer_weight", [self._in(node, "Blend", "float")] + self._normal_in(node))
        return i, 0 if output.identifier == "Fresnel" else 1

    def _node_ShaderNodeAmbientOcclusion(self, node, output):
        """Color times AO and AO, the share of the node's rays that reach Distance (core.shading.occlusion;
        1 in the world, where Cycles has no object to trace from). Distance 0 unlinked is Cycles'
        global radius: the world's AO distance (measured: the same image as that Distance, Fast GI
        on or off); without a world to read it from, named and traced as 0 (AO 1)."""
        distance = self._in(node, "Distance", "float")
        if not is_ref(distance) and distance == 0.0 and not self.world:
            world = self.layer[0].world if self.layer is not None else None
            if world is not None:
                distance = float(world.light_settings.distance)
            else:
                self.issues.add(f"'{node.name}' (Ambient Occlusion's Distance 0 without a world: Cycles' "
                                "global AO distance unknown, AO 1)")
        args = [self._in(node, "Color", "color"), distance] + self._normal_in(node)
        i = self.op("ao", args, samples=int(node.samples), inside=bool(node.inside), only_local=bool(node.only_local))
        return i, 0 if output.identifier == "Color" else 1

    def _node_ShaderNodeBevel(self, node, output):
        """Normal: the normals of the hit's own object within Radius, averaged as Cycles' svm_bevel
        (core.shading.bevel; the shading normal in the world, where Cycles has no object)."""
        return self.op("bevel", [self._in(node, "Radius", "float")] + self._normal_in(node),
                       samples=int(node.samples)), 0

    def _node_ShaderNodeBrightContrast(self, node, output):
        args = (self._in(node, "Color", "color"), self._in(node, "Bright", "float"),
                self._in(node, "Contrast", "float"))
        return self.op("brightness", args), 0

    def _curve_table(self, node, curves):
        """Blender's own curves sampled as Cycles samples them (blender/util.h's
        curvemapping_*_to_array): RAMP_TABLE_SIZE + 1 points over the x range of the curves'
        end points, the RGB Curves' combined curve applied before each channel's."""
        mapping = node.mapping
        mapping.initialize()
        mapping.update()
        maps = list(mapping.curves)[:curves]
        lo = min(m.points[0].location[0] for m in maps)
        hi = max(m.points[-1].location[0] for m in maps)
        xs = lo + np.arange(RAMP_TABLE_SIZE + 1) / RAMP_TABLE_SIZE * (hi - lo)
        if curves == 1:
            table = [[mapping.evaluate(maps[0], float(x))] for x in xs]
        elif curves == 4:
            table = [[mapping.evaluate(m, mapping.evaluate(maps[3], float(x))) for m in maps[:3]] for x in xs]
        else:
            table = [[mapping.evaluate(m, float(x)) for m in maps] for x in xs]
        return dict(table=np.array(table, float), min=float(lo), max=float(hi),
                    extrapolate=mapping.extend == "EXTRAPOLATED")

    def _node_ShaderNodeRGBCurve(self, node, output):
        args = (self._in(node, "Fac", "float"), self._in(node, "Color", "color"))
        return self.op("curves", args, **self._curve_table(node, 4)), 0

    def _node_ShaderNodeVectorCurve(self, node, output):
        args = (self._in(node, "Fac", "float"), self._in(node, "Vector", "vector"))
        return self.op("curves", args, **self._curve_table(node, 3)), 0

    def _node_ShaderNodeFloatCurve(self, node, output):
        args = (self._in(node, "Factor", "float"), self._in(node, "Value", "float"))
        params = self._curve_table(node, 1)
        params["table"] = params["table"][:, 0]
        return self.op("float_curve", args, **params), 0

    def _node_ShaderNodeVectorRotate(self, node, output):
        args = [self._in(node, n, "vector") for n in ("Vector", "Center", "Axis")]
        rotation = self._in(node, "Rotation", "vector") if node.rotation_type == "EULER_XYZ" else None
        args += [self._in(node, "Angle", "float"), np.zeros(3) if rotation is None else rotation]
        return self.op("vector_rotate", args, type=node.rotation_type, invert=bool(node.invert)), 0

    def _node_ShaderNodeVectorTransform(self, node, output):
        if self.world and "CAMERA" in (node.convert_from, node.convert_to):
            return self._unsupported(node, "Vector Transform to or from camera space in the world")
        return self.op("vector_transform", (self._in(node, "Vector", "vector"),), type=node.vector_type,
                       **{"from": node.convert_from, "to": node.convert_to}), 0

    def _node_ShaderNodeNormal(self, node, output):
        direction = _const(node.outputs["Normal"].default_value)
        if output.identifier == "Normal":
            return direction / max(float(np.linalg.norm(direction)), 1e-30)
        return self.op("normal", (self._in(node, "Normal", "vector"),), direction=direction), 1

    def _node_ShaderNodeBlackbody(self, node, output):
        return self.op("blackbody", (self._in(node, "Temperature", "float"),)), 0

    def _node_ShaderNodeWavelength(self, node, output):
        return self.op("wavelength", (self._in(node, "Wavelength", "float"),)), 0

    def _node_ShaderNodeLightPath(self, node, output):
        """The ray's kind, length and depths at the point (core.shading.lightpath), in the world too."""
        return self.program.add("light_path"), lightpath.OUTPUTS.index(output.identifier)

    def _node_ShaderNodeLightFalloff(self, node, output):
        """Strength over the ray's length at the point (core.shading.lightpath.falloff), in the world too
        (named in the world's warning on a Blender whose Cycles computes it otherwise there)."""
        if self.world and bpy.app.version < FALLOFF_WORLD_MATCHED_FROM:
            self.issues.add(f"'{node.name}' ({VERSION_FALLOFF_WORLD})")
        args = (self._in(node, "Strength", "float"), self._in(node, "Smooth", "float"))
        return self.op("light_falloff", args), lightpath.FALLOFF.index(output.identifier)

    # -- the hit's object, triangle and camera (core.shading.geometrynodes) ----------------------
    def _in_world(self, node) -> bool:
        """Whether the node is compiled for the world, where there is no object, triangle or surface
        point to read: then with its one warning."""
        if self.world:
            self._unsupported(node, f"{node.bl_label} in the world")
        return self.world

    def displacement(self, socket):
        """The shading normal bumped by the material output's Displacement socket, as Cycles'
        bump_from_displacement: the displacement vector's component along the unbumped normal as
        the height of a bump of strength 1 and distance 1; None when nothing varying feeds it."""
        vector = self.value(socket, "vector")
        if not is_ref(vector):
            return None  # a constant offset has no gradient
        along = self.op("vector_math", (vector, self._coord("normal_world"), np.zeros(3), 1.0), operation="DOT_PRODUCT")
        height = self._bump_height((along, 1), "the displacement")
        refs = (self.ref(1.0), self.ref(1.0), height, None, self.ref(DISPLACEMENT_FILTER_WIDTH))
        return self.program.add("bump", refs, invert=False), 0

    def _node_ShaderNodeDisplacement(self, node, output):
        if self._in_world(node):
            return None
        args = [self._in(node, n, "float") for n in ("Height", "Midlevel", "Scale")] + self._normal_in(node)
        return self.op("displacement", args, space=node.space), 0

    def _node_ShaderNodeVectorDisplacement(self, node, output):
        if self._in_world(node):
            return None
        args = (self._in(node, "Vector", "vector"), self._in(node, "Midlevel", "float"),
                self._in(node, "Scale", "float"))
        return self.op("vector_displacement", args, space=node.space, map="", tangents=node.space == "TANGENT"), 0

    def _node_ShaderNodeObjectInfo(self, node, output):
        if self.world:  # Cycles' world has no object (nor a pass index): every output 0
            return np.zeros(3) if output.identifier in ("Location", "Color") else 0.0
        if output.identifier == "Material Index":
            return float(self.pass_index)
        names = ("Location", "Color", "Alpha", "Object Index", "Random")
        return self.program.add("object_info"), names.index(output.identifier)

    def _node_ShaderNodeCameraData(self, node, output):
        if self._in_world(node):
            return None
        outputs = ("View Vector", "View Z Depth", "View Distance")
        return self.program.add("camera_data"), outputs.index(output.identifier)

    def _node_ShaderNodeWireframe(self, node, output):
        if self._in_world(node):
            return None
        return self.op("wireframe", (self._in(node, "Size", "float"),), pixel_size=bool(node.use_pixel_size)), 0

    def _node_ShaderNodeTangent(self, node, output):
        if self._in_world(node):
            return None
        uv = node.direction_type == "UV_MAP"
        return self.program.add("tangent", direction=node.direction_type, axis=node.axis,
                                map=node.uv_map if uv else "", tangents=uv), 0

    # Blender 4.x's legacy colour nodes (5.0 opens them as Separate/Combine Color)
    def _node_ShaderNodeSeparateRGB(self, node, output):
        return self._separate(node, output, "RGB", ("R", "G", "B"))

    def _node_ShaderNodeSeparateHSV(self, node, output):
        return self._separate(node, output, "HSV", ("H", "S", "V"))

    def _node_ShaderNodeCombineRGB(self, node, output):
        return self._combine(node, "RGB")

    def _node_ShaderNodeCombineHSV(self, node, output):
        return self._combine(node, "HSV")


def _aerosol_density(node) -> float:
    """The Sky Texture's aerosol density (Blender 4.x calls it dust density)."""
    return node.aerosol_density if hasattr(node, "aerosol_density") else node.dust_density
