"""Shader-node cases (converters, colour and vector nodes, Fresnel and Layer Weight) and the
scenes that show them, for the Cycles parity test: the procedural texture grid's machinery
(procedural_scenes: emissive 2 x 2 m tiles seen straight down, each case's output as the
emission colour through Vector Math Absolute) with a material per case that links every input
it can to the tile's mapped Object coordinates, so each node is evaluated over a range of
inputs. Fresnel and Layer Weight depend on the direction a hit is seen from, which the flat
tiles seen straight down hardly vary: ``facing_scene`` shows them as the colour of diffuse
spheres seen at every angle, from the front and from the back.
"""
from __future__ import annotations

import tempfile
from dataclasses import dataclass
from typing import Callable

import bpy
import mathutils
import numpy as np

from tests.support import procedural_scenes as ps
from tests.support.datablocks import new_material, new_world


@dataclass(frozen=True)
class NodeCase:
    name: str
    build: Callable  # (tree, vector socket) -> the output socket shown
    strength: float = 1.0
    mesh: tuple | None = None  # (vertices, faces) instead of the tile's one quad
    setup: Callable | None = None  # adds what the case reads to the tile's mesh


def _node(tree, kind, **props):
    node = tree.nodes.new(kind)
    for key, value in props.items():
        setattr(node, key, value)
    return node


def _link(tree, node, **inputs):
    """Link or set the node's inputs by identifier; returns the node."""
    sockets = {s.identifier: s for s in node.inputs}
    for key, value in inputs.items():
        if isinstance(value, bpy.types.NodeSocket):
            tree.links.new(value, sockets[key])
        else:
            sockets[key].default_value = value
    return node


