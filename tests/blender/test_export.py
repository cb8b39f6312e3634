"""Export facts: what the depsgraph holds arrives in SceneData with Cycles' meaning.

Scenes are built in code and exported through a real render depsgraph
(``export_helpers.render_export``), so render visibility and render subdivision
levels apply as in an F12 render.
"""
from __future__ import annotations

import math

import bpy
import numpy as np
import pytest
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

from drt_engine.blender.export import export_scene
from drt_engine.blender.export.materials import HUANG_NOTE, PRINCIPLED_HAIR_MATCHED_FROM, VERSION_PRINCIPLED_HAIR
from drt_engine.core.errors import SceneError
from drt_engine.core.scene import DEFAULT_MATERIAL

from tests.support.datablocks import new_material, new_world, with_nodes
from tests.support.export_helpers import add_object, cube_mesh, empty_scene, render_export, total_area

# ---------------------------------------------------------------- geometry


def test_cube_has_twelve_triangles_and_its_area():
    scene = empty_scene()
    add_object(scene, "Cube", cube_mesh())
    data = render_export(scene)
    assert len(data.meshes) == 1 and len(data.instances) == 1
    assert len(data.meshes[0].triangles) == 12
    assert total_area(data) == pytest.approx(24.0)
    assert data.meshes[0].corner_normals is None  # all faces flat


def test_subdivision_modifier_uses_render_levels():
    scene = empty_scene()
    cube = add_object(scene, "Cube", cube_mesh())
    modifier = cube.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels, modifier.render_levels = 1, 2
    data = render_export(scene)
    # 6 quads, each split into 4^2 quads at level 2, two triangles per quad
    assert data.triangle_count() == 6 * 16 * 2


def test_curve_text_and_metaball_are_exported_once_each():
    scene = empty_scene()
    bpy.ops.curve.primitive_bezier_circle_add(location=(0, 3, 0))
    bpy.context.object.data.bevel_depth = 0.1
    bpy.ops.object.text_add(location=(0, -3, 0))
    bpy.ops.object.metaball_add(location=(5, 0, 0))
    data = render_export(scene)
    names = sorted(inst.name for inst in data.instances)
    assert names == ["BézierCircle", "Mball", "Text"]
    assert all(len(m.triangles) > 0 for m in data.meshes)


def test_faceless_mesh_is_skipped_silently():
    scene = empty_scene()
    mesh = bpy.data.meshes.new("Points")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1), (1, 2)], [])
    add_object(scene, "Points", mesh)
    data = render_export(scene)
    assert data.meshes == [] and data.instances == [] and data.warnings == []


def test_world_transform_with_negative_scale_keeps_object_space_vertices():
    scene = empty_scene()
    cube = add_object(scene, "Cube", cube_mesh(), location=(1.0, 2.0, 3.0))
    cube.rotation_euler = (0.3, -0.2, 1.1)
    cube.scale = (-1.0, 2.0, 0.5)
    data = render_export(scene)
    (inst,) = data.instances
    expected = np.array(cube.matrix_world)
    np.testing.assert_allclose(inst.matrix, expected, atol=1e-6)
    assert np.linalg.det(inst.matrix[:3, :3]) == pytest.approx(-1.0)  # -1 * 2 * 0.5, mirror kept
    mesh = data.meshes[inst.mesh]
    np.testing.assert_allclose(np.abs(mesh.vertices), 1.0)  # object space, nothing baked or flipped
    # winding as Blender stores it: geometric normals point out of the object-space cube
    t = mesh.vertices[mesh.triangles]
    normals = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    assert np.all(np.einsum("ij,ij->i", normals, t.mean(axis=1)) > 0)


def _split_normals(obj):
    """Blender's per-corner shading normals, read through the loop triangles."""
    return np.array([t.split_normals[:] for t in obj.data.loop_triangles])


