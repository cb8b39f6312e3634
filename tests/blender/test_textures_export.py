"""Textured materials and worlds from Blender: node graphs exported to programs and rendered.

Each scene is a diffuse plane filling an orthographic view under a uniform white world
(radiance 1), so every pixel is exactly the albedo the nodes compute there.
"""
from __future__ import annotations

from pathlib import Path

import bpy
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.settings import RenderSettings
from drt_engine.core.shading.textures import MAGENTA, srgb_to_linear
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world
from tests.support.export_helpers import add_object, empty_scene, render_export
from tests.support.textured_scenes import write_image

RES = 16
TEXELS = 4


def textured_scene(width=RES):
    """Ortho camera over a 2 x 2 plane (one quad, UV 0..1) and a white world; returns (scene, material)."""
    scene = empty_scene(width, width)
    cam = scene.camera
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop, value in zip(uv.data, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        loop.uv = value
    mesh.update()
    mat = new_material("Textured")
    mesh.materials.append(mat)
    add_object(scene, "Plane", mesh)
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.world = world
    return scene, mat


def diffuse_from(mat, make_color):
    """Diffuse BSDF whose Color is fed by ``make_color(tree)`` (returns an output socket)."""
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    tree.nodes.remove(bsdf)
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse.outputs["BSDF"], tree.nodes["Material Output"].inputs["Surface"])
    tree.links.new(make_color(tree), diffuse.inputs["Color"])
    return diffuse


def image_node(tree, image, interpolation="Closest"):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    node.interpolation = interpolation
    return node


def render_data(data, samples=4):
    result = Renderer(data, RenderSettings(samples=samples, threads=1)).render()
    return result.passes["Combined"][..., :3].astype(np.float64), result.warnings


def centres(img):
    k = RES // TEXELS
    return img[k // 2::k, k // 2::k]


@pytest.fixture
def texels():
    return np.random.default_rng(5).integers(0, 256, (TEXELS, TEXELS, 3), dtype=np.uint8)


@pytest.fixture
def saved_scene(tmp_path, texels):
    """A textured scene saved as tmp_path/scene.blend, its image at //tex.png (relative)."""
    write_image(tmp_path / "tex.png", texels)
    scene, mat = textured_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    image = bpy.data.images.load("//tex.png")
    diffuse_from(mat, lambda tree: image_node(tree, image).outputs["Color"])
    return scene, image


def test_relative_image_path_renders_its_texels(saved_scene, texels):
    scene, image = saved_scene
    data = render_export(scene)
    assert Path(data.images[0].path) == Path(bpy.data.filepath).parent / "tex.png"
    img, warnings = render_data(data)
    assert not warnings
    assert np.abs(centres(img) - srgb_to_linear(texels[::-1] / 255.0)).max() < 1e-6


def test_non_color_and_packed_images(saved_scene, texels):
    scene, image = saved_scene
    image.colorspace_settings.name = "Non-Color"
    data_img, _ = render_data(render_export(scene))
    assert np.abs(centres(data_img) - texels[::-1] / 255.0).max() < 1e-6
    image.colorspace_settings.name = "sRGB"
    image.pack()
    packed = render_export(scene)
    assert packed.images[0].pixels is not None
    packed_img, _ = render_data(packed)
    assert np.abs(centres(packed_img) - srgb_to_linear(texels[::-1] / 255.0)).max() < 1e-6


def test_without_openimageio_file_images_come_from_blender(saved_scene, texels, monkeypatch):
    """A Blender without OpenImageIO (Debian's) reads image files through Blender's own loader:
    the same texels as OpenImageIO's, sRGB linearised and Non-Color as is."""
    import drt_engine.blender.export.shader_graph as shader_graph

    scene, image = saved_scene
    monkeypatch.setattr(shader_graph, "openimageio_available", lambda: False)
    data = render_export(scene)
    assert data.images[0].pixels is not None
    img, warnings = render_data(data)
    assert not warnings
    assert np.abs(centres(img) - srgb_to_linear(texels[::-1] / 255.0)).max() < 1e-6
    image.colorspace_settings.name = "Non-Color"
    img, _ = render_data(render_export(scene))
    assert np.abs(centres(img) - texels[::-1] / 255.0).max() < 1e-6


def test_reading_a_file_without_openimageio_is_magenta_with_a_reason(monkeypatch):
    import builtins

    from drt_engine.core.scene import TextureImage
    from drt_engine.core.shading.textures import read_pixels

    real_import = builtins.__import__

    def no_oiio(name, *args, **kwargs):
        if name == "OpenImageIO":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_oiio)
    pixels, reason = read_pixels(TextureImage("Tex", path="/nowhere/tex.png"))
    assert pixels is None and "OpenImageIO" in reason