def _affine(tree, v, scale, offset):
    """v * scale + offset, per component (Vector Math Multiply Add)."""
    node = _node(tree, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    tree.links.new(v, node.inputs[0])
    node.inputs[1].default_value = (scale,) * 3
    node.inputs[2].default_value = (offset,) * 3
    return node.outputs["Vector"]


def _unit(tree, v):
    """The tile's coordinates squeezed to about [0, 1]."""
    return _affine(tree, v, 0.3, 0.5)


def _component(tree, v, axis):
    split = _node(tree, "ShaderNodeSeparateXYZ")
    tree.links.new(v, split.inputs[0])
    return split.outputs[axis]


def _scaled(tree, value, scale, offset):
    node = _node(tree, "ShaderNodeMath", operation="MULTIPLY_ADD")
    tree.links.new(value, node.inputs[0])
    node.inputs[1].default_value = scale
    node.inputs[2].default_value = offset
    return node.outputs[0]


def _normalized(tree, v):
    node = _node(tree, "ShaderNodeVectorMath", operation="NORMALIZE")
    tree.links.new(v, node.inputs[0])
    return node.outputs["Vector"]


def _brightness(tree, v):
    node = _link(tree, _node(tree, "ShaderNodeBrightContrast"), Color=_unit(tree, v),
                 Bright=_scaled(tree, _component(tree, v, "X"), 0.2, 0.0),
                 Contrast=_scaled(tree, _component(tree, v, "Y"), 0.5, 0.1))
    return node.outputs[0]


def _shape(mapping, curve, points):
    """Give curve ``curve`` of a curve mapping these (x, y) points, the first and last moved."""
    cmap = mapping.curves[curve]
    cmap.points[0].location = points[0]
    cmap.points[-1].location = points[-1]
    for x, y in points[1:-1]:
        cmap.points.new(x, y)


def _rgb_curves(tree, v):
    node = _node(tree, "ShaderNodeRGBCurve")
    _shape(node.mapping, 3, [(0.0, 0.1), (0.5, 0.7), (1.0, 0.9)])
    _shape(node.mapping, 0, [(0.0, 0.0), (0.3, 0.1), (1.0, 1.0)])
    _shape(node.mapping, 2, [(0.0, 0.3), (0.6, 0.5), (1.0, 0.8)])
    node.mapping.update()
    return _link(tree, node, Color=_affine(tree, v, 0.45, 0.5),
                 Fac=_scaled(tree, _component(tree, v, "Z"), 0.2, 0.8)).outputs[0]


def _vector_curves(tree, v):
    node = _node(tree, "ShaderNodeVectorCurve")
    _shape(node.mapping, 0, [(-1.0, -0.5), (0.0, 0.4), (1.0, 1.0)])
    _shape(node.mapping, 1, [(-1.0, 1.0), (0.2, -0.3), (1.0, 0.2)])
    node.mapping.extend = "EXTRAPOLATED"
    node.mapping.update()
    return _link(tree, node, Vector=v, Fac=0.9).outputs[0]


def _float_curve(tree, v):
    node = _node(tree, "ShaderNodeFloatCurve")
    _shape(node.mapping, 0, [(0.0, 0.2), (0.4, 0.9), (0.7, 0.3), (1.0, 0.6)])
    node.mapping.update()
    unit = _unit(tree, v)
    return _link(tree, node, Value=_component(tree, unit, "X"), Factor=_component(tree, unit, "Y")).outputs[0]


def _rotate(kind, invert):
    def build(tree, v):
        node = _node(tree, "ShaderNodeVectorRotate", rotation_type=kind, invert=invert)
        inputs = {"Vector": v, "Center": (0.2, -0.3, 0.1), "Angle": _scaled(tree, _component(tree, v, "Y"), 1.2, 0.4)}
        if kind == "AXIS_ANGLE":
            inputs["Axis"] = _unit(tree, v)
        if kind == "EULER_XYZ":
            inputs["Rotation"] = _affine(tree, v, 0.8, 0.3)
        return _link(tree, node, **inputs).outputs[0]
    return build


def _transform(kind, src, dst, scale=1.0):
    def build(tree, v):
        node = _node(tree, "ShaderNodeVectorTransform", vector_type=kind, convert_from=src, convert_to=dst)
        # offset, so that the Absolute before the emission does not hide a sign
        return _affine(tree, _link(tree, node, Vector=v).outputs[0], scale, 0.5)
    return build


def _camera_coordinates(tree, v):
    coords = _node(tree, "ShaderNodeTexCoord")
    return _affine(tree, coords.outputs["Camera"], 0.1, 0.5)


def _window_coordinates(tree, v=None):
    return _node(tree, "ShaderNodeTexCoord").outputs["Window"]


def _other_object_coordinates(tree, v):
    """Object coordinates of an empty turned, scaled and moved in the scene."""
    empty = bpy.data.objects.new("Frame", None)
    empty.location = (1.5, -0.7, 0.4)
    empty.rotation_euler = (0.3, -0.5, 0.9)
    empty.scale = (1.5, 0.7, 1.2)
    bpy.context.scene.collection.objects.link(empty)
    coords = _node(tree, "ShaderNodeTexCoord")
    coords.object = empty
    return _affine(tree, coords.outputs["Object"], 0.15, 0.5)


def _texels():
    """An 8 x 8 packed image of random colours (one per texel, read Closest), made once."""
    image = bpy.data.images.get("Texels")
    if image is None:
        image = bpy.data.images.new("Texels", 8, 8, float_buffer=True)
        texels = np.random.default_rng(5).uniform(0.05, 1.0, (8, 8, 4)).astype(np.float32)
        texels[..., 3] = 1.0
        image.pixels.foreach_set(texels.ravel())
        image.pack()  # a generated image would be generated again (blank) for the render
    return image


def _projected(projection):
    def build(tree, v):
        node = _node(tree, "ShaderNodeTexImage", image=_texels(), interpolation="Closest", projection=projection)
        return _link(tree, node, Vector=_unit(tree, v)).outputs["Color"]
    return build


def _geometry(output, scale=1.0, offset=0.0):
    def build(tree, v):
        return _affine(tree, _node(tree, "ShaderNodeNewGeometry").outputs[output], scale, offset)
    return build


def _interpolated(interpolation, extension):
    def build(tree, v):
        node = _node(tree, "ShaderNodeTexImage", image=_texels(), interpolation=interpolation, extension=extension)
        return _link(tree, node, Vector=_affine(tree, v, 0.6, 0.5)).outputs["Color"]  # past the edges
    return build


def _islands():
    """Four quads filling the tile, the two on the left sharing an edge, the vertices listed in a
    shuffled order: three islands whose roots are not simply their first vertices."""
    corners = [(x, y, 0.0) for y in (-1.0, 0.0, 1.0) for x in (-1.0, 0.0, 1.0)]
    quads = [[(0, 1, 4, 3), (3, 4, 7, 6)], [(1, 2, 5, 4)], [(4, 5, 8, 7)]]
    vertices, faces = [], []
    for island in quads:  # each island its own copies of the corners it uses
        used = sorted({c for quad in island for c in quad})
        base = len(vertices)
        vertices += [corners[c] for c in used]
        faces += [tuple(base + used.index(c) for c in quad) for quad in island]
    order = np.random.default_rng(0).permutation(len(vertices))  # no island rooted at its smallest index
    where = np.argsort(order)
    return [vertices[i] for i in order], [tuple(int(where[c]) for c in face) for face in faces]


def _paint(mesh):
    """A corner colour attribute "Paint" and a second UV map "Extra", a value per corner."""
    colours = mesh.color_attributes.new("Paint", "FLOAT_COLOR", "CORNER")
    for i, value in enumerate(colours.data):
        value.color = ((0.9, 0.1, 0.3, 1.0), (0.2, 0.8, 0.1, 0.5), (0.1, 0.3, 0.9, 1.0), (1.0, 0.9, 0.2, 0.7))[i]
    uv = mesh.uv_layers.new(name="Extra")
    for i, value in enumerate(uv.data):
        value.uv = ((0.1, 0.9), (0.8, 0.3), (0.5, 0.5), (0.2, 0.1))[i]


def _attribute_fac(name):
    def build(tree, v):
        return _node(tree, "ShaderNodeAttribute", attribute_name=name).outputs["Fac"]
    return build


def _udim_tiles():
    """A UDIM image of tiles 1001, 1002 and 1011 (4 x 4 random texels each, EXR files in a
    temporary folder), made once."""
    image = bpy.data.images.get("Tiles")
    if image is None:
        from tests.support.textured_scenes import write_image
        folder = tempfile.mkdtemp(prefix="drt-udim-")
        rng = np.random.default_rng(8)
        for tile in (1001, 1002, 1011):
            write_image(f"{folder}/tiles.{tile}.exr", rng.uniform(0.05, 1.0, (4, 4, 3)).astype(np.float32))
        image = bpy.data.images.load(f"{folder}/tiles.1001.exr")
        image.name = "Tiles"
        image.source = "TILED"  # Blender finds the other tiles and puts <UDIM> in the path
    return image


def _udim(tree, v):
    node = _node(tree, "ShaderNodeTexImage", image=_udim_tiles(), interpolation="Closest")
    return _link(tree, node, Vector=_affine(tree, v, 0.9, 1.0)).outputs["Color"]  # tiles 1001-1012, and beyond


def _mapped(kind, vector_type, axes=("X", "Y", "Z"), image=False, **props):
    """A texture node fed by the tile's coordinates through its own Texture Mapping (an Image
    Texture reads the 8 x 8 texels)."""
    def build(tree, v):
        node = _node(tree, kind, **props)
        if image:
            node.image = _texels()
        mapping = node.texture_mapping
        mapping.vector_type = vector_type
        mapping.translation, mapping.rotation, mapping.scale = (0.3, -0.2, 0.5), (0.4, 0.2, -0.7), (1.5, 0.8, 1.2)
        mapping.mapping_x, mapping.mapping_y, mapping.mapping_z = axes
        return _link(tree, node, Vector=v).outputs[0]
    return build


def _normal_dot(tree, v):
    node = _node(tree, "ShaderNodeNormal")
    node.outputs["Normal"].default_value = (0.3, -0.5, 0.8)
    return _link(tree, node, Normal=v).outputs["Dot"]


def _blackbody(tree, v):
    node = _link(tree, _node(tree, "ShaderNodeBlackbody"),
                 Temperature=_scaled(tree, _component(tree, v, "X"), 2500.0, 5000.0))
    return node.outputs[0]


def _wavelength(tree, v):
    node = _link(tree, _node(tree, "ShaderNodeWavelength"),
                 Wavelength=_scaled(tree, _component(tree, v, "X"), 120.0, 560.0))
    return node.outputs[0]


def _separate_hsl(tree, v):
    # green the largest channel: hue away from its wrap from 1 to 0, whose edge pixels the two
    # renderers' pixel samples split differently; saturation away from white, where it is singular
    unit = _affine(tree, v, 0.2, 0.4)
    colour = _node(tree, "ShaderNodeCombineXYZ")
    tree.links.new(_component(tree, unit, "X"), colour.inputs[0])
    colour.inputs[1].default_value = 0.9
    tree.links.new(_component(tree, unit, "Z"), colour.inputs[2])
    split = _link(tree, _node(tree, "ShaderNodeSeparateColor", mode="HSL"), Color=colour.outputs[0])
    join = _node(tree, "ShaderNodeCombineXYZ")
    for i, name in enumerate(("Red", "Green", "Blue")):
        tree.links.new(split.outputs[name], join.inputs[i])
    return join.outputs[0]


def _combine_hsl(tree, v):
    unit = _unit(tree, v)
    node = _node(tree, "ShaderNodeCombineColor", mode="HSL")
    for axis, name in zip("XYZ", ("Red", "Green", "Blue")):
        tree.links.new(_component(tree, unit, axis), node.inputs[name])
    return node.outputs[0]


def _mix(blend):
    def build(tree, v):
        node = _node(tree, "ShaderNodeMix", data_type="RGBA", blend_type=blend)
        return _link(tree, node, A_Color=_unit(tree, v), B_Color=_affine(tree, v, -0.35, 0.5),
                     Factor_Float=_component(tree, _unit(tree, v), "X")).outputs[2]
    return build


def _map_range_vector(kind, clamp=True):
    def build(tree, v):
        node = _node(tree, "ShaderNodeMapRange", data_type="FLOAT_VECTOR", interpolation_type=kind, clamp=clamp)
        return _link(tree, node, Vector=v, Steps_FLOAT3=(3.0, 4.0, 5.0), From_Min_FLOAT3=(-1.0, -1.2, -0.8),
                     From_Max_FLOAT3=(1.0, 0.9, 1.1),
                     To_Min_FLOAT3=(0.1, 0.9, 0.0), To_Max_FLOAT3=_unit(tree, v)).outputs["Vector"]
    return build


def _map_range_float(kind):
    def build(tree, v):
        node = _node(tree, "ShaderNodeMapRange", data_type="FLOAT", interpolation_type=kind)
        return _link(tree, node, Value=_component(tree, v, "X"), Steps=4.0, **{"From Min": -1.2, "From Max": 1.0,
                     "To Min": 0.1, "To Max": _component(tree, _unit(tree, v), "Y")}).outputs["Result"]
    return build


def _ramp(interpolation, color_mode="RGB"):
    def build(tree, v):
        node = _node(tree, "ShaderNodeValToRGB")
        ramp = node.color_ramp
        ramp.interpolation = interpolation
        ramp.color_mode = color_mode
        ramp.elements[0].color = (0.9, 0.1, 0.1, 1.0)
        ramp.elements[1].color = (0.1, 0.2, 0.9, 1.0)
        for position, color in ((0.3, (0.1, 0.9, 0.2, 1.0)), (0.55, (1.0, 0.9, 0.1, 1.0))):
            ramp.elements.new(position).color = color
        return _link(tree, node, Fac=_component(tree, _affine(tree, v, 0.4, 0.5), "X")).outputs["Color"]
    return build


def _terrain():
    """A 5 x 5 grid of vertices over the tile, its heights a smooth bump (+-0.4 m): triangles
    facing every way for the nodes that read the surface's shape, the camera's distance or the
    triangles' edges."""
    xs = np.linspace(-1.0, 1.0, 5)
    vertices = [(x, y, 0.4 * np.sin(1.7 * x + 0.3) * np.cos(1.4 * y - 0.2)) for y in xs for x in xs]
    faces = [(5 * j + i, 5 * j + i + 1, 5 * j + i + 6, 5 * j + i + 5) for j in range(4) for i in range(4)]
    return vertices, faces


def _smooth(mesh):
    """Smooth shading: a tangent that follows the normal without a jump at the triangles' edges,
    whose pixels the renderers' samples split differently."""
    mesh.shade_smooth()


def _turned_uvs(mesh):
    """A UV map "Turned": the vertices' x and y turned by 0.6 rad and squeezed, per corner; the
    mesh smooth, since Cycles' MikkTSpace tangents of a flat-shaded quad that is not planar are
    those of its two triangles apart, and Blender's of the whole quad."""
    mesh.shade_smooth()
    uv = mesh.uv_layers.new(name="Turned")
    c, s = np.cos(0.6), np.sin(0.6)
    for loop, value in zip(mesh.loops, uv.data):
        x, y, _ = mesh.vertices[loop.vertex_index].co
        value.uv = (0.5 + 0.4 * (c * x - s * y), 0.5 + 0.3 * (s * x + c * y))


def _camera_data(output, scale, offset):
    def build(tree, v):
        value = _node(tree, "ShaderNodeCameraData").outputs[output]
        return _affine(tree, value, scale, offset) if output == "View Vector" else _scaled(tree, value, scale, offset)
    return build


def _wireframe(pixel_size, scale, offset):
    def build(tree, v):
        node = _node(tree, "ShaderNodeWireframe", use_pixel_size=pixel_size)
        return _link(tree, node, Size=_scaled(tree, _component(tree, v, "X"), scale, offset)).outputs[0]
    return build


def _tangent(direction, axis="Z", uv_map=""):
    def build(tree, v):
        node = _node(tree, "ShaderNodeTangent", direction_type=direction, axis=axis, uv_map=uv_map)
        return _affine(tree, node.outputs[0], 0.5, 0.5)
    return build


def _generic(name, data_type, domain, low=0.05, high=0.95):
    """Adds a Geometry Nodes attribute ``name`` of ``data_type`` on ``domain`` to the tile's mesh,
    random values in [low, high] (integers: 0 to 9)."""
    def setup(mesh):
        attr = mesh.attributes.new(name, data_type, domain)
        rng = np.random.default_rng(len(name))
        field = "vector" if data_type in ("FLOAT2", "FLOAT_VECTOR") else "value"
        width = {"FLOAT2": 2, "FLOAT_VECTOR": 3, "QUATERNION": 4}.get(data_type, 1)
        whole = data_type == "INT"
        count = len(attr.data) * width
        values = rng.integers(0, 10, count) if whole else rng.uniform(low, high, count)
        attr.data.foreach_set(field, values.astype(np.int32 if whole else np.float32))
    return setup


def _attribute(name, output, scale=1.0):
    def build(tree, v):
        value = _node(tree, "ShaderNodeAttribute", attribute_name=name).outputs[output]
        return _scaled(tree, value, scale, 0.0) if output == "Fac" else value
    return build


def _vector_displacement(space):
    """Vector Displacement's offset of the unit coordinates, shown as a colour."""
    def build(tree, v):
        node = _link(tree, _node(tree, "ShaderNodeVectorDisplacement", space=space), Vector=_unit(tree, v),
                     Midlevel=0.3, Scale=0.8)
        return _affine(tree, node.outputs[0], 1.0, 0.5)
    return build


CASES = (
    NodeCase("Brightness/Contrast", _brightness),
    NodeCase("RGB Curves, extrapolated", _rgb_curves),
    NodeCase("Vector Curves", _vector_curves),
    NodeCase("Float Curve", _float_curve),
    NodeCase("Vector Rotate X axis", _rotate("X_AXIS", False)),
    NodeCase("Vector Rotate Y axis inverted", _rotate("Y_AXIS", True)),
    NodeCase("Vector Rotate Z axis", _rotate("Z_AXIS", False)),
    NodeCase("Vector Rotate axis angle", _rotate("AXIS_ANGLE", False)),
    NodeCase("Vector Rotate Euler inverted", _rotate("EULER_XYZ", True)),
    NodeCase("Vector Transform point object to world", _transform("POINT", "OBJECT", "WORLD", 0.25)),
    NodeCase("Vector Transform normal world to camera", _transform("NORMAL", "WORLD", "CAMERA")),
    NodeCase("Vector Transform vector camera to object", _transform("VECTOR", "CAMERA", "OBJECT")),
    NodeCase("Vector Transform point world to camera", _transform("POINT", "WORLD", "CAMERA", 0.1)),
    NodeCase("Texture Coordinate Camera", _camera_coordinates),
    NodeCase("Texture Coordinate Window", _window_coordinates),
    NodeCase("Texture Coordinate from another object", _other_object_coordinates),
    NodeCase("Image Texture Sphere projection", _projected("SPHERE")),
    NodeCase("Image Texture Tube projection", _projected("TUBE")),
    NodeCase("Image Texture UDIM tiles", _udim, strength=0.5),
    NodeCase("Texture Mapping, texture type (Noise)", _mapped("ShaderNodeTexNoise", "TEXTURE")),
    NodeCase("Texture Mapping, point type, axes swapped (Checker)",
             _mapped("ShaderNodeTexChecker", "POINT", ("Y", "NONE", "X"))),
    NodeCase("Texture Mapping, vector type (Image)", _mapped("ShaderNodeTexImage", "VECTOR", image=True,
                                                              interpolation="Closest")),
    NodeCase("Texture Mapping, normal type (Gradient)", _mapped("ShaderNodeTexGradient", "NORMAL",
                                                                 gradient_type="RADIAL")),
    NodeCase("Image Texture Cubic, repeat", _interpolated("Cubic", "REPEAT")),
    NodeCase("Image Texture Cubic, clip", _interpolated("Cubic", "CLIP")),
    NodeCase("Image Texture Cubic, extend", _interpolated("Cubic", "EXTEND")),
    NodeCase("Image Texture Smart, mirror", _interpolated("Smart", "MIRROR")),
    # scaled down: Parametric jumps across the quad's diagonal, whose edge pixels the renderers'
    # pixel samples split differently (by up to 0.08 of the jump), as they would any edge
    NodeCase("Geometry Parametric", _geometry("Parametric", 0.3)),
    NodeCase("Geometry Tangent", _geometry("Tangent", 0.5, 0.5)),
    NodeCase("Attribute Fac of a colour attribute", _attribute_fac("Paint"), setup=_paint),
    NodeCase("Attribute Fac of a UV map", _attribute_fac("Extra"), setup=_paint),
    NodeCase("Geometry Random Per Island", _geometry("Random Per Island"), mesh=_islands()),
    NodeCase("Normal Dot", _normal_dot),
    NodeCase("Blackbody", _blackbody, strength=0.3),
    NodeCase("Wavelength", _wavelength),
    NodeCase("Separate Color HSL", _separate_hsl),
    NodeCase("Combine Color HSL", _combine_hsl),
    NodeCase("Mix Hue", _mix("HUE")),
    NodeCase("Mix Saturation", _mix("SATURATION")),
    NodeCase("Mix Value", _mix("VALUE")),
    NodeCase("Mix Color", _mix("COLOR")),
    NodeCase("Map Range vector linear", _map_range_vector("LINEAR")),
    NodeCase("Map Range vector stepped", _map_range_vector("STEPPED")),
    NodeCase("Map Range vector smoothstep", _map_range_vector("SMOOTHSTEP")),
    NodeCase("Map Range vector smootherstep, unclamped", _map_range_vector("SMOOTHERSTEP", False)),
    NodeCase("Map Range stepped", _map_range_float("STEPPED")),
    NodeCase("Map Range smootherstep", _map_range_float("SMOOTHERSTEP")),
    NodeCase("Color Ramp B-Spline", _ramp("B_SPLINE")),
    NodeCase("Color Ramp Cardinal", _ramp("CARDINAL")),
    NodeCase("Color Ramp linear in HSV", _ramp("LINEAR", "HSV")),
    NodeCase("Camera Data View Vector", _camera_data("View Vector", 0.5, 0.5), mesh=_terrain()),
    NodeCase("Camera Data View Z Depth", _camera_data("View Z Depth", 1.0, -9.5), mesh=_terrain()),
    NodeCase("Camera Data View Distance", _camera_data("View Distance", 0.5, -4.6), mesh=_terrain()),
    NodeCase("Wireframe world size", _wireframe(False, 0.06, 0.12), mesh=_terrain()),
    NodeCase("Tangent radial X", _tangent("RADIAL", "X"), mesh=_terrain(), setup=_smooth),
    NodeCase("Tangent radial Y", _tangent("RADIAL", "Y"), mesh=_terrain(), setup=_smooth),
    NodeCase("Tangent radial Z", _tangent("RADIAL", "Z"), mesh=_terrain(), setup=_smooth),
    NodeCase("Tangent UV map", _tangent("UV_MAP", uv_map="Turned"), mesh=_terrain(), setup=_turned_uvs),
    NodeCase("Attribute float on points", _attribute("height", "Color"), mesh=_terrain(),
             setup=_generic("height", "FLOAT", "POINT")),
    NodeCase("Attribute vector on faces", _attribute("tint", "Vector"), mesh=_terrain(),
             setup=_generic("tint", "FLOAT_VECTOR", "FACE")),
    NodeCase("Attribute integer on corners, Fac", _attribute("count", "Fac", 0.1), mesh=_terrain(),
             setup=_generic("count", "INT", "CORNER")),
    NodeCase("Attribute 2D vector on points", _attribute("offset", "Vector"), mesh=_terrain(),
             setup=_generic("offset", "FLOAT2", "POINT")),
    NodeCase("Vector Displacement tangent space", _vector_displacement("TANGENT"), setup=_turned_uvs),
    NodeCase("Vector Displacement object space", _vector_displacement("OBJECT")),
    NodeCase("Attribute float on edges", _attribute("crease", "Color"), mesh=_terrain(),
             setup=_generic("crease", "FLOAT", "EDGE")),
    NodeCase("Attribute quaternion on points, Alpha", _attribute("turn", "Alpha"), mesh=_terrain(),
             setup=_generic("turn", "QUATERNION", "POINT")),
)


def _emissive(tree, color, strength):
    absolute = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
    tree.links.new(color, absolute.inputs[0])
    emission = _node(tree, "ShaderNodeEmission")
    emission.inputs["Strength"].default_value = strength
    tree.links.new(absolute.outputs["Vector"], emission.inputs["Color"])
    out = _node(tree, "ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])


def material(case: NodeCase):
    """The case's node fed by the tile's Object coordinates turned by a Mapping, as emission."""
    mat = new_material(case.name)
    tree = mat.node_tree
    tree.nodes.clear()
    coords = _node(tree, "ShaderNodeTexCoord")
    mapping = _node(tree, "ShaderNodeMapping")
    mapping.inputs["Location"].default_value = (0.31, -0.17, 0.43)
    mapping.inputs["Rotation"].default_value = (0.5, 0.35, 0.2)
    tree.links.new(coords.outputs["Object"], mapping.inputs["Vector"])
    _emissive(tree, case.build(tree, mapping.outputs["Vector"]), case.strength)
    return mat


def grid_scene(cases=CASES):
    return ps.grid_scene(cases, material)


def _sphere_normal(tree):
    """The sphere's normal tilted (normalised object-space normal plus a constant): a linked Normal."""
    coords = _node(tree, "ShaderNodeTexCoord")
    add = _node(tree, "ShaderNodeVectorMath", operation="ADD")
    tree.links.new(coords.outputs["Normal"], add.inputs[0])
    add.inputs[1].default_value = (0.4, -0.3, 0.2)
    return _normalized(tree, add.outputs["Vector"])


def _generated_z(tree, scale, offset):
    coords = _node(tree, "ShaderNodeTexCoord")
    return _scaled(tree, _component(tree, coords.outputs["Generated"], "Z"), scale, offset)


def _true_normal_and_backfacing(tree):
    """|True Normal| / 2 plus Backfacing / 2."""
    geometry = _node(tree, "ShaderNodeNewGeometry")
    absolute = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
    tree.links.new(geometry.outputs["True Normal"], absolute.inputs[0])
    node = _node(tree, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    tree.links.new(absolute.outputs["Vector"], node.inputs[0])
    node.inputs[1].default_value = (0.5, 0.5, 0.5)
    tree.links.new(_scaled(tree, geometry.outputs["Backfacing"], 0.5, 0.0), node.inputs[2])
    return node.outputs["Vector"]


def _reflection(tree):
    coords = _node(tree, "ShaderNodeTexCoord")
    return _affine(tree, coords.outputs["Reflection"], 0.4, 0.5)


def _normal_map(space):
    """Normal Map of a constant colour, shown as a colour ((N + 1) / 2)."""
    def build(tree):
        node = _link(tree, _node(tree, "ShaderNodeNormalMap", space=space), Color=(0.75, 0.35, 0.85, 1.0),
                     Strength=0.8)
        return _affine(tree, node.outputs["Normal"], 0.5, 0.5)
    return build


FACING = (
    ("Fresnel", lambda tree: _link(tree, _node(tree, "ShaderNodeFresnel"), IOR=1.45).outputs[0]),
    ("Fresnel, IOR and normal linked", lambda tree: _link(
        tree, _node(tree, "ShaderNodeFresnel"), IOR=_generated_z(tree, 1.0, 1.2), Normal=_sphere_normal(tree)).outputs[0]),
    ("Layer Weight Fresnel, blend linked", lambda tree: _link(
        tree, _node(tree, "ShaderNodeLayerWeight"), Blend=_generated_z(tree, 0.6, 0.2)).outputs[0]),
    ("Layer Weight Facing, normal linked", lambda tree: _link(
        tree, _node(tree, "ShaderNodeLayerWeight"), Blend=0.3, Normal=_sphere_normal(tree)).outputs[1]),
    ("Geometry True Normal and Backfacing", _true_normal_and_backfacing),
    ("Texture Coordinate Reflection", _reflection),
    ("Texture Coordinate Window (perspective)", _window_coordinates),
    ("Normal Map tangent space", _normal_map("TANGENT")),
    ("Normal Map object space", _normal_map("OBJECT")),
    ("Normal Map Blender world space", _normal_map("BLENDER_WORLD")),
)
"""Nodes that see the direction a hit is seen from or its side (Fresnel, Layer Weight, Geometry's
True Normal and Backfacing, Texture Coordinate's Reflection, Normal Map), and Window
coordinates in perspective: a diffuse sphere each, coloured by the node, in front (top row) and, with the
normals turned inwards, from the back."""


def facing_parts(size: int):
    """(case, side, pixels) of each sphere of ``facing_scene``'s image: the front row, then the back."""
    return [(name, side, (slice(row * size, (row + 1) * size), slice(i * size, (i + 1) * size)))
            for row, side in enumerate(("front", "back")) for i, (name, _) in enumerate(FACING)]


def facing_scene(size=32):
    """The FACING cases on smooth diffuse spheres under a uniform white world (each point of a
    sphere then reflects its colour), seen in perspective: the incoming direction meets the
    shading normal at every angle. The bottom row's spheres have their normals flipped, so the
    camera sees their backs (Cycles' backfacing hits: the IOR inverted)."""
    scene = ps._scene(size * len(FACING), 2 * size)
    ps.aim(scene.camera, (0.0, -7.0 * len(FACING) / 2.4, 0.0))  # 36 mm sensor at 50 mm: 2.1 m, the spacing, is 32 px
    scene.camera.data.lens = 50.0
    scene.world = new_world("World")
    for row, flipped in enumerate((False, True)):
        for i, (name, build) in enumerate(FACING):
            x = 2.1 * (i - (len(FACING) - 1) / 2)
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.95, location=(x, 0.0, 1.05 - 2.1 * row), segments=48,
                                                 ring_count=24)
            bpy.ops.object.shade_smooth()
            obj = bpy.context.active_object
            if flipped:
                obj.data.flip_normals()
            obj.data.materials.append(_lit_diffuse(name, build)[0])
    return scene


def pointiness_scene(size=48):
    """An icosphere with its vertices pushed in and out at random and its sharp edges split (the
    duplicated vertices Pointiness welds again), emitting its Pointiness with the contrast raised
    (4 p - 1.5, through Absolute), seen in perspective."""
    scene = ps._scene(size, size)
    ps.aim(scene.camera, (2.4, -3.0, 2.2))
    ps.black_world(scene)
    bpy.ops.mesh.primitive_ico_sphere_add(radius=1.0, subdivisions=3)
    obj = bpy.context.active_object
    rng = np.random.default_rng(4)
    for vertex in obj.data.vertices:
        vertex.co *= rng.uniform(0.85, 1.15)
    bpy.ops.object.shade_smooth()
    split = obj.modifiers.new("Split", "EDGE_SPLIT")
    split.split_angle = 0.5
    mat = new_material("Pointiness")
    tree = mat.node_tree
    tree.nodes.clear()
    geometry = _node(tree, "ShaderNodeNewGeometry")
    _emissive(tree, _affine(tree, geometry.outputs["Pointiness"], 4.0, -1.5), 1.0)
    obj.data.materials.append(mat)
    return scene


def _plane(name, x, material, collection):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-0.9, -0.9, 0), (0.9, -0.9, 0), (0.9, 0.9, 0), (-0.9, 0.9, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = (x, 0.0, 0.0)
    collection.objects.link(obj)
    return obj


def _attribute_material(name, kind, attribute, output="Color"):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    node = _node(tree, "ShaderNodeAttribute", attribute_type=kind, attribute_name=attribute)
    _emissive(tree, node.outputs[output], 1.0)
    return mat


def attribute_scene():
    """Five emissive squares in a row, seen from above, coloured by Attribute nodes of the
    Object, Instancer and View Layer types: an object's custom property, an RNA path (its
    location), its mesh's custom property, an instanced object's instancer's property, the
    scene's custom property (through the view layer)."""
    scene = ps._scene(5 * ps.TILE, ps.TILE)
    cam = scene.camera
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 10.0
    ps.black_world(scene)
    own = _plane("Own", -4.0, _attribute_material("Own", "OBJECT", "tint"), scene.collection)
    own["tint"] = (0.2, 0.7, 0.4)
    path = _plane("Path", -2.0, _attribute_material("Path", "OBJECT", "location"), scene.collection)
    path.location.y = 0.35
    data = _plane("Data", 0.0, _attribute_material("Data", "OBJECT", "tint"), scene.collection)
    data.data["tint"] = 0.6
    hidden = bpy.data.collections.new("Instanced")
    inner = _plane("Inner", 0.0, _attribute_material("Instanced", "INSTANCER", "tint"), hidden)
    inner["tint"] = (1.0, 0.0, 0.0)  # the instancer's own value comes first
    instancer = bpy.data.objects.new("Instancer", None)
    instancer.instance_type = "COLLECTION"
    instancer.instance_collection = hidden
    instancer.location = (2.0, 0.0, 0.0)
    instancer["tint"] = (0.3, 0.3, 0.9, 0.5)
    scene.collection.objects.link(instancer)
    scene["tint"] = (0.9, 0.5, 0.1)
    _plane("Layer", 4.0, _attribute_material("Layer", "VIEW_LAYER", "tint"), scene.collection)
    return scene


def mirror_ball_scene(size=48):
    """Only the world, an Environment Texture (the 8 x 8 texels, Closest) in Mirror Ball
    projection, seen by a wide camera at the origin looking down -y, where the ball's centre is."""
    scene = ps._scene(size, size)
    cam = scene.camera
    cam.location = (0.0, 0.0, 0.0)
    cam.rotation_euler = mathutils.Vector((-0.3, -1.0, 0.2)).to_track_quat("-Z", "Y").to_euler()
    cam.data.lens = 12.0
    world = new_world("World")
    tree = world.node_tree
    env = _node(tree, "ShaderNodeTexEnvironment", image=_texels(), interpolation="Closest", projection="MIRROR_BALL")
    tree.links.new(env.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    scene.world = world
    return scene


def _lit_diffuse(name, build):
    """A Diffuse BSDF material whose colour ``build(tree)`` (an output socket) gives."""
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = _node(tree, "ShaderNodeBsdfDiffuse")
    tree.links.new(build(tree), bsdf.inputs["Color"])
    out = _node(tree, "ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat, tree, out


def wireframe_scene(size=64):
    """Wireframe in pixels (Size 0.6 to 2.6 px across the square) as the colour of a flat diffuse
    square of 6 x 6 jittered quads under a white world, seen straight down: the pixel footprint
    comes from the camera ray, which DRT's emission does not see."""
    scene = ps._scene(size, size)
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 2.2
    scene.world = new_world("World")
    xs = np.linspace(-1.0, 1.0, 7)
    jitter = np.random.default_rng(3).uniform(-0.08, 0.08, (7, 7, 2))
    vertices = [(x + (0 < i < 6) * jitter[j, i, 0], y + (0 < j < 6) * jitter[j, i, 1], 0.0)
                for j, y in enumerate(xs) for i, x in enumerate(xs)]
    faces = [(7 * j + i, 7 * j + i + 1, 7 * j + i + 8, 7 * j + i + 7) for j in range(6) for i in range(6)]
    mesh = bpy.data.meshes.new("Wires")
    mesh.from_pydata(vertices, [], faces)

    def wires(tree):
        coords = _node(tree, "ShaderNodeTexCoord")
        node = _node(tree, "ShaderNodeWireframe", use_pixel_size=True)
        return _link(tree, node, Size=_scaled(tree, _component(tree, coords.outputs["Object"], "X"), 1.0, 1.6)).outputs[0]
    mesh.materials.append(_lit_diffuse("Wires", wires)[0])
    obj = bpy.data.objects.new("Wires", mesh)
    scene.collection.objects.link(obj)
    return scene


def _info_material(name, build):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    _emissive(tree, build(tree, _node(tree, "ShaderNodeObjectInfo")), 1.0)
    return mat


def _random_and_indices(tree, info):
    join = _node(tree, "ShaderNodeCombineXYZ")
    tree.links.new(info.outputs["Random"], join.inputs[0])
    tree.links.new(_scaled(tree, info.outputs["Object Index"], 0.1, 0.0), join.inputs[1])
    tree.links.new(_scaled(tree, info.outputs["Material Index"], 0.1, 0.0), join.inputs[2])
    return join.outputs[0]


def _colour_alpha_location(tree, info):
    """Colour times alpha, plus a fifth of the location's x and y."""
    colour = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
    tree.links.new(info.outputs["Color"], colour.inputs[0])
    tree.links.new(info.outputs["Alpha"], colour.inputs["Scale"])
    place = _node(tree, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    tree.links.new(info.outputs["Location"], place.inputs[0])
    place.inputs[1].default_value = (0.05, 0.05, 0.0)
    tree.links.new(colour.outputs[0], place.inputs[2])
    return place.outputs[0]


def object_info_scene():
    """Two rows of emissive squares seen from above, coloured by Object Info: Random, Object Index
    and Material Index on top, colour times alpha plus location below. The squares' objects have
    plain, numbered and non-ASCII names, colours, alphas and pass indices; two of each row are
    instances of a collection (Random from the instance, not the name)."""
    scene = ps._scene(6 * ps.TILE, 2 * ps.TILE)
    cam = scene.camera
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 12.0
    ps.black_world(scene)
    hidden = bpy.data.collections.new("Instanced")
    for row, (name, build, pass_index) in enumerate((("Indices", _random_and_indices, 3),
                                                     ("Colour", _colour_alpha_location, 0))):
        mat = _info_material(name, build)
        mat.pass_index = pass_index
        y = 1.0 - 2.0 * row
        names = ("Cube", "Cube.001", "Säule ünd Ölbaum", "Z")
        for i, obj_name in enumerate(names):
            obj = _plane(f"{obj_name} {name}" if row else obj_name, -5.0 + 2.0 * i, mat, scene.collection)
            obj.location.y = y
            obj.pass_index = 2 * i + 1
            obj.color = (0.2 + 0.2 * i, 0.9 - 0.2 * i, 0.5, 1.0 - 0.15 * i)
        inner = _plane(f"Inner {name}", 0.0, mat, hidden)
        inner.location.y = y
        inner.pass_index = 7
        inner.color = (0.9, 0.3, 0.6, 0.8)
    for x in (3.0, 5.0):
        instancer = bpy.data.objects.new(f"Instancer {x}", None)
        instancer.instance_type = "COLLECTION"
        instancer.instance_collection = hidden
        instancer.location = (x, 0.0, 0.0)
        scene.collection.objects.link(instancer)
    return scene


def _height(tree, kind, scale):
    """A smooth height over the object's coordinates: a noise texture or a sine wave."""
    coords = _node(tree, "ShaderNodeTexCoord")
    if kind == "noise":
        node = _link(tree, _node(tree, "ShaderNodeTexNoise"), Vector=coords.outputs["Object"], Scale=scale, Detail=0.0)
        return node.outputs["Fac"], node.outputs["Color"]
    wave = _link(tree, _node(tree, "ShaderNodeTexWave", wave_type="RINGS"), Vector=coords.outputs["Object"], Scale=scale)
    return wave.outputs["Fac"], wave.outputs["Color"]


def displacement_scene(size=32):
    """Six diffuse squares lit by a sun, each bumped by its material's Displacement socket
    (method Bump Only): a Displacement node in object space on a square scaled 0.7 (the offset
    scales with it), one in world space, a Vector Displacement in object space and one in tangent
    space (a turned UV map), a Math node's height linked straight in, that square coloured by its
    Geometry Normal (the surface seeing the bumped normal), and a Displacement node along a linked,
    tilted normal."""
    scene = ps._scene(3 * size, 2 * size)
    ps.aim(scene.camera, (0.0, -5.0, 7.5))
    ps.black_world(scene)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.35, 0.25, 0.0)
    scene.collection.objects.link(sun)
    grey = lambda tree: _node(tree, "ShaderNodeRGB").outputs[0]  # noqa: E731

    def square(name, x, y, build, colour=grey, scale=1.0, setup=None):
        mat, tree, out = _lit_diffuse(name, colour)
        tree.links.new(build(tree), out.inputs["Displacement"])
        obj = _plane(name, x, mat, scene.collection)
        obj.location.y = y
        obj.scale = (scale, scale, scale)
        obj.rotation_euler.z = 0.4
        if setup is not None:
            setup(obj.data)

    def object_space(tree):
        fac, _ = _height(tree, "noise", 2.0)
        return _link(tree, _node(tree, "ShaderNodeDisplacement", space="OBJECT"), Height=fac, Midlevel=0.5,
                     Scale=0.5).outputs[0]

    def world_space(tree):
        fac, _ = _height(tree, "wave", 0.4)
        return _link(tree, _node(tree, "ShaderNodeDisplacement", space="WORLD"), Height=fac, Scale=0.25).outputs[0]

    def vector(space):
        def build(tree):
            _, colour = _height(tree, "noise", 1.5)
            return _link(tree, _node(tree, "ShaderNodeVectorDisplacement", space=space), Vector=colour, Midlevel=0.5,
                         Scale=0.3).outputs[0]
        return build

    def tilted_normal(tree):
        fac, _ = _height(tree, "wave", 0.5)
        normal = _normalized(tree, _affine(tree, _node(tree, "ShaderNodeNewGeometry").outputs["Normal"], 1.0, 0.3))
        return _link(tree, _node(tree, "ShaderNodeDisplacement", space="OBJECT"), Height=fac, Scale=0.3,
                     Normal=normal).outputs[0]

    def straight(tree):
        fac, _ = _height(tree, "wave", 0.3)
        return _scaled(tree, fac, 0.2, 0.0)

    def normal_colour(tree):
        return _affine(tree, _node(tree, "ShaderNodeNewGeometry").outputs["Normal"], 0.5, 0.5)

    square("Object space", -2.2, 1.1, object_space, scale=0.7)
    square("World space", 0.0, 1.1, world_space)
    square("Vector", 2.2, 1.1, vector("OBJECT"))
    square("Vector tangent", -2.2, -1.1, vector("TANGENT"), setup=_turned_uvs)
    square("Straight", 0.0, -1.1, straight, normal_colour)
    square("Normal linked", 2.2, -1.1, tilted_normal)
    return scene


def _rough_diffuse(tree, roughness):
    return _link(tree, _node(tree, "ShaderNodeBsdfDiffuse"), Color=(0.8, 0.55, 0.3, 1.0), Roughness=roughness)


def _principled_rough(tree):
    return _link(tree, _node(tree, "ShaderNodeBsdfPrincipled"), Roughness=0.4,
                 **{"Base Color": (0.3, 0.6, 0.8, 1.0), "Diffuse Roughness": 1.0})


def _metallic(tree):
    """Blender 5's Metallic BSDF with F82 Fresnel, roughness 0.35, a bluish edge tint and a base
    colour from gold at the bottom of the sphere to copper at its top (Generated z)."""
    ramp = _link(tree, _node(tree, "ShaderNodeMix", data_type="RGBA"), Factor_Float=_generated_z(tree, 1.0, 0.0),
                 A_Color=(0.95, 0.7, 0.3, 1.0), B_Color=(0.95, 0.45, 0.3, 1.0))
    return _link(tree, _node(tree, "ShaderNodeBsdfMetallic"), Roughness=0.35,
                 **{"Base Color": ramp.outputs[2], "Edge Tint": (0.6, 0.8, 1.0, 1.0)})


def _thin_film(metallic):
    """A Principled BSDF, roughness 0.5, with a 500 nm film of IOR 1.33 (Cycles' default): over a dark
    dielectric (metallic 0) or a copper-coloured metal (metallic 1)."""
    def build(tree):
        colour = (0.9, 0.6, 0.3, 1.0) if metallic else (0.05, 0.05, 0.05, 1.0)
        return _link(tree, _node(tree, "ShaderNodeBsdfPrincipled"), Metallic=metallic, Roughness=0.5,
                     **{"Base Color": colour, "Thin Film Thickness": 500.0, "Thin Film IOR": 1.33})
    return build


def _toon(component, size, smooth):
    """A Toon BSDF of this component, Size and Smooth."""
    def build(tree):
        node = _link(tree, _node(tree, "ShaderNodeBsdfToon"), Color=(0.9, 0.6, 0.3, 1.0), Size=size, Smooth=smooth)
        node.component = component
        return node
    return build


def _sheen(tree):
    """A Sheen BSDF (Microfiber), roughness 0.3: the rim light of the sun from behind."""
    return _link(tree, _node(tree, "ShaderNodeBsdfSheen"), Color=(0.9, 0.8, 0.6, 1.0), Roughness=0.3)


def _principled_sheen(tree):
    """A Principled BSDF over a dark base with Sheen Weight 1 (roughness 0.5, pinkish tint)."""
    return _link(tree, _node(tree, "ShaderNodeBsdfPrincipled"), Roughness=0.5,
                 **{"Base Color": (0.05, 0.03, 0.02, 1.0), "Sheen Weight": 1.0, "Sheen Roughness": 0.5,
                    "Sheen Tint": (1.0, 0.6, 0.8, 1.0)})


def _translucent(tree, colour=(0.3, 0.9, 0.4, 1.0)):
    return _link(tree, _node(tree, "ShaderNodeBsdfTranslucent"), Color=colour)


def _translucent_over_diffuse(tree):
    """0.6 translucent, coloured from yellow at the square's bottom to cyan at its top (Generated y:
    its upright side), and 0.4 diffuse: lit through from behind and in front."""
    y = _scaled(tree, _component(tree, _node(tree, "ShaderNodeTexCoord").outputs["Generated"], "Y"), 1.0, 0.0)
    combine = _node(tree, "ShaderNodeCombineColor")
    tree.links.new(_scaled(tree, y, -0.8, 0.9), combine.inputs[0])
    combine.inputs[1].default_value = 0.8
    tree.links.new(_scaled(tree, y, 0.8, 0.1), combine.inputs[2])
    translucent = _translucent(tree)
    tree.links.new(combine.outputs[0], translucent.inputs["Color"])
    mix = _link(tree, _node(tree, "ShaderNodeMixShader"), Fac=0.6)
    tree.links.new(_link(tree, _node(tree, "ShaderNodeBsdfDiffuse"), Color=(0.9, 0.9, 0.9, 1.0)).outputs[0],
                   mix.inputs[1])
    tree.links.new(translucent.outputs[0], mix.inputs[2])
    return mix


def _hair(component):
    """The Hair BSDF's Reflection or Transmission component (defaults but the colour): on a mesh
    about each triangle's dPdv."""
    def build(tree):
        node = _link(tree, _node(tree, "ShaderNodeBsdfHair"), Color=(0.9, 0.6, 0.3, 1.0))
        node.component = component
        return node
    return build


def _principled_hair(model, parametrization, **inputs):
    """A Principled Hair BSDF of this model and parametrization (set before the inputs it enables)."""
    def build(tree):
        node = _node(tree, "ShaderNodeBsdfHairPrincipled")
        node.model, node.parametrization = model, parametrization
        return _link(tree, node, **inputs)
    return build


@dataclass(frozen=True)
class ClosureCase:
    name: str
    shape: str  # "sphere" | "square"
    build: Callable  # tree -> the shader node shown
    oren_nayar: bool = False
    since: tuple = (0, 0)  # the first Blender with the node inputs it sets


CLOSURES = (
    ClosureCase("Toon BSDF, glossy, Size 0.2, Smooth 0.1", "sphere", _toon("GLOSSY", 0.2, 0.1)),
    ClosureCase("Toon BSDF, diffuse, Size 0.5, Smooth 0.1", "sphere", _toon("DIFFUSE", 0.5, 0.1)),
    ClosureCase("Metallic BSDF, F82, base colour from a texture", "sphere", _metallic, since=(5, 0)),
    ClosureCase("Principled BSDF, Thin Film 500 nm, dielectric, roughness 0.5", "sphere", _thin_film(0.0),
                since=(5, 0)),
    ClosureCase("Principled BSDF, Thin Film 500 nm, metallic, roughness 0.5", "sphere", _thin_film(1.0),
                since=(5, 0)),
    ClosureCase("Oren-Nayar, roughness 1", "sphere", lambda tree: _rough_diffuse(tree, 1.0), True),
    ClosureCase("Oren-Nayar, roughness from a texture", "sphere",
                lambda tree: _rough_diffuse(tree, _generated_z(tree, 1.0, 0.0)), True),
    ClosureCase("Principled BSDF, Diffuse Roughness 1", "sphere", _principled_rough, True, (4, 3)),
    ClosureCase("Translucent", "square", _translucent),
    ClosureCase("Translucent mixed with Diffuse", "square", _translucent_over_diffuse),
    ClosureCase("Sheen BSDF, roughness 0.3", "sphere", _sheen),
    ClosureCase("Principled BSDF, Sheen Weight 1 over a dark base", "sphere", _principled_sheen),
    ClosureCase("Hair BSDF, Reflection", "sphere", _hair("Reflection")),
    ClosureCase("Hair BSDF, Transmission", "sphere", _hair("Transmission")),
    ClosureCase("Principled Hair BSDF, Chiang, Direct Coloring", "sphere",
                _principled_hair("CHIANG", "COLOR", Color=(0.6, 0.3, 0.15, 1.0)), since=(5, 0)),
    ClosureCase("Principled Hair BSDF, Chiang, Melanin, Coat 0.3", "sphere",
                _principled_hair("CHIANG", "MELANIN", Melanin=0.5, Coat=0.3), since=(5, 0)),
)
"""Closures under two suns, each in its own square of ``closure_scene``: toon spheres, glossy and
diffuse (the sharp edges of Cycles' cones), a Metallic BSDF sphere, thin-film spheres from 5.0 (whose
Cycles computes the film as DRT does; these first: a glossy
neighbour would light the translucent squares through their transmission bounces), rough diffuse spheres
(Oren-Nayar's flat look and bright limb under light from the camera's side; roughness constant,
textured, and a Principled BSDF's Diffuse Roughness), upright squares lit through from behind
(Translucent, alone and mixed with a Diffuse lit in front) and sheen spheres (the Sheen BSDF, a
Principled's sheen over a dark base; last: each square's neighbours light it, and between the
rough diffuse spheres and the squares the sheen spheres took the Principled sheen to 0.0242 against a
limit of 0.0238 and, before the thin films, the rough diffuse and translucent cases over theirs), then
the hair closures on spheres (shaded about each triangle's edge, as Cycles does on a mesh; Principled
Hair's Huang model, named in its warning, in tests/blender/test_hair_cycles.py)."""


def closure_part(i: int, size: int):
    """Case i's square of ``closure_scene``'s image without its edge pixels (the pixel filter's
    reach into the next square)."""
    m = ps.MARGIN
    return slice(m, size - m), slice(i * size + m, (i + 1) * size - m)


def closure_scene(cases, size=32):
    """The ``cases`` side by side, ``size`` pixels apart, seen level along +y by an orthographic
    camera under a black world: one sun from the camera's side, a little above and to the left,
    one from behind, above and to the right (through the squares, on the spheres' limbs)."""
    scene = ps._scene(size * len(cases), size)
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 2.1 * len(cases)
    scene.camera.location = (0.0, -8.0, 0.0)
    scene.camera.rotation_euler = (np.pi / 2, 0.0, 0.0)
    ps.black_world(scene)
    for name, energy, direction in (("Front", 2.0, (-0.35, -1.0, 0.45)), ("Back", 3.0, (0.4, 1.0, 0.6))):
        sun = bpy.data.objects.new(name, bpy.data.lights.new(name, "SUN"))
        sun.data.energy = energy
        sun.rotation_euler = mathutils.Vector(direction).to_track_quat("Z", "Y").to_euler()
        scene.collection.objects.link(sun)
    for i, case in enumerate(cases):
        x = 2.1 * (i - (len(cases) - 1) / 2)
        if case.shape == "sphere":
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.95, location=(x, 0.0, 0.0), segments=64, ring_count=32)
            bpy.ops.object.shade_smooth()
        else:
            bpy.ops.mesh.primitive_plane_add(size=1.8, location=(x, 0.0, 0.0), rotation=(np.pi / 2, 0.0, 0.0))
        mat = new_material(case.name)
        tree = mat.node_tree
        tree.nodes.clear()
        out = _node(tree, "ShaderNodeOutputMaterial")
        tree.links.new(case.build(tree).outputs[0], out.inputs["Surface"])
        bpy.context.active_object.data.materials.append(mat)
    return scene


def _diffuse_bsdf(tree, colour):
    bsdf = _node(tree, "ShaderNodeBsdfDiffuse")
    if isinstance(colour, bpy.types.NodeSocket):
        tree.links.new(colour, bsdf.inputs["Color"])
    else:
        bsdf.inputs["Color"].default_value = colour
    return bsdf.outputs["BSDF"]


def translucent_world_scene(size=32):
    """The Translucent squares of ``CLOSURES`` (alone, and mixed with a Diffuse) under a uniform white
    world and no light: lit through from behind by the world alone, which Cycles' BSDF rays find
    and DRT's light sample drawn from the translucent lobe (core.integrator.world_lobes); the
    squares side by side in one plane, so neither sees the other (``translucent_pair_scene`` has
    two that do)."""
    scene = closure_scene([case for case in CLOSURES if case.name.startswith("Translucent")], size)
    for name in ("Front", "Back"):
        bpy.data.objects.remove(bpy.data.objects[name])
    world = new_world("White")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scene.world = world
    return scene


def translucent_pair_scene(width=64, height=32):
    """Two Translucent squares (orange, blue), tilted alike, under a uniform white world and no light,
    each seeing part of the other behind it: the far one's light comes through the near one,
    which a Translucent ray carries (Cycles counts it a transmission bounce, not a diffuse one:
    its default diffuse bounces 0 keep it). DRT's light sample alone, blocked by the near square,
    left the far one 1.4-3.2% dark per channel."""
    scene = ps.sphere_pair_stage(width, height)
    world = new_world("White")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scene.world = world
    for i, (x, colour) in enumerate(((-1.1, (0.8, 0.5, 0.3, 1.0)), (1.1, (0.3, 0.6, 0.8, 1.0)))):
        material, _ = ps.closure_material(f"Translucent {i}", "ShaderNodeBsdfTranslucent", Color=colour)
        bpy.ops.mesh.primitive_plane_add(size=1.8, location=(x, 0.0, 0.0), rotation=(1.2, 0.0, 0.3))
        bpy.context.active_object.data.materials.append(material)
    return scene


def _mixed_by_camera(tree, other, camera):
    """A Mix Shader of ``other`` and ``camera`` (two shader outputs) by Is Camera Ray."""
    mix = _node(tree, "ShaderNodeMixShader")
    tree.links.new(_node(tree, "ShaderNodeLightPath").outputs["Is Camera Ray"], mix.inputs["Fac"])
    tree.links.new(other, mix.inputs[1])
    tree.links.new(camera, mix.inputs[2])
    return mix.outputs["Shader"]


def _path_material(name, surface):
    """A material whose Surface ``surface(tree)`` (a shader output) gives."""
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    tree.links.new(surface(tree), _node(tree, "ShaderNodeOutputMaterial").inputs["Surface"])
    return mat


def _path_colour(tree, *channels):
    """A colour of Light Path outputs, one (output name, scale, offset) per channel."""
    path = _node(tree, "ShaderNodeLightPath")
    join = _node(tree, "ShaderNodeCombineXYZ")
    for i, (name, scale, offset) in enumerate(channels):
        tree.links.new(_scaled(tree, path.outputs[name], scale, offset), join.inputs[i])
    return join.outputs[0]


def _light_path_stage(size):
    """The Light Path scenes' camera (the horizon across the image's upper part) and world: sky
    blue to the camera, grey to every other ray and to light."""
    scene = ps._scene(2 * size, size)
    camera = scene.camera
    camera.location = (0.0, -7.5, 1.6)
    camera.rotation_euler = mathutils.Vector((0.0, 7.5, -1.5)).to_track_quat("-Z", "Y").to_euler()
    camera.data.lens = 35.0
    world = new_world("World")
    tree = world.node_tree
    background = tree.nodes["Background"]
    sky = _node(tree, "ShaderNodeBackground")
    sky.inputs["Color"].default_value = (0.2, 0.45, 0.9, 1.0)
    background.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    output = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputWorld")
    tree.links.new(_mixed_by_camera(tree, background.outputs[0], sky.outputs[0]), output.inputs["Surface"])
    scene.world = world
    return scene


def light_path_scene(size=48):
    """Light Path on a sharp mirror floor under a sun: a sphere that is green to the camera and red
    to everything else (a Mix Shader by Is Camera Ray), one whose diffuse colour is made of Ray
    Length (red), Glossy Depth (green) and Ray Depth (blue), each seen straight and in the mirror,
    and a world that is sky blue to the camera and grey to the mirror and to light."""
    scene = _light_path_stage(size)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.5, -0.4, 0.0)
    scene.collection.objects.link(sun)

    def mirror(tree):
        glossy = _node(tree, "ShaderNodeBsdfGlossy")
        glossy.inputs["Roughness"].default_value = 0.0
        glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
        return glossy.outputs["BSDF"]

    def by_camera(tree):
        red, green = _diffuse_bsdf(tree, (0.8, 0.1, 0.1, 1.0)), _diffuse_bsdf(tree, (0.1, 0.8, 0.1, 1.0))
        return _mixed_by_camera(tree, red, green)

    def depths(tree):
        return _diffuse_bsdf(tree, _path_colour(tree, ("Ray Length", 0.1, 0.0), ("Glossy Depth", 0.8, 0.1),
                                                ("Ray Depth", 0.8, 0.1)))

    bpy.ops.mesh.primitive_plane_add(size=30.0)
    bpy.context.active_object.data.materials.append(_path_material("Mirror", mirror))
    for x, name, surface in ((-1.1, "By camera", by_camera), (1.1, "Depths", depths)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, location=(x, 0.0, 1.0), segments=48, ring_count=24)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(_path_material(name, surface))
    return scene


def light_falloff_scene(size=48):
    """Light Falloff on the Light Path stage's sharp mirror floor: two emissive spheres seen
    straight (the camera's ray length) and in the mirror (the reflected ray's), one Quadratic
    smoothed (Strength 4, Smooth 20), one Linear whose Strength is linked (0.5 to the camera, 0.2
    to the mirror's rays); the world's grey Background of strength Linear (Strength as is there)."""
    scene = _light_path_stage(size)
    tree = scene.world.node_tree
    world_falloff = _node(tree, "ShaderNodeLightFalloff")
    world_falloff.inputs["Strength"].default_value = 1.0
    tree.links.new(world_falloff.outputs["Linear"], tree.nodes["Background"].inputs["Strength"])

    def mirror(tree):
        glossy = _node(tree, "ShaderNodeBsdfGlossy")
        glossy.inputs["Roughness"].default_value = 0.0
        glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
        return glossy.outputs["BSDF"]

    def emitting(output, strength, smooth):
        def build(tree):
            falloff = _node(tree, "ShaderNodeLightFalloff")
            if isinstance(strength, tuple):
                camera = _node(tree, "ShaderNodeLightPath").outputs["Is Camera Ray"]
                tree.links.new(_scaled(tree, camera, *strength), falloff.inputs["Strength"])
            else:
                falloff.inputs["Strength"].default_value = strength
            falloff.inputs["Smooth"].default_value = smooth
            emission = _node(tree, "ShaderNodeEmission")
            emission.inputs["Color"].default_value = (1.0, 0.85, 0.6, 1.0)
            tree.links.new(falloff.outputs[output], emission.inputs["Strength"])
            return emission.outputs["Emission"]
        return build

    bpy.ops.mesh.primitive_plane_add(size=30.0)
    bpy.context.active_object.data.materials.append(_path_material("Mirror", mirror))
    for x, name, surface in ((-1.1, "Quadratic", emitting("Quadratic", 4.0, 20.0)),
                             (1.1, "Linear", emitting("Linear", (0.3, 0.2), 0.0))):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, location=(x, 0.0, 1.0), segments=48, ring_count=24)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(_path_material(name, surface))
    return scene


def light_path_glass_scene(size=48):
    """Light Path through a transparent sheet and a sharp glass slab: emissive spheres behind them
    whose colour is made of the node's outputs, one of Is Camera Ray (red: still 1 through the
    sheet), Transparent Depth (green) and Is Transmission Ray (blue), the other of Transmission
    Depth (red), Ray Depth (green) and Is Singular Ray (blue); the world, sky blue to the camera
    only, seen through the sheet and in and through the glass."""
    scene = _light_path_stage(size)

    def sheet(tree):
        transparent = _node(tree, "ShaderNodeBsdfTransparent")
        transparent.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
        return transparent.outputs["BSDF"]

    def glass(tree):
        node = _node(tree, "ShaderNodeBsdfGlass")
        node.inputs["Roughness"].default_value = 0.0
        node.inputs["IOR"].default_value = 1.45
        return node.outputs["BSDF"]

    def emitting(*channels):
        def build(tree):
            emission = _node(tree, "ShaderNodeEmission")
            tree.links.new(_path_colour(tree, *channels), emission.inputs["Color"])
            return emission.outputs["Emission"]
        return build

    camera = emitting(("Is Camera Ray", 0.8, 0.1), ("Transparent Depth", 0.8, 0.1), ("Is Transmission Ray", 0.8, 0.1))
    depths = emitting(("Transmission Depth", 0.4, 0.1), ("Ray Depth", 0.4, 0.1), ("Is Singular Ray", 0.8, 0.1))
    for x, name, surface in ((-1.1, "Camera", camera), (1.1, "Transmission", depths)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, location=(x, 0.0, 1.0), segments=48, ring_count=24)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(_path_material(name, surface))
    bpy.ops.mesh.primitive_plane_add(size=2.2, location=(-1.1, -1.6, 1.0), rotation=(0.5 * np.pi, 0.0, 0.0))
    bpy.context.active_object.data.materials.append(_path_material("Sheet", sheet))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(1.1, -1.6, 1.0), scale=(2.2, 0.1, 2.2))
    bpy.context.active_object.data.materials.append(_path_material("Glass", glass))
    return scene


