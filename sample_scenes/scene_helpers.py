"""Shared pieces of the sample-scene build scripts: one place for the render settings every
sample scene shares (small, Cycles ready for a like-for-like comparison) and for the few
node-free building blocks (meshes from bmesh, constant-input materials, lights aimed at a point).

Each build script is run as ``.venv/bin/python sample_scenes/build_NAME.py [OUT.blend]``.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import bpy  # first: it puts Blender's own modules (bmesh, mathutils) on sys.path
import bmesh
from mathutils import Vector

HERE = Path(__file__).resolve().parent
REPO = HERE.parent


def output_path(name: str) -> Path:
    """The .blend to write: the first script argument, else sample_scenes/NAME.blend.

    Script arguments follow the script under Python, or "--" under `blender -b --python SCRIPT -- OUT`.
    """
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    return Path(args[0]).resolve() if args else HERE / f"{name}.blend"


def new_scene(resolution=(128, 128)) -> bpy.types.Scene:
    """An empty file with one scene whose DRT and Cycles settings are comparable."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    render = scene.render
    render.resolution_x, render.resolution_y = resolution
    render.resolution_percentage = 100
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0
    render.filter_size = 1.5  # Blackman-Harris width, read by DRT and matched by Cycles below
    render.film_transparent = False
    render.use_motion_blur = False
    scene.frame_start = scene.frame_end = scene.frame_current = 1

    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = 256
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = 0
    cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    cycles.filter_width = 1.5
    # Distribution ray tracing: no indirect diffuse light, specular chains up to DRT's max depth (8).
    cycles.max_bounces = 8
    cycles.diffuse_bounces = 0
    cycles.glossy_bounces = 8
    cycles.transmission_bounces = 8
    cycles.transparent_max_bounces = 8
    cycles.volume_bounces = 0
    cycles.blur_glossy = 0.0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0

    render.engine = drt_engine_or_cycles()
    return scene


def drt_engine_or_cycles() -> str:
    """'DRT' when the repo's engine registers here, else 'CYCLES' (the CLI selects DRT anyway)."""
    if str(REPO) not in sys.path:
        sys.path.insert(0, str(REPO))
    try:
        import drt_engine
    except ImportError as error:
        print(f"DRT not importable ({error}); saving with Cycles selected", file=sys.stderr)
        return "CYCLES"
    if not hasattr(drt_engine, "register"):
        print("drt_engine has no register(); saving with Cycles selected", file=sys.stderr)
        return "CYCLES"
    if "DRT" not in {getattr(engine, "bl_idname", None) for engine in bpy.types.RenderEngine.__subclasses__()}:
        drt_engine.register()
    return "DRT"


def set_world(scene, color, strength: float) -> None:
    """A uniform world: Background node with an explicit color and strength."""
    world = bpy.data.worlds.new("World")
    if world.node_tree is None:  # Blender 4.x; 5.0 always has nodes and deprecates use_nodes
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    scene.world = world


def _material(name: str, node_type: str, inputs: dict) -> bpy.types.Material:
    """A material whose output is one shader node with constant inputs."""
    material = bpy.data.materials.new(name)
    if material.node_tree is None:  # Blender 4.x; 5.0 always has nodes and deprecates use_nodes
        material.use_nodes = True
    nodes = material.node_tree.nodes
    for node in list(nodes):
        if node.type != "OUTPUT_MATERIAL":
            nodes.remove(node)
    shader = nodes.new(node_type)
    for socket, value in inputs.items():
        if isinstance(value, tuple) and len(value) == 3:
            value = (*value, 1.0)
        shader.inputs[socket].default_value = value
    material.node_tree.links.new(shader.outputs[0], nodes["Material Output"].inputs["Surface"])
    if "Base Color" in inputs or "Color" in inputs:
        color = inputs.get("Base Color", inputs.get("Color"))
        material.diffuse_color = (*color[:3], 1.0)  # viewport color only
    return material


def diffuse(name, color):
    return _material(name, "ShaderNodeBsdfDiffuse", {"Color": color, "Roughness": 0.0})


PRINCIPLED_DEFAULTS = {"Subsurface_Scale": 0.05}
"""Inputs whose default differs between Blender versions (5.2 made Subsurface Scale 0.005), set to
the value of the committed files (saved by 5.0) so that every version builds the same scene."""


def principled(name, **inputs):
    """Principled BSDF; keyword names are socket names with spaces as underscores."""
    inputs = {**PRINCIPLED_DEFAULTS, **inputs}
    return _material(name, "ShaderNodeBsdfPrincipled", {k.replace("_", " "): v for k, v in inputs.items()})