def test_missing_image_renders_magenta_with_one_warning(tmp_path):
    scene, mat = textured_scene()
    image = bpy.data.images.new("Lost", 4, 4)
    image.source = "FILE"
    image.filepath = str(tmp_path / "missing.png")
    diffuse_from(mat, lambda tree: image_node(tree, image).outputs["Color"])
    img, warnings = render_data(render_export(scene))
    assert np.allclose(img[2:-2, 2:-2], MAGENTA[:3], atol=1e-6)
    assert sum("Lost" in w for w in warnings) == 1


def test_named_uv_map_and_node_group(saved_scene, texels):
    """A second UV map (mirrored in u), chosen by a UV Map node inside a node group, mirrors the image;
    a Math node in the group halves it."""
    scene, image = saved_scene
    mesh = bpy.data.meshes["Plane"]
    flipped = mesh.uv_layers.new(name="Flipped")
    for loop, value in zip(flipped.data, [(1, 0), (0, 0), (0, 1), (1, 1)]):
        loop.uv = value
    mesh.uv_layers["UVMap"].active_render = True
    group = bpy.data.node_groups.new("Halve", "ShaderNodeTree")
    group.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    inner_out = group.nodes.new("NodeGroupOutput")
    uvmap = group.nodes.new("ShaderNodeUVMap")
    uvmap.uv_map = "Flipped"
    tex = image_node(group, image)
    group.links.new(uvmap.outputs["UV"], tex.inputs["Vector"])
    mix = group.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 1.0
    mix.inputs["B"].default_value = (0.5, 0.5, 0.5, 1.0)
    reroute = group.nodes.new("NodeReroute")
    group.links.new(tex.outputs["Color"], reroute.inputs[0])
    group.links.new(reroute.outputs[0], mix.inputs["A"])
    group.links.new(mix.outputs["Result"], inner_out.inputs["Color"])
    mat = bpy.data.materials["Textured"]

    def grouped(tree):
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        return node.outputs["Color"]

    tree = mat.node_tree
    tree.links.new(grouped(tree), tree.nodes["Diffuse BSDF"].inputs["Color"])
    img, warnings = render_data(render_export(scene))
    assert not warnings
    expected = 0.5 * srgb_to_linear(texels[::-1, ::-1] / 255.0)
    assert np.abs(centres(img) - expected).max() < 1e-6


def test_color_attribute_per_corner():
    scene, mat = textured_scene()
    mesh = bpy.data.meshes["Plane"]
    attr = mesh.color_attributes.new("Paint", "FLOAT_COLOR", "CORNER")
    colors = [(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1), (1, 1, 1, 1)]
    for item, c in zip(attr.data, colors):
        item.color = c

    def color_node(tree):
        node = tree.nodes.new("ShaderNodeVertexColor")
        node.layer_name = "Paint"
        return node.outputs["Color"]

    diffuse_from(mat, color_node)
    img, warnings = render_data(render_export(scene))
    assert not warnings
    # the quad's centre on the diagonal shared by both triangles: the mean of corners 0 and 2
    centre = img[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1].mean(axis=(0, 1))
    assert np.allclose(centre, [0.5, 0, 0.5], atol=0.08)  # pixels beside it take a little of corners 1, 3
    assert np.allclose(img[0, 0], [1, 0, 0], atol=0.15) and np.allclose(img[-1, -1], [0, 0, 1], atol=0.15)


def test_unsupported_node_warns_once_naming_type_and_material():
    scene, mat = textured_scene()
    diffuse_from(mat, lambda tree: tree.nodes.new("ShaderNodePointInfo").outputs["Radius"])
    data = render_export(scene)
    lines = [w for w in data.warnings if "Textured" in w]
    assert len(lines) == 1 and "Point Info" in lines[0]
    img, _ = render_data(data)
    assert np.allclose(img[4:-4, 4:-4], 0.8, atol=1e-6)  # the Diffuse Color socket's default