AO_CASES = {
    "default": {},
    "short": {"distance": 0.25},
    "inside": {"inside": True},
    "only_local": {"only_local": True},
}
"""The Ambient Occlusion node's settings compared with Cycles: the defaults (Distance 1, 16
samples), Distance 0.25, Inside, Only Local."""


def _ao_material(distance=1.0, inside=False, only_local=False):
    """An emission material of strength the Ambient Occlusion node's AO."""
    material = new_material("AO")
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs["Emission"], tree.nodes["Material Output"].inputs["Surface"])
    ao = tree.nodes.new("ShaderNodeAmbientOcclusion")
    ao.inputs["Distance"].default_value = distance
    ao.inside = inside
    ao.only_local = only_local
    tree.links.new(ao.outputs["AO"], emission.inputs["Strength"])
    return material


def ambient_occlusion_scene(**settings):
    """A 1 m cube standing on a floor that fills the view and a smooth sphere of radius 0.6 beside it, all one emission
    material whose Strength is the Ambient Occlusion node's AO with ``settings`` (AO_CASES), under
    a black world: the image is the AO field. With Only Local the cube and the floor are one object."""
    scene = ps._scene(64, 48)
    ps.aim(scene.camera, (3.0, -5.0, 3.5))
    scene.camera.data.lens = 35.0
    ps.black_world(scene)
    material = _ao_material(**settings)
    floor = ps.add_primitive(bpy.ops.mesh.primitive_plane_add, material, "Floor", size=40.0)
    cube = ps.add_primitive(bpy.ops.mesh.primitive_cube_add, material, "Cube", size=1.0, location=(-0.4, 0.3, 0.5))
    if settings.get("only_local"):  # the cube and the floor one object
        bpy.ops.object.select_all(action="DESELECT")
        floor.select_set(True)
        cube.select_set(True)
        bpy.context.view_layer.objects.active = floor
        bpy.ops.object.join()
    ps.smooth_sphere("Sphere", 0.9, material)
    sphere = scene.objects["Sphere"]
    sphere.scale = (0.6, 0.6, 0.6)
    sphere.location = (0.9, -0.2, 0.6)
    return scene


