"""The committed sample scenes hold what they are for (the light kinds, materials, depth of field and
motion each one exercises), stay within what DRT supports (constant-input shader nodes, no textures,
a uniform world), carry Cycles settings for a like-for-like comparison, and are exactly what their
build scripts produce today."""
import math

import bpy
import pytest
from mathutils import Vector

from tests.support.sample_scene_files import OPENS_COMMITTED_FILES, SCENES, SCENES_DIR, build
SHADERS = {"BSDF_PRINCIPLED", "EMISSION", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_GLASS"}


def load(path):
    bpy.ops.wm.open_mainfile(filepath=str(path))
    return bpy.context.scene


def triangles(obj):
    obj.data.calc_loop_triangles()
    return len(obj.data.loop_triangles)


def rounded(values, digits=5):
    return tuple(round(float(v), digits) for v in values)


def material_facts(material):
    """Shader node types with their unlinked input values, and the output's surface source."""
    nodes = []
    for node in sorted(material.node_tree.nodes, key=lambda n: n.name):
        inputs = []
        for socket in node.inputs:
            value = getattr(socket, "default_value", None)
            if value is None:
                continue
            value = rounded(value) if hasattr(value, "__len__") else round(float(value), 5)
            inputs.append((socket.identifier, value, socket.is_linked))
        nodes.append((node.name, node.type, tuple(inputs)))
    return tuple(nodes)


def fingerprint(scene):
    """Everything a renderer reads from the scene, as comparable plain values."""
    objects = []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        facts = [obj.name, obj.type, rounded(v for row in obj.matrix_world for v in row)]
        if obj.type == "MESH":
            facts += [triangles(obj), tuple(slot.material.name for slot in obj.material_slots)]
        elif obj.type == "LIGHT":
            light = obj.data
            facts += [light.type, round(light.energy, 5), rounded(light.color), round(light.shadow_soft_size, 5)]
            facts += [getattr(light, k) for k in ("shape", "size", "size_y", "spot_size", "spot_blend", "angle")
                      if hasattr(light, k)]
        elif obj.type == "CAMERA":
            cam = obj.data
            facts += [cam.type, round(cam.lens, 5), cam.sensor_fit, round(cam.sensor_width, 5), cam.dof.use_dof,
                      round(cam.dof.aperture_fstop, 5), round(cam.dof.focus_distance, 5)]
        objects.append(tuple(facts))
    materials = tuple((m.name, material_facts(m)) for m in sorted(bpy.data.materials, key=lambda m: m.name))
    render, cycles = scene.render, scene.cycles
    settings = (
        render.resolution_x, render.resolution_y, render.resolution_percentage, render.filter_size,
        render.film_transparent, render.use_motion_blur, render.motion_blur_shutter, scene.frame_current,
        cycles.diffuse_bounces, cycles.glossy_bounces, cycles.transmission_bounces, cycles.blur_glossy,
        cycles.sample_clamp_direct, cycles.sample_clamp_indirect, cycles.use_denoising, cycles.device,
        cycles.pixel_filter_type, cycles.filter_width,
    )
    background = scene.world.node_tree.nodes["Background"]
    world = (rounded(background.inputs["Color"].default_value), background.inputs["Strength"].default_value)
    motion = tuple((obj.name, motion_at(scene, obj, 0.75), motion_at(scene, obj, 1.25))
                   for obj in sorted(scene.objects, key=lambda o: o.name) if obj.animation_data)
    scene.frame_set(1)
    return objects, materials, settings, world, motion


def motion_at(scene, obj, frame):
    scene.frame_set(int(math.floor(frame)), subframe=frame - math.floor(frame))
    return rounded(v for row in obj.matrix_world for v in row)


@pytest.fixture(scope="module")
def rebuilt(tmp_path_factory):
    """Each build script run afresh into a temporary folder, as `make scenes` runs it."""
    out = tmp_path_factory.mktemp("scenes")
    for name in SCENES:
        build(name, out / f"{name}.blend")
    return out


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.skipif(not OPENS_COMMITTED_FILES, reason="Blender 4.x cannot open the committed files (saved by 5.0)")
def test_build_script_reproduces_the_committed_scene(name, rebuilt):
    committed = fingerprint(load(SCENES_DIR / f"{name}.blend"))
    fresh = fingerprint(load(rebuilt / f"{name}.blend"))
    assert committed == fresh, f"sample_scenes/{name}.blend is stale: run `make scenes`"


@pytest.mark.parametrize("name", SCENES)
def test_scene_is_small_supported_and_comparable_with_cycles(name, sample_scene):
    scene = load(sample_scene(name))
    render, cycles = scene.render, scene.cycles
    assert scene.camera is not None and scene.camera.type == "CAMERA"
    assert 64 <= render.resolution_x <= 256 and 64 <= render.resolution_y <= 256
    assert render.resolution_percentage == 100
    assert cycles.pixel_filter_type == "BLACKMAN_HARRIS" and cycles.filter_width == render.filter_size == 1.5
    assert (cycles.diffuse_bounces, cycles.glossy_bounces, cycles.transmission_bounces) == (0, 8, 8)
    assert cycles.max_bounces >= 8
    assert cycles.blur_glossy == cycles.sample_clamp_direct == cycles.sample_clamp_indirect == 0
    assert not cycles.use_denoising and cycles.device == "CPU"

    world_nodes = scene.world.node_tree.nodes
    assert {n.type for n in world_nodes} == {"BACKGROUND", "OUTPUT_WORLD"}
    background = world_nodes["Background"]
    assert not background.inputs["Color"].is_linked and not background.inputs["Strength"].is_linked
    assert max(background.inputs["Color"].default_value[:3]) * background.inputs["Strength"].default_value <= 0.1

    meshes = [o for o in scene.objects if o.type == "MESH"]
    assert sum(triangles(o) for o in meshes) < 20000
    for obj in meshes:
        assert obj.material_slots and all(slot.material for slot in obj.material_slots), obj.name
        for slot in obj.material_slots:
            nodes = slot.material.node_tree.nodes
            shaders = {n.type for n in nodes} - {"OUTPUT_MATERIAL"}
            assert len(shaders) == 1 and shaders <= SHADERS, (slot.material.name, shaders)
            assert not any(s.is_linked for n in nodes if n.type != "OUTPUT_MATERIAL" for s in n.inputs)


def light_kinds(scene):
    return sorted((o.data.type, getattr(o.data, "shape", None) if o.data.type == "AREA" else None)
                  for o in scene.objects if o.type == "LIGHT")


def view_depth(camera, point):
    """Distance of a point in front of the camera along its view axis (-Z)."""
    return -(camera.matrix_world.inverted() @ Vector(point)).z


def test_cornell_box(sample_scene):
    scene = load(sample_scene("cornell_box"))
    assert light_kinds(scene) == [("AREA", "SQUARE")]
    light = next(o for o in scene.objects if o.type == "LIGHT")
    facing = light.matrix_world.to_3x3() @ Vector((0, 0, -1))
    assert facing.z == pytest.approx(-1.0), "the ceiling light faces the floor"
    assert scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value == 0.0

    room = scene.objects["Room"].data
    colors = {}
    for polygon in room.polygons:
        diffuse = room.materials[polygon.material_index].node_tree.nodes["Diffuse BSDF"]
        colors[tuple(round(c) for c in polygon.normal)] = diffuse.inputs["Color"].default_value
    left, right = colors[(1, 0, 0)], colors[(-1, 0, 0)]  # inward normals: +X is the left wall
    assert left[0] > 3 * left[1] and right[1] > 2 * right[0], "red wall on the left, green on the right"
    boxes = [o for o in scene.objects if o.type == "MESH" and o.name != "Room"]
    assert len(boxes) == 2
    for box in boxes:
        corners = [box.matrix_world @ Vector(c) for c in box.bound_box]
        assert all(-1 < c.x < 1 and -1 < c.y < 1 and -1e-6 <= c.z < 2 for c in corners), box.name


def test_glossy_spheres(sample_scene):
    scene = load(sample_scene("glossy_spheres"))
    lights = [o.data for o in scene.objects if o.type == "LIGHT"]
    assert [l.type for l in lights] == ["AREA", "AREA"]
    areas = [l.size * (l.size_y if l.shape in ("RECTANGLE", "ELLIPSE") else l.size) for l in lights]
    assert max(areas) > 4 * min(areas), "one small and one large light"
    assert tuple(lights[0].color) != tuple(lights[1].color)

    principled = []
    for obj in scene.objects:
        if obj.type == "MESH" and obj.name != "Floor":
            node = obj.material_slots[0].material.node_tree.nodes["Principled BSDF"]
            principled.append((node.inputs["Metallic"].default_value, node.inputs["Roughness"].default_value))
            assert min((obj.matrix_world @ Vector(c)).z for c in obj.bound_box) == pytest.approx(0, abs=1e-5)
    dielectric = sorted(r for m, r in principled if m == 0)
    assert len(dielectric) >= 3 and dielectric[0] == pytest.approx(0.05) and dielectric[-1] == pytest.approx(0.6)
    assert sum(m == 1 for m, _ in principled) == 1, "one metal"


def test_dof_row(sample_scene):
    scene = load(sample_scene("dof_row"))
    assert light_kinds(scene) == [("AREA", "DISK"), ("SUN", None)]
    camera = scene.camera
    dof = camera.data.dof
    assert dof.use_dof and 1.4 <= dof.aperture_fstop <= 4.0
    row = sorted((o for o in scene.objects if o.name.startswith("Object")), key=lambda o: o.name)
    depths = [view_depth(camera, o.matrix_world.translation) for o in row]
    assert depths == sorted(depths) and depths[-1] > 3 * depths[0], "the row recedes from the camera"
    assert dof.focus_distance == pytest.approx(depths[len(depths) // 2], rel=1e-3), "focused on the middle"
    # Circle of confusion on the sensor, thin lens: aperture * f / (s - f) * |d - s| / d, in pixels.
    f = camera.data.lens / 1000
    aperture = f / dof.aperture_fstop
    pixel = camera.data.sensor_width / 1000 / scene.render.resolution_x
    blur = [aperture * f / (dof.focus_distance - f) * abs(d - dof.focus_distance) / d / pixel for d in depths]
    assert blur[0] > 4 and blur[-1] > 2, f"near and far objects visibly blurred, CoC {blur} px"


def test_motion_blur(sample_scene):
    scene = load(sample_scene("motion_blur"))
    assert scene.render.use_motion_blur and scene.render.motion_blur_shutter > 0
    assert light_kinds(scene) == [("POINT", None), ("SPOT", None)]
    assert all(o.data.shadow_soft_size > 0 for o in scene.objects if o.type == "LIGHT")

    half = scene.render.motion_blur_shutter / 2
    slider, spinner = scene.objects["Slider"], scene.objects["Spinner"]
    start = motion_at(scene, slider, 1 - half), motion_at(scene, spinner, 1 - half)
    end = motion_at(scene, slider, 1 + half), motion_at(scene, spinner, 1 + half)
    scene.frame_set(1)
    travel = Vector(end[0][3::4][:3]) - Vector(start[0][3::4][:3])
    assert travel.length > 0.2 and abs(travel.z) < 1e-6, "the slider moves across the shutter interval"
    a, b = (Vector(m[1][0:12:4]) for m in (start, end))  # the spinner's local X axis
    assert a.angle(b) > math.radians(20) and a.y == pytest.approx(b.y, abs=1e-6), "the spinner turns about Y"