def test_environment_texture_world_with_mapping_and_strength(tmp_path):
    """An equirectangular map through a 90 degree Mapping rotation, strength 2: the world
    radiance in each direction is twice the texel the rotated direction looks up."""
    scene, _ = textured_scene()
    rng = np.random.default_rng(9)
    pixels = rng.random((8, 16, 3)).astype(np.float32)
    path = write_image(tmp_path / "sky.exr", pixels)
    world = scene.world
    rh.environment_texture(world, path, np.pi / 2, 2.0, "Closest")
    world.cycles_visibility.camera = False
    world.cycles_visibility.glossy = False
    data = render_export(scene)
    assert data.world.program is not None and not data.world.visible_camera and not data.world.visible_glossy
    assert data.world.visible_diffuse and data.world.visible_transmission
    from drt_engine.core.lights.environment import Environment
    from drt_engine.core.shading.textures import Texture, equirect_uv
    environment = Environment(data.world, [Texture(i) for i in data.images])
    d = np.array([[1.0, 0.2, 0.3], [-0.3, -0.9, -0.2]])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    rotated = d @ np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]).T
    uv = equirect_uv(rotated)
    col = (uv[:, 0] * 16).astype(int)
    row = (uv[:, 1] * 8).astype(int)
    assert np.allclose(environment.radiance(d), 2.0 * pixels[::-1][row, col], rtol=1e-6)


def test_flat_normal_map_and_constant_bump_export_change_nothing():
    """Normal Map of a flat normal image and Bump of a constant height, exported from nodes,
    leave a sun-lit glossy plane's image as it is; a Bump of a slope tilts it."""
    scene, mat = textured_scene()
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.4, 0.2, 0.0)
    scene.collection.objects.link(sun)
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.3
    plain, _ = render_data(render_export(scene), samples=16)
    flat = bpy.data.images.new("Flat", 4, 4, float_buffer=True)
    flat.pixels.foreach_set(np.tile([0.5, 0.5, 1.0, 1.0], 16).astype(np.float32))
    flat.colorspace_settings.name = "Non-Color"
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(image_node(tree, flat, "Linear").outputs["Color"], normal_map.inputs["Color"])
    tree.links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    mapped, warnings = render_data(render_export(scene), samples=16)
    assert not warnings and np.abs(mapped - plain).max() < 1e-9
    bump = tree.nodes.new("ShaderNodeBump")
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 0.4
    tree.links.new(value.outputs[0], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    bumped, warnings = render_data(render_export(scene), samples=16)
    assert not warnings and np.abs(bumped - plain).max() < 1e-9
    coords = tree.nodes.new("ShaderNodeTexCoord")
    separate = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(coords.outputs["Object"], separate.inputs["Vector"])
    tree.links.new(separate.outputs["X"], bump.inputs["Height"])
    bump.inputs["Distance"].default_value = 0.5  # Blender 5.0's default is 0.001
    sloped, _ = render_data(render_export(scene), samples=16)
    assert np.abs(sloped - plain).max() > 0.01


def test_normal_map_tilts_along_the_uv_tangent():
    """Tangent-space normal (0.5, 0, 1) on a plane whose u runs along +X tilts the shading normal
    toward +X (MikkTSpace tangents from Blender): under a sun from 45 degrees above +X a white
    diffuse plane has radiance E cos(theta) / pi with cos(theta) = (0.5 + 1) / sqrt(2 * 1.25).
    The material's Bump Map Correction is off: its smoothing at the terminator (Cycles' bump
    shadowing, tests/blender/test_bump_shadowing_cycles.py) would dim the tilted plane by 0.8%."""
    scene, mat = textured_scene()
    mat.cycles.use_bump_map_correction = False
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = 0.0
    sun.rotation_euler = (0.0, np.pi / 4, 0.0)
    scene.collection.objects.link(sun)

    def white(tree):
        rgb = tree.nodes.new("ShaderNodeRGB")
        rgb.outputs[0].default_value = (1, 1, 1, 1)
        return rgb.outputs[0]

    diffuse = diffuse_from(mat, white)
    tree = mat.node_tree
    tilt = tree.nodes.new("ShaderNodeRGB")
    tilt.outputs[0].default_value = (0.75, 0.5, 1.0, 1.0)
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(tilt.outputs[0], normal_map.inputs["Color"])
    tree.links.new(normal_map.outputs["Normal"], diffuse.inputs["Normal"])
    data = render_export(scene)
    assert "tangent:" in data.meshes[0].attributes
    img, warnings = render_data(data)
    assert not warnings
    expected = 3.0 / np.pi * 1.5 / np.sqrt(2 * 1.25)
    assert np.allclose(img[2:-2, 2:-2], expected, rtol=1e-5)