BEVEL_CASES = {
    "default": {},
    "wide": {"radius": 0.2, "samples": 16},
    "bumped": {"bumped": True},
}
"""The Bevel node's settings compared with Cycles: Radius 0.1 with 8 samples, 0.2 with 16, and
the node's Normal linked (a Bump of a Noise Texture, whose turn the node keeps)."""


def _bevel_material(radius=0.1, samples=8, bumped=False):
    """A white Diffuse BSDF whose Normal is the Bevel node's (its own Normal a noise bump's when
    ``bumped``)."""
    material = new_material("Bevel")
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    tree.links.new(diffuse.outputs["BSDF"], tree.nodes["Material Output"].inputs["Surface"])
    bevel = tree.nodes.new("ShaderNodeBevel")
    bevel.inputs["Radius"].default_value = radius
    bevel.samples = samples
    tree.links.new(bevel.outputs["Normal"], diffuse.inputs["Normal"])
    if bumped:
        noise = tree.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 4.0
        bump = tree.nodes.new("ShaderNodeBump")
        bump.inputs["Distance"].default_value = 0.2
        tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
        tree.links.new(bump.outputs["Normal"], bevel.inputs["Normal"])
    return material


def bevel_scene(**settings):
    """A 1 m cube turned about z and a flat-shaded cylinder (24 sides, radius 0.5, 1 m high), sharp
    edged, of one Diffuse material whose Normal is the Bevel node's with ``settings`` (BEVEL_CASES),
    lit by a sun at an angle under a black world: the edges the node rounds catch the light."""
    scene = ps._scene(64, 48)
    ps.aim(scene.camera, (2.6, -3.6, 2.6))
    scene.camera.data.lens = 50.0
    ps.black_world(scene)
    material = _bevel_material(**settings)
    ps.add_primitive(bpy.ops.mesh.primitive_cube_add, material, "Cube", size=1.0, location=(-0.55, 0.35, 0.0),
                     rotation=(0.0, 0.0, 0.5))
    ps.add_primitive(bpy.ops.mesh.primitive_cylinder_add, material, "Cylinder", vertices=24, radius=0.5,
                     depth=1.0, location=(0.65, -0.45, 0.0))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    ps.aim(sun, (-1.0, -3.0, 2.0))
    scene.collection.objects.link(sun)
    return scene