def test_smooth_flat_and_custom_normals_per_corner():
    scene = empty_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    data = render_export(scene)
    mesh = data.meshes[data.instances[0].mesh]
    np.testing.assert_allclose(mesh.corner_normals, _split_normals(sphere), atol=1e-6)
    # smooth sphere: each corner's normal is close to its unit position vector
    np.testing.assert_allclose(mesh.corner_normals, mesh.vertices[mesh.triangles], atol=0.03)

    # one face flat among smooth ones: its corners carry the face normal
    sphere.data.polygons[0].use_smooth = False
    data = render_export(scene)
    mesh = data.meshes[data.instances[0].mesh]
    rows = [i for i, t in enumerate(sphere.data.loop_triangles) if t.polygon_index == 0]
    face_normal = sphere.data.polygons[0].normal[:]
    flat_corners = mesh.corner_normals[rows].reshape(-1, 3)
    np.testing.assert_allclose(flat_corners, [face_normal] * len(flat_corners), atol=1e-5)
    np.testing.assert_allclose(mesh.corner_normals, _split_normals(sphere), atol=1e-6)

    # custom split normals: every corner points along +Z
    sphere.data.polygons[0].use_smooth = True
    sphere.data.normals_split_custom_set([(0.0, 0.0, 1.0)] * len(sphere.data.loops))
    data = render_export(scene)
    mesh = data.meshes[data.instances[0].mesh]
    up = np.tile([0.0, 0.0, 1.0], (mesh.corner_normals.size // 3, 1))
    np.testing.assert_allclose(mesh.corner_normals.reshape(-1, 3), up, atol=1e-3)  # stored quantised


def test_uvs_from_the_active_render_map():
    scene = empty_scene()
    bpy.ops.mesh.primitive_plane_add()
    plane = bpy.context.object
    plane.data.uv_layers.new(name="Second")
    second = plane.data.uv_layers["Second"]
    for i, loop_uv in enumerate(second.uv):
        loop_uv.vector = (i * 0.1, 1.0 - i * 0.1)
    second.active_render = True
    data = render_export(scene)
    mesh = data.meshes[0]
    loops = np.array([t.loops[:] for t in plane.data.loop_triangles])
    np.testing.assert_allclose(mesh.uvs[..., 0], loops * 0.1, atol=1e-6)
    np.testing.assert_allclose(mesh.uvs[..., 1], 1.0 - loops * 0.1, atol=1e-6)


def test_render_disabled_and_excluded_objects_are_left_out():
    scene = empty_scene()
    add_object(scene, "Visible", cube_mesh())
    add_object(scene, "HiddenInViewport", cube_mesh()).hide_viewport = True  # still rendered
    add_object(scene, "NoRender", cube_mesh()).hide_render = True
    excluded = bpy.data.collections.new("Excluded")
    scene.collection.children.link(excluded)
    excluded.objects.link(bpy.data.objects.new("InExcluded", cube_mesh()))
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True
    data = render_export(scene)
    assert sorted(i.name for i in data.instances) == ["HiddenInViewport", "Visible"]


def test_collection_instances_share_one_mesh():
    scene = empty_scene()
    source = bpy.data.collections.new("Source")  # not linked to the scene: only instanced
    source.objects.link(bpy.data.objects.new("Cube", cube_mesh()))
    for i in range(3):
        empty = add_object(scene, f"Instance{i}", None, location=(3.0 * i, 0.0, 0.0))
        empty.instance_type = "COLLECTION"
        empty.instance_collection = source
    data = render_export(scene)
    assert len(data.meshes) == 1 and len(data.instances) == 3
    xs = sorted(inst.matrix[0, 3] for inst in data.instances)
    assert xs == pytest.approx([0.0, 3.0, 6.0])


def test_geometry_nodes_instances_on_points_export_the_mesh_once():
    scene = empty_scene()
    obj = add_object(scene, "Scatter", cube_mesh())
    tree = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    grid = nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Vertices X"].default_value = 4
    grid.inputs["Vertices Y"].default_value = 5
    cube = nodes.new("GeometryNodeMeshCube")
    on_points = nodes.new("GeometryNodeInstanceOnPoints")
    output = nodes.new("NodeGroupOutput")
    links.new(grid.outputs["Mesh"], on_points.inputs["Points"])
    links.new(cube.outputs["Mesh"], on_points.inputs["Instance"])
    links.new(on_points.outputs["Instances"], output.inputs[0])
    obj.modifiers.new("Scatter", "NODES").node_group = tree
    data = render_export(scene)
    assert len(data.instances) == 20
    assert len(data.meshes) == 1 and len(data.meshes[0].triangles) == 12
    assert len({tuple(np.round(i.matrix[:3, 3], 6)) for i in data.instances}) == 20


def _export_calls(subdivisions):
    """Python function calls made by exporting a smooth grid of 2 x subdivisions^2 triangles."""
    import cProfile
    import pstats

    empty_scene()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=subdivisions, y_subdivisions=subdivisions)
    bpy.ops.object.shade_smooth()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    profile = cProfile.Profile()
    data = profile.runcall(export_scene, depsgraph)
    assert data.triangle_count() == 2 * subdivisions * subdivisions
    return pstats.Stats(profile).total_calls


def test_large_mesh_export_is_vectorised():
    """Export work per mesh is array work: a 180k-triangle grid makes no more Python calls than a
    200-triangle one (a per-vertex or per-triangle Python loop would add 10^5 of them). Counting
    calls, not seconds, keeps the test exact on a shared machine."""
    small, large = _export_calls(10), _export_calls(300)
    assert large <= small + 20, f"{large} Python calls for 180k triangles against {small} for 200"


# ---------------------------------------------------------------- materials


def _material_scene(material):
    """The current (empty) scene with a cube using ``material``."""
    scene = bpy.context.scene
    obj = add_object(scene, "Cube", cube_mesh())
    obj.data.materials.append(material)
    return scene


def _closures(data, name):
    (material,) = [m for m in data.materials if m.name == name]
    return material.closures


def _new_node_material(name):
    material = new_material(name)
    tree = material.node_tree
    for node in list(tree.nodes):
        if node.bl_idname != "ShaderNodeOutputMaterial":
            tree.nodes.remove(node)
    return material, tree, tree.get_output_node("CYCLES")


def test_principled_values_are_exported():
    empty_scene()
    material = new_material("Principled")
    bsdf = material.node_tree.nodes["Principled BSDF"]
    values = {
        "Base Color": (0.2, 0.4, 0.6, 1.0),
        "Metallic": 0.7,
        "Roughness": 0.35,
        "IOR": 1.33,
        "Specular IOR Level": 0.25,
        "Specular Tint": (0.9, 0.8, 0.7, 1.0),
        "Transmission Weight": 0.4,
        "Coat Weight": 0.6,
        "Coat Roughness": 0.1,
        "Coat IOR": 1.6,
        "Coat Tint": (0.5, 0.6, 0.7, 1.0),
        "Emission Color": (1.0, 0.5, 0.25, 1.0),
        "Emission Strength": 4.0,
    }
    for name, value in values.items():
        bsdf.inputs[name].default_value = value
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Principled")
    assert closure.kind == "PRINCIPLED"
    np.testing.assert_allclose(closure.weight, 1.0)
    np.testing.assert_allclose(closure.color, (0.2, 0.4, 0.6), rtol=1e-6)
    assert closure.metallic == pytest.approx(0.7)
    assert closure.roughness == pytest.approx(0.35)
    assert closure.ior == pytest.approx(1.33)
    assert closure.specular_ior_level == pytest.approx(0.25)
    np.testing.assert_allclose(closure.specular_tint, (0.9, 0.8, 0.7), rtol=1e-6)
    assert closure.transmission == pytest.approx(0.4)
    assert (closure.coat_weight, closure.coat_roughness, closure.coat_ior) == pytest.approx((0.6, 0.1, 1.6))
    np.testing.assert_allclose(closure.coat_tint, (0.5, 0.6, 0.7), rtol=1e-6)
    np.testing.assert_allclose(closure.emission, (4.0, 2.0, 1.0), rtol=1e-6)  # colour x strength
    assert data.warnings == []
    assert data.meshes[0].material_indices.tolist() == [1] * 12


def test_alpha_is_a_mix_with_transparent():
    empty_scene()
    material = new_material("Glassy")
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Alpha"].default_value = 0.3
    bsdf.inputs["Emission Strength"].default_value = 2.0
    data = render_export(_material_scene(material))
    principled, transparent = _closures(data, "Glassy")
    assert (principled.kind, transparent.kind) == ("PRINCIPLED", "TRANSPARENT")
    np.testing.assert_allclose(principled.weight, 0.3, rtol=1e-6)
    np.testing.assert_allclose(transparent.weight, 0.7, rtol=1e-6)
    np.testing.assert_allclose(transparent.color, 1.0)
    # Cycles attenuates the Principled emission by alpha as well
    np.testing.assert_allclose(data.materials[1].emission, 0.3 * 2.0, rtol=1e-6)


def test_mix_and_add_shaders_flatten_into_weighted_closures():
    empty_scene()
    material, tree, output = _new_node_material("Mixed")
    nodes, links = tree.nodes, tree.links
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 0.0, 0.0, 1.0)
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Roughness"].default_value = 0.2
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 3.0
    glass = nodes.new("ShaderNodeBsdfGlass")
    glass.inputs["IOR"].default_value = 1.45
    inner = nodes.new("ShaderNodeMixShader")
    inner.inputs[0].default_value = 0.5
    outer = nodes.new("ShaderNodeMixShader")
    outer.inputs[0].default_value = 0.25
    add = nodes.new("ShaderNodeAddShader")
    links.new(glossy.outputs[0], inner.inputs[1])
    links.new(emission.outputs[0], inner.inputs[2])
    links.new(diffuse.outputs[0], outer.inputs[1])
    links.new(inner.outputs[0], outer.inputs[2])
    links.new(outer.outputs[0], add.inputs[0])
    links.new(glass.outputs[0], add.inputs[1])
    links.new(add.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    closures = _closures(data, "Mixed")
    kinds = [c.kind for c in closures]
    assert kinds == ["DIFFUSE", "GLOSSY", "EMISSION", "GLASS"]
    weights = [c.weight[0] for c in closures]
    # outer: (1 - 0.25) diffuse + 0.25 inner; inner: 0.5 glossy + 0.5 emission; Add: + glass
    assert weights == pytest.approx([0.75, 0.125, 0.125, 1.0])
    np.testing.assert_allclose(closures[0].color, (1.0, 0.0, 0.0))
    assert closures[1].roughness == pytest.approx(0.2)
    np.testing.assert_allclose(closures[2].emission, 3.0)
    assert closures[3].ior == pytest.approx(1.45)
    np.testing.assert_allclose(data.materials[1].emission, 0.125 * 3.0)
    assert data.warnings == []


def test_translucent_and_rough_diffuse_export_as_their_closures():
    """Translucent BSDF in a Mix Shader, a Diffuse BSDF's Roughness (constant, and from a texture,
    then varying per hit) and a Principled BSDF's Diffuse Roughness (Blender 4.3+) become closures
    without a warning where this Blender's Cycles computes Oren-Nayar as DRT does."""
    from drt_engine.blender.export.materials import OREN_NAYAR_MATCHED_FROM, VERSION_OREN_NAYAR
    empty_scene()
    material, tree, output = _new_node_material("Leaf")
    translucent = tree.nodes.new("ShaderNodeBsdfTranslucent")
    translucent.inputs["Color"].default_value = (0.2, 0.9, 0.3, 1.0)
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.7
    rough = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(tree.nodes.new("ShaderNodeTexNoise").outputs["Fac"], rough.inputs["Roughness"])
    principled = tree.nodes.new("ShaderNodeBsdfPrincipled")
    if "Diffuse Roughness" in principled.inputs:
        principled.inputs["Diffuse Roughness"].default_value = 0.4
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.25
    add, add2 = tree.nodes.new("ShaderNodeAddShader"), tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(translucent.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], add.inputs[0])
    tree.links.new(rough.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], add2.inputs[0])
    tree.links.new(principled.outputs[0], add2.inputs[1])
    tree.links.new(add2.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    diffuse_c, translucent_c, rough_c, principled_c = _closures(data, "Leaf")
    assert (diffuse_c.kind, translucent_c.kind, rough_c.kind) == ("DIFFUSE", "TRANSLUCENT", "DIFFUSE")
    assert [diffuse_c.weight[0], translucent_c.weight[0]] == pytest.approx([0.75, 0.25])
    np.testing.assert_allclose(translucent_c.color, (0.2, 0.9, 0.3), rtol=1e-6)
    assert diffuse_c.diffuse_roughness == pytest.approx(0.7)
    assert "diffuse_roughness" in rough_c.inputs and "roughness" not in rough_c.inputs
    assert principled_c.diffuse_roughness == pytest.approx(0.4 if "Diffuse Roughness" in principled.inputs else 0.0)
    if bpy.app.version < OREN_NAYAR_MATCHED_FROM:
        assert len(data.warnings) == 1 and VERSION_OREN_NAYAR in data.warnings[0], data.warnings
    else:
        assert data.warnings == []


def _added(tree, output, *nodes):
    """The nodes' first outputs summed by Add Shaders into the material output."""
    out = nodes[0].outputs[0]
    for node in nodes[1:]:
        add = tree.nodes.new("ShaderNodeAddShader")
        tree.links.new(out, add.inputs[0])
        tree.links.new(node.outputs[0], add.inputs[1])
        out = add.outputs[0]
    tree.links.new(out, output.inputs["Surface"])


def test_anisotropy_exports_with_its_tangent_and_rotation():
    """Principled's Anisotropic, the Metallic BSDF's (Blender 5+) and Glossy's Anisotropy export with their
    rotation and a tangent, Geometry's where the Tangent socket is unlinked (one program node for
    all of them), a linked Tangent node's otherwise, without a warning; an isotropic shader has no
    tangent. Anisotropic shaders with different tangents in one material are named (a hit has one
    shading frame, along the first one's tangent)."""
    empty_scene()
    brushed, tree, output = _new_node_material("Brushed")
    principled = tree.nodes.new("ShaderNodeBsdfPrincipled")
    principled.inputs["Anisotropic"].default_value = 0.8
    principled.inputs["Anisotropic Rotation"].default_value = 0.25
    if hasattr(bpy.types, "ShaderNodeBsdfMetallic"):
        metallic = tree.nodes.new("ShaderNodeBsdfMetallic")
        metallic.inputs["Anisotropy"].default_value = 0.3
        metallic.inputs["Rotation"].default_value = 0.25
    else:  # before Blender 5: a metallic Principled BSDF
        metallic = tree.nodes.new("ShaderNodeBsdfPrincipled")
        metallic.inputs["Metallic"].default_value = 1.0
        metallic.inputs["Anisotropic"].default_value = 0.3
        metallic.inputs["Anisotropic Rotation"].default_value = 0.25
    plain = tree.nodes.new("ShaderNodeBsdfPrincipled")
    _added(tree, output, principled, metallic, plain)
    turned, tree, output = _new_node_material("Turned")
    glossy = tree.nodes.new("ShaderNodeBsdfAnisotropic")
    glossy.inputs["Anisotropy"].default_value = -0.5
    tangent = tree.nodes.new("ShaderNodeTangent")
    tangent.direction_type, tangent.axis = "RADIAL", "X"
    tree.links.new(tangent.outputs[0], glossy.inputs["Tangent"])
    second = tree.nodes.new("ShaderNodeBsdfPrincipled")
    second.inputs["Anisotropic"].default_value = 0.5
    _added(tree, output, glossy, second)
    scene = _material_scene(brushed)
    add_object(scene, "Other", cube_mesh()).data.materials.append(turned)
    data = render_export(scene)
    p, m, iso = _closures(data, "Brushed")
    assert (p.anisotropy, p.anisotropic_rotation) == pytest.approx((0.8, 0.25))
    assert (m.anisotropy, m.anisotropic_rotation) == pytest.approx((0.3, 0.25))
    assert p.inputs["tangent"] == m.inputs["tangent"] and "tangent" not in iso.inputs
    g, second = _closures(data, "Turned")
    assert g.anisotropy == pytest.approx(-0.5) and g.inputs["tangent"] != second.inputs["tangent"]
    (warning,) = data.warnings
    assert "'Turned'" in warning and "different tangents" in warning, warning


def test_muted_mix_shader_passes_its_first_shader_through():
    empty_scene()
    material, tree, output = _new_node_material("Muted")
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.9
    tree.links.new(tree.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[1])
    tree.links.new(tree.nodes.new("ShaderNodeBsdfGlossy").outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    mix.mute = True
    data = render_export(_material_scene(material))
    assert [(c.kind, c.weight[0]) for c in _closures(data, "Muted")] == [("DIFFUSE", 1.0)]


def test_linked_sockets_fall_back_to_defaults_with_one_warning():
    empty_scene()
    material = new_material("Textured")
    tree = material.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.1, 0.2, 0.3, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.4
    info = tree.nodes.new("ShaderNodePointInfo")  # a node DRT does not evaluate
    tree.links.new(info.outputs["Radius"], bsdf.inputs["Base Color"])
    tree.links.new(info.outputs["Radius"], bsdf.inputs["Roughness"])
    value = tree.nodes.new("ShaderNodeValue")  # a constant node is evaluated, not warned about
    value.outputs[0].default_value = 0.9
    tree.links.new(value.outputs[0], bsdf.inputs["Metallic"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Textured")
    np.testing.assert_allclose(closure.color, (0.1, 0.2, 0.3), rtol=1e-6)
    assert closure.roughness == pytest.approx(0.4)
    assert closure.metallic == pytest.approx(0.9)
    assert len(data.warnings) == 1
    assert "Textured" in data.warnings[0] and "Point Info" in data.warnings[0]


def test_unconnected_surface_has_no_closures():
    empty_scene()
    material, _tree, _output = _new_node_material("Black")
    data = render_export(_material_scene(material))
    assert _closures(data, "Black") == []


def test_material_slots_map_to_scene_materials():
    scene = empty_scene()
    red = new_material("Red")
    blue = new_material("Blue")
    mesh = cube_mesh("TwoSlots")
    mesh.materials.append(red)
    mesh.materials.append(None)  # empty slot: default surface
    mesh.materials.append(blue)
    for face, slot in zip(mesh.polygons, [0, 1, 2, 2, 7, 0]):  # 7: past the last slot, clamped
        face.material_index = slot
    add_object(scene, "Plain", mesh)
    twin = add_object(scene, "Twin", mesh, location=(3, 0, 0))  # linked duplicate
    add_object(scene, "Bare", cube_mesh("Bare"), location=(-3, 0, 0))
    data = render_export(scene)
    names = [m.name for m in data.materials]
    assert names[0] == "Default" and data.materials[0] is DEFAULT_MATERIAL
    by_name = {i.name: i for i in data.instances}
    assert by_name["Plain"].mesh == by_name["Twin"].mesh  # same data, same materials: exported once
    per_face = [names[i] for i in data.meshes[by_name["Plain"].mesh].material_indices[::2]]
    assert per_face == ["Red", "Default", "Blue", "Blue", "Blue", "Red"]
    assert set(data.meshes[by_name["Bare"].mesh].material_indices.tolist()) == {0}

    # an object-linked slot gives the twin other materials, hence its own mesh
    twin.material_slots[0].link = "OBJECT"
    twin.material_slots[0].material = blue
    data = render_export(scene)
    by_name = {i.name: i for i in data.instances}
    assert by_name["Plain"].mesh != by_name["Twin"].mesh
    names = [m.name for m in data.materials]
    assert names[data.meshes[by_name["Twin"].mesh].material_indices[0]] == "Blue"
    assert names[data.meshes[by_name["Plain"].mesh].material_indices[0]] == "Red"
    assert sorted(names) == ["Blue", "Default", "Red"]  # each material once


# ---------------------------------------------------------------- lights


def _light(scene, kind, name=None, location=(0.0, 0.0, 5.0), **settings):
    light = bpy.data.lights.new(name or kind, kind)
    for key, value in settings.items():
        setattr(light, key, value)
    return add_object(scene, name or kind, light, location)


def _lights(data):
    return {light.name: light for light in data.lights}


light_units = pytest.mark.skipif(
    "normalize" not in bpy.types.PointLight.bl_rna.properties,
    reason="Blender 4.2's lights have no Normalize, Exposure or Temperature (later versions added them)")


def test_point_and_spot_lights_in_cycles_units():
    scene = empty_scene()
    _light(scene, "POINT", energy=100.0, color=(1.0, 0.5, 0.25), shadow_soft_size=0.3)
    _light(scene, "POINT", "Hard", energy=100.0, shadow_soft_size=0.0, use_soft_falloff=False)
    spot = _light(scene, "SPOT", energy=40.0, spot_size=0.8, spot_blend=0.3, shadow_soft_size=0.1)
    spot.rotation_euler = (math.pi / 2, 0.0, 0.0)
    spot.scale = (2.0, 2.0, 2.0)
    lights = _lights(render_export(scene))
    point = lights["POINT"]
    # Cycles: radiant intensity = P / (4 pi) W/sr, the radius does not change it
    np.testing.assert_allclose(point.intensity, np.array([1.0, 0.5, 0.25]) * 100.0 / (4 * math.pi), rtol=1e-6)
    assert point.radius == pytest.approx(0.3) and point.soft_falloff
    np.testing.assert_allclose(point.position, (0.0, 0.0, 5.0))
    assert not lights["Hard"].soft_falloff and lights["Hard"].radius == 0.0
    spot_light = lights["SPOT"]
    np.testing.assert_allclose(spot_light.intensity, 40.0 / (4 * math.pi), rtol=1e-6)
    assert (spot_light.spot_size, spot_light.spot_blend) == pytest.approx((0.8, 0.3))
    assert spot_light.radius == pytest.approx(0.1)  # Cycles ignores object scale for the radius
    np.testing.assert_allclose(spot_light.matrix[:3, :3] @ spot_light.matrix[:3, :3].T, np.eye(3), atol=1e-6)
    # -Z rotated by 90 degrees about X
    np.testing.assert_allclose(spot_light.direction, (0.0, 1.0, 0.0), atol=1e-6)


@light_units
def test_unnormalized_point_light_exposure_and_temperature():
    scene = empty_scene()
    _light(scene, "POINT", energy=10.0, shadow_soft_size=0.5, normalize=False)
    warm = _light(scene, "POINT", "Warm", energy=10.0, use_temperature=True, temperature=3000.0)
    _light(scene, "POINT", "Exposed", energy=100.0, color=(1.0, 0.5, 0.25), shadow_soft_size=0.3, exposure=1.0)
    lights = _lights(render_export(scene))
    # Cycles: radiant intensity = P * 2^exposure / (4 pi) W/sr
    np.testing.assert_allclose(lights["Exposed"].intensity, np.array([1.0, 0.5, 0.25]) * 200.0 / (4 * math.pi),
                               rtol=1e-6)
    # Cycles without normalisation: sphere radiance P/pi, so intensity P/pi * pi r^2 = P r^2
    np.testing.assert_allclose(lights["POINT"].intensity, 10.0 * 0.25, rtol=1e-6)
    blackbody = np.array(warm.data.temperature_color[:])
    assert blackbody[0] > blackbody[2]  # 3000 K is reddish
    np.testing.assert_allclose(lights["Warm"].intensity, blackbody * 10.0 / (4 * math.pi), rtol=1e-6)


def test_sun_irradiance_equals_strength():
    scene = empty_scene()
    _light(scene, "SUN", energy=3.0, angle=0.2)
    lights = _lights(render_export(scene))
    np.testing.assert_allclose(lights["SUN"].irradiance, 3.0)
    assert lights["SUN"].angle == pytest.approx(0.2)


@light_units
def test_unnormalized_sun_and_area_light():
    scene = empty_scene()
    _light(scene, "SUN", "RawSun", energy=3.0, angle=0.2, normalize=False)
    _light(scene, "AREA", "RawArea", energy=60.0, size=2.0, normalize=False)
    lights = _lights(render_export(scene))
    # unnormalised: radiance = strength over a disk of pi sin^2(angle / 2) sr
    np.testing.assert_allclose(lights["RawSun"].irradiance, 3.0 * math.pi * math.sin(0.1) ** 2, rtol=1e-6)
    np.testing.assert_allclose(lights["RawArea"].radiance, 60.0 / math.pi, rtol=1e-6)  # P / pi, whatever A


def test_area_light_sizes_carry_the_object_scale():
    scene = empty_scene()
    rect = _light(scene, "AREA", "Rect", energy=60.0, shape="RECTANGLE", size=2.0, size_y=0.5, spread=1.0)
    rect.scale = (3.0, 2.0, 7.0)
    _light(scene, "AREA", "Disk", energy=60.0, shape="DISK", size=2.0)
    _light(scene, "AREA", "Ellipse", energy=60.0, shape="ELLIPSE", size=2.0, size_y=1.0)
    _light(scene, "AREA", "Square", energy=60.0, shape="SQUARE", size=2.0, size_y=9.0)  # size_y unused
    lights = _lights(render_export(scene))
    r = lights["Rect"]
    assert (r.shape, r.size_x, r.size_y) == ("RECTANGLE", pytest.approx(6.0), pytest.approx(1.0))
    np.testing.assert_allclose(r.radiance, 60.0 / (math.pi * 6.0), rtol=1e-6)  # P / (pi A)
    assert r.spread == pytest.approx(1.0)
    np.testing.assert_allclose(r.matrix[:3, :3], np.eye(3), atol=1e-6)  # scale removed
    np.testing.assert_allclose(lights["Disk"].radiance, 60.0 / (math.pi * math.pi), rtol=1e-6)  # A = pi r^2
    np.testing.assert_allclose(lights["Ellipse"].radiance, 60.0 / (math.pi * math.pi / 2), rtol=1e-6)
    assert (lights["Square"].size_x, lights["Square"].size_y) == (2.0, 2.0)


def test_lights_without_contribution_are_dropped():
    scene = empty_scene()
    _light(scene, "POINT", "Dark", energy=0.0)
    _light(scene, "POINT", "Black", energy=10.0, color=(0.0, 0.0, 0.0))
    _light(scene, "AREA", "Tiny", energy=10.0, size=0.0)
    _light(scene, "AREA", "Flat", energy=10.0).scale = (1.0, 0.0, 1.0)
    _light(scene, "POINT", "Kept", energy=1.0, shadow_soft_size=0.0)
    assert list(_lights(render_export(scene))) == ["Kept"]


def test_instanced_lights_are_each_exported():
    scene = empty_scene()
    source = bpy.data.collections.new("Lamps")
    source.objects.link(bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT")))
    for i in range(2):
        empty = add_object(scene, f"Holder{i}", None, location=(0.0, 2.0 * i, 0.0))
        empty.instance_type, empty.instance_collection = "COLLECTION", source
    data = render_export(scene)
    assert sorted(light.position[1] for light in data.lights) == pytest.approx([0.0, 2.0])


# ---------------------------------------------------------------- world


def test_world_background_colour_times_strength():
    scene = empty_scene()
    assert np.all(render_export(scene).world.radiance == 0.0)  # no world: black
    scene.world = new_world("World")
    np.testing.assert_allclose(render_export(scene).world.radiance, 0.05, rtol=1e-6)  # Blender 5.0 default
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 0.5, 0.25, 1.0)
    background.inputs["Strength"].default_value = 2.0
    data = render_export(scene)
    np.testing.assert_allclose(data.world.radiance, (2.0, 1.0, 0.5), rtol=1e-6)
    assert data.warnings == []


@pytest.mark.parametrize("falloff, exponent", [("QUADRATIC", 2.0), ("LINEAR", 1.0), ("INVERSE_QUADRATIC", 0.5)])
def test_mist_settings_and_pass_indices(falloff, exponent):
    """The world's mist (no world: Cycles' film defaults) and the object and material pass indices."""
    scene = empty_scene()
    obj = add_object(scene, "Cube", cube_mesh())
    obj.pass_index = 6
    mat = new_material("Indexed")
    mat.pass_index = 9
    obj.data.materials.append(mat)
    data = render_export(scene)
    assert (data.world.mist_start, data.world.mist_depth, data.world.mist_falloff) == (0.0, 100.0, 1.0)
    scene.world = new_world("World")
    mist = scene.world.mist_settings
    mist.start, mist.depth, mist.falloff = 2.5, 7.0, falloff
    data = render_export(scene)
    assert (data.world.mist_start, data.world.mist_depth, data.world.mist_falloff) == (2.5, 7.0, exponent)
    assert [i.pass_index for i in data.instances] == [6]
    assert [m.pass_index for m in data.materials if m.name == "Indexed"] == [9]


def test_world_texture_without_image_is_magenta_with_one_warning():
    """As Cycles (measured: an Image Texture without an image renders (1, 0, 1))."""
    scene = empty_scene()
    scene.world = new_world("Sky")
    tree = scene.world.node_tree
    background = tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.2, 0.3, 0.4, 1.0)
    background.inputs["Strength"].default_value = 1.5
    tree.links.new(tree.nodes.new("ShaderNodeTexEnvironment").outputs["Color"], background.inputs["Color"])
    data = render_export(scene)
    np.testing.assert_allclose(data.world.radiance, np.array([1.0, 0.0, 1.0]) * 1.5, rtol=1e-6)
    assert len(data.warnings) == 1 and "Sky" in data.warnings[0]


# ---------------------------------------------------------------- camera


def _pixel(camera, point):
    """Pixel coordinates of a world point through the exported frame (the tracer's projection)."""
    local = np.linalg.inv(camera.matrix) @ np.array([*point, 1.0])
    x, y = local[:2] / (-local[2] if camera.type == "PERSP" else 1.0)
    left, right, bottom, top = camera.frame
    w, h = camera.resolution
    return np.array([(x - left) / (right - left) * w, (y - bottom) / (top - bottom) * h])


CAMERA_CASES = {
    "landscape": {},
    "shift": {"shift_x": 0.15, "shift_y": -0.1},
    "portrait_auto": {"resolution": (30, 64)},
    "vertical_fit": {"sensor_fit": "VERTICAL", "sensor_height": 20.0},
    "pixel_aspect": {"pixel_aspect": (2.0, 1.0)},
    "pixel_aspect_y": {"pixel_aspect": (1.0, 1.5), "resolution": (30, 64), "shift_x": 0.05},
    "ortho": {"type": "ORTHO", "ortho_scale": 9.0, "shift_y": 0.2},
    "ortho_vertical": {
        "type": "ORTHO",
        "ortho_scale": 5.0,
        "sensor_fit": "VERTICAL",
        "pixel_aspect": (1.0, 2.0),
    },
}


@pytest.mark.parametrize("case", sorted(CAMERA_CASES))
def test_camera_frame_matches_blenders_projection(case):
    settings = dict(CAMERA_CASES[case])
    scene = empty_scene(*settings.pop("resolution", (64, 48)))
    scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = settings.pop("pixel_aspect", (1.0, 1.0))
    cam = scene.camera
    cam.location = (1.0, -8.0, 4.0)
    cam.rotation_euler = (1.2, 0.05, 0.2)
    cam.scale = (1.5, 1.5, 1.5)  # removed from the exported matrix, as Cycles does
    for key, value in settings.items():
        setattr(cam.data, key, value)
    camera = render_export(scene).camera
    np.testing.assert_allclose(camera.matrix[:3, :3] @ camera.matrix[:3, :3].T, np.eye(3), atol=1e-6)
    size = np.array(camera.resolution)
    for point in [(0.0, 0.0, 0.0), (1.5, 2.0, -0.5), (-2.0, 1.0, 1.0), (0.5, -3.0, 2.0)]:
        blender = np.array(world_to_camera_view(scene, cam, Vector(point))[:2]) * size
        np.testing.assert_allclose(_pixel(camera, point), blender, atol=1e-4)


def test_resolution_percentage_and_border_window():
    scene = empty_scene(100, 60)
    render = scene.render
    render.resolution_percentage = 50
    render.use_border = True
    render.border_min_x, render.border_max_x = 0.25, 0.75
    render.border_min_y, render.border_max_y = 0.25, 0.75
    camera = render_export(scene).camera
    assert camera.resolution == (50, 30)
    assert camera.window == (12, 7, 37, 22)  # Blender truncates 12.5, 7.5, 37.5, 22.5
    # in single precision, as Blender: 0.7f * 50 = 35.0 exactly (in double 34.9999...)
    render.border_max_x = 0.7
    assert render_export(scene).camera.window[2] == 35
    render.use_border = False
    assert render_export(scene).camera.window == (0, 0, 50, 30)


def test_depth_of_field_and_clipping():
    scene = empty_scene()
    cam = scene.camera
    cam.data.lens = 50.0
    cam.data.clip_start, cam.data.clip_end = 0.5, 200.0
    assert render_export(scene).camera.aperture_radius == 0.0  # depth of field off
    cam.data.dof.use_dof = True
    cam.data.dof.aperture_fstop = 2.8
    cam.data.dof.focus_distance = 7.0
    camera = render_export(scene).camera
    assert camera.aperture_radius == pytest.approx(0.050 / (2 * 2.8))  # lens in metres / (2 f-stop)
    assert camera.focus_distance == pytest.approx(7.0)
    assert (camera.clip_start, camera.clip_end) == pytest.approx((0.5, 200.0))
    # focus object: distance along the view axis (camera at z = 10 looking down -Z)
    cam.data.dof.focus_object = add_object(scene, "Target", None, location=(3.0, -2.0, 4.0))
    assert render_export(scene).camera.focus_distance == pytest.approx(6.0)


def test_film_transparent():
    scene = empty_scene()
    assert not render_export(scene).film_transparent
    scene.render.film_transparent = True
    assert render_export(scene).film_transparent


def test_missing_camera_is_a_scene_error():
    """(A panorama type DRT does not render: test_panorama_cycles, for the Blenders that have one.)"""
    scene = empty_scene()
    scene.camera = None
    with pytest.raises(SceneError, match="No camera found in scene"):
        export_scene(bpy.context.evaluated_depsgraph_get())


# ---------------------------------------------------------------- more instancing and overrides


def test_particle_instances_export_the_mesh_once():
    scene = empty_scene()
    emitter = add_object(scene, "Emitter", cube_mesh("Emitter"))
    hidden = bpy.data.collections.new("Hidden")  # the instanced object itself is not in the scene
    pebble = bpy.data.objects.new("Pebble", cube_mesh("Pebble"))
    hidden.objects.link(pebble)
    emitter.modifiers.new("Particles", "PARTICLE_SYSTEM")
    settings = emitter.particle_systems[0].settings
    settings.type = "HAIR"
    settings.count = 25
    settings.render_type = "OBJECT"
    settings.instance_object = pebble
    emitter.show_instancer_for_render = False
    data = render_export(scene)
    assert len(data.instances) == 25  # the emitter is not rendered
    assert len(data.meshes) == 1 and data.meshes[0].name == "Pebble"
    emitter.show_instancer_for_render = True
    assert len(render_export(scene).instances) == 26


def test_view_layer_material_and_world_overrides():
    scene = empty_scene()
    red = new_material("Red")
    override = new_material("Override")
    cube = add_object(scene, "Cube", cube_mesh())
    cube.data.materials.append(red)
    scene.world = new_world("Scene world")
    other = new_world("Override world")
    other.node_tree.nodes["Background"].inputs["Strength"].default_value = 4.0
    view_layer = scene.view_layers[0]
    view_layer.material_override = override
    view_layer.world_override = other
    data = render_export(scene)
    assert [m.name for m in data.materials] == ["Default", "Override"]
    assert set(data.meshes[0].material_indices.tolist()) == {1}
    np.testing.assert_allclose(data.world.radiance, 0.05 * 4.0, rtol=1e-6)


def test_unsupported_shader_node_renders_default_grey_with_one_warning():
    empty_scene()
    material, tree, output = _new_node_material("Portal")
    tree.links.new(tree.nodes.new("ShaderNodeBsdfRayPortal").outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    closures = _closures(data, "Portal")
    assert [(c.kind, tuple(c.color)) for c in closures] == [
        (c.kind, tuple(c.color)) for c in DEFAULT_MATERIAL.closures
    ]
    assert len(data.warnings) == 1 and "Ray Portal BSDF" in data.warnings[0]


@pytest.mark.parametrize("distribution", ["MICROFIBER", "ASHIKHMIN"])
def test_sheen_bsdf_exports_colour_and_roughness(distribution):
    """The Sheen BSDF is Cycles' microfiber sheen without a warning; the legacy Ashikhmin velvet is
    rendered as microfiber and named."""
    empty_scene()
    material, tree, output = _new_node_material("Sheen")
    node = tree.nodes.new("ShaderNodeBsdfSheen")
    node.distribution = distribution
    node.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    node.inputs["Roughness"].default_value = 0.3
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Sheen")
    assert closure.kind == "SHEEN" and closure.roughness == pytest.approx(0.3)
    np.testing.assert_allclose(closure.color, [0.2, 0.4, 0.6], rtol=1e-6)
    if distribution == "MICROFIBER":
        assert data.warnings == []
    else:
        assert len(data.warnings) == 1 and "Ashikhmin" in data.warnings[0]


@pytest.mark.parametrize("component, kind", [("DIFFUSE", "DIFFUSE_TOON"), ("GLOSSY", "GLOSSY_TOON")])
def test_toon_bsdf_exports_its_component_size_and_smooth_without_a_warning(component, kind):
    empty_scene()
    material, tree, output = _new_node_material("Toon")
    toon = tree.nodes.new("ShaderNodeBsdfToon")
    toon.component = component
    toon.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    toon.inputs["Size"].default_value = 0.3
    toon.inputs["Smooth"].default_value = 0.1
    tree.links.new(toon.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Toon")
    assert closure.kind == kind
    np.testing.assert_allclose(closure.color, (0.2, 0.4, 0.6), rtol=1e-6)
    assert (closure.toon_size, closure.toon_smooth) == pytest.approx((0.3, 0.1))
    assert data.warnings == []


def _program_coord(material, ref):
    """The coordinate name of the program node ``ref`` points at."""
    node = material.program.nodes[ref[0]]
    assert node.op == "coord"
    return node.params["name"]


@pytest.mark.parametrize("component, kind", [("Reflection", "HAIR_REFLECTION"), ("Transmission", "HAIR_TRANSMISSION")])
def test_hair_bsdf_exports_about_the_triangles_dpdv_without_a_warning(component, kind):
    """Unlinked Tangent: the strand is each triangle's dPdv and Offset 0, as Cycles on a mesh;
    linked: that direction, with the node's Offset."""
    empty_scene()
    material, tree, output = _new_node_material("Hair")
    hair = tree.nodes.new("ShaderNodeBsdfHair")
    hair.component = component
    hair.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    hair.inputs["Offset"].default_value = 0.1
    hair.inputs["RoughnessU"].default_value = 0.2
    hair.inputs["RoughnessV"].default_value = 0.7
    tree.links.new(hair.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Hair")
    (exported,) = [m for m in data.materials if m.name == "Hair"]
    assert closure.kind == kind and data.warnings == []
    assert (closure.roughness, closure.hair_roughness_v, closure.hair_offset) == pytest.approx((0.2, 0.7, 0.0))
    np.testing.assert_allclose(closure.color, (0.2, 0.4, 0.6), rtol=1e-6)
    assert _program_coord(exported, closure.inputs["hair_tangent"]) == "dpdv"
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["Object"], hair.inputs["Tangent"])
    data = render_export(bpy.context.scene)
    (closure,) = _closures(data, "Hair")
    (exported,) = [m for m in data.materials if m.name == "Hair"]
    assert closure.hair_offset == pytest.approx(0.1)
    assert _program_coord(exported, closure.inputs["hair_tangent"]) == "object"


@pytest.mark.parametrize("model", ["CHIANG", "HUANG"])
def test_principled_hair_exports_its_model_and_parametrization(model):
    """Chiang without a warning; Huang named (export.materials.HUANG_NOTE); before 5.0 both named
    (VERSION_PRINCIPLED_HAIR)."""
    empty_scene()
    material, tree, output = _new_node_material("Principled Hair")
    hair = tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    hair.model, hair.parametrization = model, "MELANIN"
    values = {"Melanin": 0.3, "Melanin Redness": 0.6, "Roughness": 0.25, "IOR": 1.4, "Random Roughness": 0.2}
    for name, value in values.items():
        hair.inputs[name].default_value = value
    hair.inputs["Tint"].default_value = (0.9, 0.8, 0.7, 1.0)
    if model == "HUANG":  # Huang's alone
        hair.inputs["Secondary Reflection"].default_value = 0.5
    tree.links.new(hair.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Principled Hair")
    (exported,) = [m for m in data.materials if m.name == "Principled Hair"]
    assert closure.kind == "PRINCIPLED_HAIR"
    old = bpy.app.version < PRINCIPLED_HAIR_MATCHED_FROM
    if model == "HUANG" or old:
        assert len(data.warnings) == 1, data.warnings
        assert HUANG_NOTE in data.warnings[0] or model != "HUANG"
        assert VERSION_PRINCIPLED_HAIR in data.warnings[0] or not old
    else:
        assert data.warnings == []
    assert (closure.hair_model, closure.hair_parametrization) == (model, "MELANIN")
    got = (closure.melanin, closure.melanin_redness, closure.roughness, closure.ior, closure.random_roughness)
    assert got == pytest.approx(tuple(values.values()), rel=1e-6)
    np.testing.assert_allclose(closure.hair_tint, (0.9, 0.8, 0.7), rtol=1e-6)
    np.testing.assert_allclose(closure.hair_gains, (1.0, 1.0, 0.5) if model == "HUANG" else (1.0, 1.0, 1.0), rtol=1e-6)
    assert _program_coord(exported, closure.inputs["hair_tangent"]) == "dpdu"


def test_principled_thin_film_exports_thickness_and_ior_without_a_warning_from_5_0():
    """Thickness and IOR go to the closure (the thickness linkable); from 5.0 the film covers the
    metal too and nothing is named; before, the metal stays bare and the film is named."""
    empty_scene()
    material, tree, output = _new_node_material("Film")
    bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Thin Film Thickness"].default_value = 420.0
    bsdf.inputs["Thin Film IOR"].default_value = 1.6
    tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Film")
    assert (closure.thin_film_thickness, closure.thin_film_ior) == pytest.approx((420.0, 1.6))
    if bpy.app.version >= (5, 0):
        assert closure.thin_film_metal and data.warnings == []
    else:
        assert not closure.thin_film_metal and len(data.warnings) == 1 and "thin film" in data.warnings[0]
    z = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["Generated"], z.inputs[0])
    tree.links.new(z.outputs["Z"], bsdf.inputs["Thin Film Thickness"])
    (closure,) = _closures(render_export(bpy.context.scene), "Film")
    assert "thin_film_thickness" in closure.inputs


def test_thin_film_over_a_physical_conductor_is_named():
    if bpy.app.version < (5, 0):
        pytest.skip("the Metallic BSDF is Blender 5's")
    empty_scene()
    material, tree, output = _new_node_material("Conductor film")
    metal = tree.nodes.new("ShaderNodeBsdfMetallic")
    metal.fresnel_type = "PHYSICAL_CONDUCTOR"
    metal.inputs["Thin Film Thickness"].default_value = 300.0
    tree.links.new(metal.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    assert len(data.warnings) == 1 and "thin film over a Physical Conductor" in data.warnings[0]


def test_light_node_tree_emission_scales_the_strength():
    scene = empty_scene()
    lamp = _light(scene, "POINT", energy=10.0)
    with_nodes(lamp.data)
    emission = next(n for n in lamp.data.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 3.0
    emission.inputs["Color"].default_value = (1.0, 0.5, 0.0, 1.0)
    (light,) = render_export(scene).lights
    np.testing.assert_allclose(light.intensity, np.array([3.0, 1.5, 0.0]) * 10.0 / (4 * math.pi), rtol=1e-6)


def test_export_can_be_cancelled():
    from drt_engine.core.errors import RenderCancelled

    scene = empty_scene()
    add_object(scene, "Cube", cube_mesh())
    with pytest.raises(RenderCancelled):
        export_scene(bpy.context.evaluated_depsgraph_get(), cancel=lambda: True)


def test_object_types_drt_does_not_render_are_named_in_one_warning():
    """Hair curves, point clouds, volumes and hair particles render in Cycles; DRT leaves them out,
    never silently. Text and curves reach the export as meshes and render; an empty renders in neither."""
    scene = empty_scene()
    add_object(scene, "Cube", cube_mesh())
    for name, data in (("Strands", bpy.data.hair_curves.new("Strands")), ("Points", bpy.data.pointclouds.new("Points")),
                       ("Smoke", bpy.data.volumes.new("Smoke")), ("Label", bpy.data.curves.new("Label", "FONT")),
                       ("Empty", None)):
        scene.collection.objects.link(bpy.data.objects.new(name, data))
    fur = add_object(scene, "Furry", cube_mesh())
    fur.modifiers.new("Fur", "PARTICLE_SYSTEM").particle_system.settings.type = "HAIR"
    data = render_export(scene)
    (warning,) = data.warnings
    for name, what in (("Strands", "hair curves"), ("Points", "point cloud"), ("Smoke", "volume"),
                       ("Furry", "hair particles")):
        assert f"'{name}' ({what})" in warning, warning
    assert "Label" not in warning and "Empty" not in warning and "'Cube'" not in warning
    assert len(data.instances) == 3  # the two cubes and the text


def test_shadow_catchers_are_exported_and_named_in_no_warning():
    """Shadow Catcher is read (per instance, an instance taking its instancer's flag or its own, as
    Cycles' sync_object): no warning names it; light groups and light linking are read too."""
    scene = empty_scene()
    cubes = [add_object(scene, f"Cube{i}", cube_mesh(f"Cube{i}"), location=(3.0 * i, 0.0, 0.0)) for i in range(3)]
    cubes[0].is_shadow_catcher = True
    cubes[0].lightgroup = "key"
    cubes[1].light_linking.receiver_collection = bpy.data.collections.new("Lit")
    hidden = bpy.data.collections.new("Instanced")
    hidden.objects.link(cubes[2])
    instancer = add_object(scene, "Instancer", None, location=(0.0, 4.0, 0.0))
    instancer.instance_type, instancer.instance_collection = "COLLECTION", hidden
    instancer.is_shadow_catcher = True
    data = render_export(scene)
    assert not data.warnings, data.warnings
    caught = sorted((i.name, i.shadow_catcher) for i in data.instances)
    # Cube2 itself, and its instance, which takes its instancer's flag
    assert caught == [("Cube0", True), ("Cube1", False), ("Cube2", False), ("Cube2", True)], caught
    cubes[1].light_linking.receiver_collection = None


def test_light_and_shadow_linking_are_exported():
    """A receiver collection excluding one cube and a blocker collection including another: the
    excluded cube gets its own receiver set, which the emitter's membership leaves out; the
    included cube its own blocker set, the emitter's shadow membership that set alone."""
    scene = empty_scene()
    cubes = [add_object(scene, f"Cube{i}", cube_mesh(f"Cube{i}")) for i in range(3)]
    receivers, blockers = bpy.data.collections.new("Receivers"), bpy.data.collections.new("Blockers")
    receivers.objects.link(cubes[1])
    receivers.collection_objects[0].light_linking.link_state = "EXCLUDE"
    blockers.objects.link(cubes[2])
    cubes[0].light_linking.receiver_collection = receivers
    cubes[0].light_linking.blocker_collection = blockers
    data = render_export(scene)
    by_name = {i.name: i for i in data.instances}
    emitter, excluded, blocker = by_name["Cube0"], by_name["Cube1"], by_name["Cube2"]
    assert excluded.receiver_light_set == 1 and by_name["Cube2"].receiver_light_set == 0
    assert emitter.light_set_membership == (1 << 64) - 1 - 2
    assert blocker.blocker_shadow_set == 1 and excluded.blocker_shadow_set == 0
    assert emitter.shadow_set_membership == 2
    assert excluded.light_set_membership == (1 << 64) - 1 and not data.warnings


def test_instances_take_their_instancers_linking_sets():
    """A collection instance whose instancer a receiver collection excludes and a blocker collection
    includes: its instances take the instancer's receiver and blocker sets (Cycles' BlenderLightLink
    reads the parent's where it is not the default), the instanced object itself keeps its own."""
    scene = empty_scene()
    emitter = add_object(scene, "Emitter", cube_mesh("Emitter"))
    source = bpy.data.collections.new("Source")
    source.objects.link(add_object(scene, "Inner", cube_mesh("Inner"), location=(3.0, 0.0, 0.0)))
    instancer = add_object(scene, "Instancer", None, location=(0.0, 4.0, 0.0))
    instancer.instance_type, instancer.instance_collection = "COLLECTION", source
    receivers, blockers = bpy.data.collections.new("Receivers"), bpy.data.collections.new("Blockers")
    receivers.objects.link(instancer)
    receivers.collection_objects[0].light_linking.link_state = "EXCLUDE"
    blockers.objects.link(instancer)
    emitter.light_linking.receiver_collection = receivers
    emitter.light_linking.blocker_collection = blockers
    data = render_export(scene)
    inner = sorted((i.receiver_light_set, i.blocker_shadow_set) for i in data.instances if i.name == "Inner")
    assert inner == [(0, 0), (1, 1)], inner  # the object itself, then its instance
    assert not data.warnings, data.warnings


def test_more_blocker_sets_than_drt_tells_apart_are_named():
    """Each of 28 emitters' blocker collection includes a cube of its own: 28 blocker sets, past the
    26 DRT's shadow masks tell apart (the 27th and 28th cubes cast every shadow): one warning."""
    scene = empty_scene()
    for i in range(28):
        emitter = add_object(scene, f"Emitter{i}", cube_mesh(f"Emitter{i}"))
        blockers = bpy.data.collections.new(f"Blockers{i}")
        blockers.objects.link(add_object(scene, f"Blocker{i}", cube_mesh(f"Blocker{i}")))
        emitter.light_linking.blocker_collection = blockers
    warnings = [w for w in render_export(scene).warnings if "shadow linking" in w]
    assert len(warnings) == 1 and "28 sets" in warnings[0], warnings


def test_light_groups_are_exported():
    """The view layer's light groups, and each object's, light's and the world's group as an index
    among them (-1: none, or a name the view layer has no group of, as Cycles)."""
    scene = empty_scene()
    layer = scene.view_layers[0]
    for name in ("key", "fill"):
        layer.lightgroups.add(name=name)
    cubes = [add_object(scene, f"Cube{i}", cube_mesh(f"Cube{i}")) for i in range(3)]
    cubes[0].lightgroup, cubes[1].lightgroup = "fill", "elsewhere"
    lamp = add_object(scene, "Lamp", bpy.data.lights.new("Lamp", "POINT"), (0.0, 0.0, 3.0))
    lamp.lightgroup = "key"
    scene.world = bpy.data.worlds.new("World")
    scene.world.lightgroup = "fill"
    data = render_export(scene)
    assert data.light_groups == ["key", "fill"]
    groups = {i.name: i.lightgroup for i in data.instances}
    assert groups == {"Cube0": 1, "Cube1": -1, "Cube2": -1}
    assert [light.lightgroup for light in data.lights] == [0]
    assert data.world.lightgroup == 1
    assert not data.warnings


def test_ray_visibility_and_cast_shadow_are_exported():
    """Objects' ray visibility, lights' diffuse, glossy and transmission visibility and Cast Shadow
    reach the scene, without a warning."""
    scene = empty_scene()
    cube = add_object(scene, "Cube", cube_mesh("Cube"))
    cube.visible_camera, cube.visible_shadow, cube.visible_glossy = False, False, False
    lamp = _light(scene, "POINT")
    lamp.visible_diffuse, lamp.visible_transmission, lamp.data.use_shadow = False, False, False
    data = render_export(scene)
    assert not data.warnings
    (inst,) = data.instances
    assert (inst.visible_camera, inst.visible_shadow, inst.visible_diffuse, inst.visible_glossy,
            inst.visible_transmission) == (False, False, True, False, True)
    (light,) = data.lights
    assert (light.visible_diffuse, light.visible_glossy, light.visible_transmission, light.cast_shadow) == \
        (False, True, False, False)


@pytest.mark.skipif(not hasattr(bpy.types, "ShaderNodeBsdfMetallic"), reason="Blender 5's Metallic BSDF")
@pytest.mark.parametrize("fresnel", ["F82", "PHYSICAL_CONDUCTOR"])
def test_metallic_bsdf_is_a_principled_metal(fresnel):
    """F82: Cycles' Principled metal (base colour, Edge Tint as its tint); Physical Conductor: the
    F82-tint fit of its IOR and extinction, named in the warning."""
    from drt_engine.core.bsdf.microfacet import conductor_f82
    empty_scene()
    material, tree, output = _new_node_material("Metal")
    node = tree.nodes.new("ShaderNodeBsdfMetallic")
    node.inputs["Base Color"].default_value = (0.9, 0.6, 0.2, 1.0)
    node.inputs["Edge Tint"].default_value = (0.5, 0.7, 0.9, 1.0)
    node.inputs["Roughness"].default_value = 0.25
    node.fresnel_type = fresnel  # the other mode's sockets are then gone
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    data = render_export(_material_scene(material))
    (closure,) = _closures(data, "Metal")
    assert closure.kind == "PRINCIPLED" and closure.metallic == 1.0 and closure.roughness == pytest.approx(0.25)
    if fresnel == "F82":
        np.testing.assert_allclose(closure.color, [0.9, 0.6, 0.2], rtol=1e-6)
        np.testing.assert_allclose(closure.specular_tint, [0.5, 0.7, 0.9], rtol=1e-6)
        assert not data.warnings
    else:
        f0, tint = conductor_f82(node.inputs["IOR"].default_value[:], node.inputs["Extinction"].default_value[:])
        np.testing.assert_allclose(closure.color, f0, rtol=1e-6)
        np.testing.assert_allclose(closure.specular_tint, tint, rtol=1e-6)
        assert len(data.warnings) == 1 and "Physical Conductor" in data.warnings[0]


def test_passes_drt_does_not_write_are_named_in_the_warning():
    """Cycles' Ambient Occlusion: a view layer asking for it gets no such pass from DRT, and says so
    (Diffuse / Glossy / Transmission Color, Direct and Indirect and Cryptomatte it writes)."""
    scene = empty_scene()
    add_object(scene, "Cube", cube_mesh())
    layer = scene.view_layers[0]
    light = ("use_pass_diffuse_color", "use_pass_glossy_color", "use_pass_diffuse_direct", "use_pass_glossy_indirect",
             "use_pass_transmission_direct", "use_pass_transmission_indirect", "use_pass_transmission_color")
    for toggle in light:
        setattr(layer, toggle, True)
    try:
        assert render_export(scene).warnings == []
        layer.use_pass_ambient_occlusion = layer.use_pass_cryptomatte_material = True
        (warning,) = render_export(scene).warnings
    finally:
        for toggle in light:
            setattr(layer, toggle, False)
        layer.use_pass_ambient_occlusion = layer.use_pass_cryptomatte_material = False
    assert "Ambient Occlusion" in warning and "Cryptomatte" not in warning
    assert "Diffuse" not in warning and "Glossy" not in warning and "Transmission" not in warning