def glossy(name, color, roughness):
    node_inputs = {"Color": color, "Roughness": roughness}
    material = _material(name, "ShaderNodeBsdfGlossy", node_inputs)
    material.node_tree.nodes["Glossy BSDF"].distribution = "GGX"
    return material


def glass(name, color, roughness, ior):
    material = _material(name, "ShaderNodeBsdfGlass", {"Color": color, "Roughness": roughness, "IOR": ior})
    material.node_tree.nodes["Glass BSDF"].distribution = "GGX"
    return material


def emission(name, color, strength):
    return _material(name, "ShaderNodeEmission", {"Color": color, "Strength": strength})


def link(scene, name, data, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1)):
    """A new object in the scene's master collection; rotation is XYZ Euler in degrees."""
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.rotation_euler = tuple(math.radians(angle) for angle in rotation)
    obj.scale = scale
    scene.collection.objects.link(obj)
    return obj


def mesh_from_bmesh(name, bm, materials, smooth=False):
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    for material in materials:
        mesh.materials.append(material)
    if smooth:
        mesh.shade_smooth()
    return mesh


def box_mesh(name, size, material):
    """An axis-aligned box of the given (x, y, z) size centred on the origin."""
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    bmesh.ops.scale(bm, vec=Vector(size), verts=bm.verts)
    return mesh_from_bmesh(name, bm, [material])


def sphere_mesh(name, radius, material, segments=48, rings=24):
    """A smooth UV sphere; 48 x 24 gives 2208 triangles. Its faces are put in one order: bmesh's
    create_uvsphere lists them in an order that changes from run to run (measured in Blender 4.2
    and 5.0), and a renderer's samples follow the order of an emitter's triangles, so each build
    rendered a little differently."""
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bm.verts.index_update()
    bm.faces.index_update()
    order = sorted(bm.faces, key=lambda face: sorted(v.index for v in face.verts))
    rank = {face.index: i for i, face in enumerate(order)}
    bm.faces.sort(key=lambda face: rank[face.index])
    bm.faces.index_update()
    return mesh_from_bmesh(name, bm, [material], smooth=True)


def plane_mesh(name, size_x, size_y, material):
    """A plane in XY facing +Z, centred on the origin."""
    mesh = bpy.data.meshes.new(name)
    hx, hy = size_x / 2, size_y / 2
    mesh.from_pydata([(-hx, -hy, 0), (hx, -hy, 0), (hx, hy, 0), (-hx, hy, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    return mesh


def aim(obj, target) -> None:
    """Point the object's -Z axis (cameras, spot, sun and area lights) at target, +Y up."""
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def add_light(scene, name, kind, location, target=None, color=(1, 1, 1), **props):
    light = bpy.data.lights.new(name, kind)
    light.color = color
    for key, value in props.items():
        setattr(light, key, value)
    obj = link(scene, name, light, location)
    if target is not None:
        aim(obj, target)
    return obj


def add_camera(scene, location, target, lens=50.0):
    camera = bpy.data.cameras.new("Camera")
    camera.lens = lens
    camera.sensor_fit = "AUTO"
    camera.sensor_width = 36.0
    obj = link(scene, "Camera", camera, location)
    aim(obj, target)
    scene.camera = obj
    return obj


def fcurves(obj):
    """The object's animation curves: in its action's slot channelbag (Blender 4.4+) or the action."""
    try:
        from bpy_extras.anim_utils import animdata_get_channelbag_for_assigned_slot
    except ImportError:  # Blender before 4.4: actions hold their F-curves directly
        return obj.animation_data.action.fcurves
    return animdata_get_channelbag_for_assigned_slot(obj.animation_data).fcurves


def linear_keys(obj) -> None:
    """Make every key of the object's animation linear (new keys are Bezier, easing in and out)."""
    for curve in fcurves(obj):
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"


def save(path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=True)
    print(f"wrote {path}")


def done() -> None:
    """End a build script run by the bpy 4.2 module now, with status 0.

    That module crashes (SIGSEGV) while Python tears it down once a property with an update
    callback was registered, as DRT's are, which would fail `make scenes` after the files are
    written. Inside Blender itself (``blender --python``) and under other versions it does nothing.
    """
    if bpy.app.version[:2] == (4, 2) and not bpy.app.binary_path:
        from drt_engine.headless.cli import exit_now

        exit_now(0)
