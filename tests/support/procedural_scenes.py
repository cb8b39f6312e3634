"""Procedural texture cases and the scenes that show them, for the Cycles parity test and
bench/texture_parity.py (which writes the measured figures into docs/shader-node-parity.md's table).

Every case is one emissive 2 x 2 m tile of a grid seen straight down by an orthographic
camera, each tile exactly ``TILE`` pixels wide: the texture node, fed by the tile's Object
coordinates turned by a Mapping (so x, y and z all vary over the tile), drives the
emission colour through Vector Math Absolute (Cycles' emission of a negative value is not
what is being compared). White Noise hashes coordinates snapped to a 0.25 grid, so each
cell's value must be Cycles' bit for bit. The figure per case: the worst 4x4-block
difference from Cycles (seed 0), and Cycles' own worst between its seeds 0 and 1.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import bpy
import mathutils
import numpy as np

from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world
from tests.support.export_helpers import empty_scene

TILE = 32
BLOCK = 4
MARGIN = 2
SAMPLES = 64


@dataclass(frozen=True)
class Case:
    name: str
    node: str
    output: str
    props: dict = field(default_factory=dict)
    inputs: dict = field(default_factory=dict)
    w_from_x: bool = False  # 1D textures: W varies as the tile's x
    snap: bool = False  # coordinates snapped to a 0.25 grid (White Noise)
    musgrave: tuple = ()  # (detail, dimension) of a Musgrave texture, linked as Blender 4.1 converts it


def _noise(name, dims, kind, output="Fac", normalize=True, **inputs):
    base = {"Scale": 2.5, "Detail": 2.5, "Roughness": 0.6, "Lacunarity": 2.1, "W": 0.7}
    return Case(name, "ShaderNodeTexNoise", output, {"noise_dimensions": dims, "noise_type": kind,
                                                     "normalize": normalize}, {**base, **inputs}, dims == "1D")


def _voronoi(name, dims, feature, metric="EUCLIDEAN", output="Distance", normalize=False, **inputs):
    base = {"Scale": 3.0, "W": 0.4, "Randomness": 0.9}
    return Case(name, "ShaderNodeTexVoronoi", output, {"voronoi_dimensions": dims, "feature": feature,
                                                       "distance": metric, "normalize": normalize},
                {**base, **inputs}, dims == "1D")


def _wave(name, kind, direction, profile, **inputs):
    props = {"wave_type": kind, "wave_profile": profile,
             "bands_direction" if kind == "BANDS" else "rings_direction": direction}
    return Case(name, "ShaderNodeTexWave", "Fac", props, {"Scale": 0.6, **inputs})


CASES = (
    _noise("Noise fBM 1D", "1D", "FBM", Distortion=0.4),
    _noise("Noise fBM 2D", "2D", "FBM", Distortion=0.5),
    _noise("Noise fBM 3D colour", "3D", "FBM", "Color", Distortion=0.5),
    _noise("Noise fBM 4D", "4D", "FBM"),
    _noise("Noise fBM 3D not normalized", "3D", "FBM", normalize=False),
    _noise("Noise multifractal 3D", "3D", "MULTIFRACTAL"),
    _noise("Noise hetero terrain 3D", "3D", "HETERO_TERRAIN", Offset=0.5),
    _noise("Noise hybrid multifractal 3D", "3D", "HYBRID_MULTIFRACTAL", Offset=0.5, Gain=1.2),
    _noise("Noise ridged multifractal 3D", "3D", "RIDGED_MULTIFRACTAL", Offset=1.0, Gain=2.0),
    _noise("Noise ridged multifractal 4D", "4D", "RIDGED_MULTIFRACTAL", Offset=1.0, Gain=2.0, Distortion=0.3),
    _noise("Noise hybrid multifractal 1D", "1D", "HYBRID_MULTIFRACTAL", Offset=0.3, Gain=1.5),
    _voronoi("Voronoi F1 1D", "1D", "F1"),
    _voronoi("Voronoi F1 2D Manhattan colour", "2D", "F1", "MANHATTAN", "Color"),
    _voronoi("Voronoi F1 3D Euclidean", "3D", "F1"),
    _voronoi("Voronoi F1 3D Chebychev", "3D", "F1", "CHEBYCHEV"),
    _voronoi("Voronoi F1 3D Minkowski", "3D", "F1", "MINKOWSKI", Exponent=1.5),
    _voronoi("Voronoi F1 4D colour", "4D", "F1", output="Color"),
    _voronoi("Voronoi F1 3D fractal normalized", "3D", "F1", normalize=True, Detail=2.5, Roughness=0.6),
    _voronoi("Voronoi F2 3D", "3D", "F2"),
    _voronoi("Voronoi smooth F1 3D colour", "3D", "SMOOTH_F1", output="Color", Smoothness=0.7),
    _voronoi("Voronoi smooth F1 2D", "2D", "SMOOTH_F1", Smoothness=0.5),
    _voronoi("Voronoi distance to edge 2D fractal", "2D", "DISTANCE_TO_EDGE", Detail=1.5),
    _voronoi("Voronoi distance to edge 3D", "3D", "DISTANCE_TO_EDGE"),
    _voronoi("Voronoi n-sphere radius 3D", "3D", "N_SPHERE_RADIUS", output="Radius"),
    _voronoi("Voronoi F1 4D W", "4D", "F1", output="W"),
    _voronoi("Voronoi F2 2D position, normalized", "2D", "F2", output="Position", normalize=True, Detail=1.0),
    _voronoi("Voronoi distance to edge 4D", "4D", "DISTANCE_TO_EDGE"),
    _voronoi("Voronoi n-sphere radius 4D", "4D", "N_SPHERE_RADIUS", output="Radius"),
    _wave("Wave bands X sine", "BANDS", "X", "SIN"),
    _wave("Wave bands Y saw", "BANDS", "Y", "SAW"),
    _wave("Wave bands Z triangle", "BANDS", "Z", "TRI", Distortion=2.0, Detail=2.0),
    _wave("Wave bands diagonal saw, distorted", "BANDS", "DIAGONAL", "SAW", Distortion=3.0, Detail=2.5),
    _wave("Wave rings spherical triangle", "RINGS", "SPHERICAL", "TRI"),
    _wave("Wave rings X sine", "RINGS", "X", "SIN", **{"Phase Offset": 1.0}),
    _wave("Wave rings Y saw", "RINGS", "Y", "SAW"),
    _wave("Wave rings Z sine, distorted", "RINGS", "Z", "SIN", Distortion=2.0, **{"Detail Scale": 2.0}),
    *(Case(f"Gradient {kind.lower().replace('_', ' ')}", "ShaderNodeTexGradient", "Fac", {"gradient_type": kind})
      for kind in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE", "RADIAL")),
    Case("Magic depth 2", "ShaderNodeTexMagic", "Color", {"turbulence_depth": 2}, {"Scale": 1.0}),
    Case("Magic depth 6", "ShaderNodeTexMagic", "Color", {"turbulence_depth": 6},
         {"Scale": 0.8, "Distortion": 1.7}),
    *(Case(f"White Noise {d}", "ShaderNodeTexWhiteNoise", "Color" if d != "2D" else "Value",
           {"noise_dimensions": d}, {"W": 0.25}, d == "1D", True) for d in ("1D", "2D", "3D", "4D")),
    replace(_noise("Musgrave fBM 3D (converted)", "3D", "FBM", normalize=False), musgrave=(3.5, 1.2)),
    replace(_noise("Musgrave multifractal 3D (converted)", "3D", "MULTIFRACTAL", normalize=False),
            musgrave=(2.5, 0.8)),
    Case("Brick", "ShaderNodeTexBrick", "Color", {}, {"Scale": 0.6, "Mortar Size": 0.05}),
    Case("Brick offset and squash, smooth mortar", "ShaderNodeTexBrick", "Fac",
         {"offset": 0.3, "offset_frequency": 3, "squash": 0.6, "squash_frequency": 2},
         {"Scale": 0.8, "Mortar Size": 0.05, "Mortar Smooth": 0.6, "Bias": 0.2}),
) + ((  # Blender 4.3+
    Case("Gabor 2D", "ShaderNodeTexGabor", "Value", {"gabor_type": "2D"},
         {"Scale": 3.0, "Frequency": 2.0, "Anisotropy": 0.3, "Orientation 2D": 0.6}),
    Case("Gabor 2D anisotropic, intensity", "ShaderNodeTexGabor", "Intensity", {"gabor_type": "2D"},
         {"Scale": 2.5, "Frequency": 3.0, "Anisotropy": 1.0, "Orientation 2D": -0.4}),
    Case("Gabor 3D, phase", "ShaderNodeTexGabor", "Phase", {"gabor_type": "3D"},
         {"Scale": 2.0, "Frequency": 1.5, "Anisotropy": 0.5, "Orientation 3D": (0.3, 0.5, 0.8)}),
    Case("Gabor 3D isotropic", "ShaderNodeTexGabor", "Value", {"gabor_type": "3D"},
         {"Scale": 2.5, "Frequency": 2.0, "Anisotropy": 0.0}),
) if hasattr(bpy.types, "ShaderNodeTexGabor") else ())


def _math(tree, operation, a, b, clamp=False):
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    node.use_clamp = clamp
    for socket, value in zip(node.inputs, (a, b)):
        if isinstance(value, float):
            socket.default_value = value
        else:
            tree.links.new(value, socket)
    return node.outputs[0]


def _musgrave_converted(tree, tex, sockets, kind, detail, dimension):
    """The nodes Blender (4.1 on, versioning_410.cc) puts around a Musgrave texture it turns into
    a Noise texture, when the Musgrave's Detail and Dimension were linked: Detail - 1 capped at
    14, Roughness = Lacunarity^-max(Dimension, -1e-5), the factor times clamp(Detail) (and, for
    multifractal, plus clamp(1 - Detail)). Returns the socket that replaces the Musgrave's output."""
    d = tree.nodes.new("ShaderNodeValue")
    d.outputs[0].default_value = detail
    r = tree.nodes.new("ShaderNodeValue")
    r.outputs[0].default_value = dimension
    tree.links.new(_math(tree, "MINIMUM", _math(tree, "SUBTRACT", d.outputs[0], 1.0), 14.0), sockets["Detail"])
    exponent = _math(tree, "MULTIPLY", _math(tree, "MAXIMUM", r.outputs[0], -1e-5), -1.0)
    tree.links.new(_math(tree, "POWER", float(sockets["Lacunarity"].default_value), exponent), sockets["Roughness"])
    clamp = tree.nodes.new("ShaderNodeClamp")
    tree.links.new(d.outputs[0], clamp.inputs["Value"])
    out = _math(tree, "MULTIPLY", tex.outputs["Fac"], clamp.outputs[0])
    if kind == "MULTIFRACTAL":
        out = _math(tree, "ADD", out, _math(tree, "SUBTRACT", 1.0, d.outputs[0], clamp=True))
    return out


def _material(case: Case):
    mat = new_material(case.name)
    tree = mat.node_tree
    tree.nodes.clear()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Location"].default_value = (0.31, -0.17, 0.43)
    mapping.inputs["Rotation"].default_value = (0.5, 0.35, 0.2)
    tree.links.new(coords.outputs["Object"], mapping.inputs["Vector"])
    vector = mapping.outputs["Vector"]
    if case.snap:
        snap = tree.nodes.new("ShaderNodeVectorMath")
        snap.operation = "SNAP"
        snap.inputs[1].default_value = (0.25, 0.25, 0.25)
        tree.links.new(vector, snap.inputs[0])
        vector = snap.outputs["Vector"]
    tex = tree.nodes.new(case.node)
    for key, value in case.props.items():
        setattr(tex, key, value)
    sockets = {s.identifier: s for s in tex.inputs}  # by identifier: hidden sockets too
    for key, value in case.inputs.items():
        sockets[key].default_value = value
    if case.w_from_x:
        split = tree.nodes.new("ShaderNodeSeparateXYZ")
        tree.links.new(vector, split.inputs[0])
        tree.links.new(split.outputs["X"], sockets["W"])
    else:
        tree.links.new(vector, sockets["Vector"])
    result = tex.outputs[case.output]
    if case.musgrave:
        result = _musgrave_converted(tree, tex, sockets, case.props["noise_type"], *case.musgrave)
    absolute = tree.nodes.new("ShaderNodeVectorMath")
    absolute.operation = "ABSOLUTE"
    tree.links.new(result, absolute.inputs[0])
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(absolute.outputs["Vector"], emission.inputs["Color"])
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    return mat


def _scene(width: int, height: int):
    """An empty scene whose Cycles renders with the classic (Tabulated Sobol) pattern, as a new
    scene in Blender 5.0 does: 4.x's default (Automatic) dithers its samples as blue noise, which
    changes Cycles' own seed-to-seed block figure, the yardstick of ``parity``."""
    scene = empty_scene(width, height)
    scene.cycles.sampling_pattern = "TABULATED_SOBOL"
    return scene


def black_world(scene) -> None:
    """A world that gives no light (the Background's strength 0)."""
    world = new_world("World")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world


def glowing_half_plane(make_material):
    """A 64 x 32 scene under a black world and in it the half-plane x < 0 (z = 0) of the material
    ``make_material()`` makes (after the scene, which starts from Blender's factory state),
    returned with it: the edge the motion-blur comparisons slide."""
    scene = _scene(64, 32)
    black_world(scene)
    mesh = bpy.data.meshes.new("edge")
    mesh.from_pydata([(-50, -50, 0), (0, -50, 0), (0, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(make_material())
    edge = bpy.data.objects.new("edge", mesh)
    scene.collection.objects.link(edge)
    return scene, edge


def dark_scene(size: int, location, lens: float, transparent: bool):
    """A ``size`` x ``size`` scene of a black world (``_scene``), its camera at ``location`` looking
    at the origin through a ``lens`` mm lens, Film Transparent ``transparent``."""
    scene = _scene(size, size)
    aim(scene.camera, location)
    scene.camera.data.lens = lens
    scene.render.film_transparent = transparent
    black_world(scene)
    return scene


def aim(camera, location) -> None:
    """Place ``camera`` at ``location`` looking at the origin, y up."""
    camera.location = location
    camera.rotation_euler = (-mathutils.Vector(camera.location)).to_track_quat("-Z", "Y").to_euler()


def add_primitive(op, mat, name=None, **kw):
    """The mesh primitive the operator ``op`` (bpy.ops.mesh.primitive_*_add) makes from ``kw``,
    with material ``mat`` (and ``name``)."""
    op(**kw)
    obj = bpy.context.active_object
    if name is not None:
        obj.name = name
    obj.data.materials.append(mat)
    return obj


def sphere_pair_stage(width: int, height: int):
    """The closure tests' stage for two ``smooth_sphere``s at x = -1.1 and 1.1: the camera 7 units in
    front, a 50 mm lens, a black world; the caller adds the lights."""
    scene = _scene(width, height)
    aim(scene.camera, (0.0, -7.0, 1.5))
    scene.camera.data.lens = 50.0
    black_world(scene)
    return scene


def smooth_sphere(name, x, material) -> None:
    """A smooth-shaded unit UV sphere at (x, 0, 0) with ``material``."""
    add_primitive(bpy.ops.mesh.primitive_uv_sphere_add, material, name, radius=1.0, location=(x, 0.0, 0.0),
                  segments=64, ring_count=32)
    bpy.ops.object.shade_smooth()


def add_light(scene, name, kind, energy, location, size=0.0, color=(1.0, 1.0, 1.0), radius=0.0):
    """A light of ``kind`` and ``color`` aimed at the origin from ``location``: an area light ``size``
    across, any other of ``radius`` (0: a point source); the light's object."""
    light = bpy.data.objects.new(name, bpy.data.lights.new(name, kind))
    light.data.energy = energy
    light.data.color = color
    if kind == "AREA":
        light.data.size = size
    else:
        light.data.shadow_soft_size = radius
    aim(light, location)
    scene.collection.objects.link(light)
    return light


def assert_parity(scene, samples, out, name):
    """DRT's render of ``scene`` within ``parity``'s limit of Cycles' (asserted); Cycles' seeds 0
    and 1 (render_helpers.Render), for the comparisons of the feature left out."""
    drt, cycles0, cycles1 = [rh.render(scene, engine, samples, seed, out, name=name) for engine, seed in RUNS]
    figures = parity(drt.rgb, cycles0.rgb, cycles1.rgb)
    print(name, figures)
    assert figures["ok"], message(name, figures)
    return cycles0, cycles1


def closure_material(name, bl_idname, **inputs):
    """A material of one closure node ``bl_idname`` with these input values (underscores for
    spaces), and the node."""
    material = new_material(name)
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new(bl_idname)
    for socket, value in inputs.items():
        node.inputs[socket.replace("_", " ")].default_value = value
    tree.links.new(node.outputs["BSDF"], tree.nodes["Material Output"].inputs["Surface"])
    return material, node


def grid_shape(n: int) -> tuple[int, int]:
    cols = int(np.ceil(np.sqrt(n)))
    return cols, int(np.ceil(n / cols))


def grid_scene(cases=CASES, material=None):
    """The cases as a grid of emissive tiles (row-major from the top left) under a black world;
    ``material(case)`` makes each tile's material (this module's texture cases by default), and
    a case with a ``mesh`` ((vertices, faces) within the tile's 2 x 2 m) has it instead of one quad,
    and a case's ``setup(mesh)`` adds to its tile's mesh what it needs (attributes)."""
    material = material or _material
    cols, rows = grid_shape(len(cases))
    scene = _scene(cols * TILE, rows * TILE)
    cam = scene.camera
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0 * max(cols, rows)
    black_world(scene)
    for i, case in enumerate(cases):
        row, col = divmod(i, cols)
        mesh = bpy.data.meshes.new(case.name)
        shape = getattr(case, "mesh", None) or ([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)])
        mesh.from_pydata(shape[0], [], shape[1])
        if getattr(case, "setup", None) is not None:
            case.setup(mesh)
        mesh.materials.append(material(case))
        obj = bpy.data.objects.new(case.name, mesh)
        obj.location = (2.0 * col - cols + 1.0, rows - 1.0 - 2.0 * row, 0.0)
        scene.collection.objects.link(obj)
    return scene


def tiles(image: np.ndarray, n: int) -> list[np.ndarray]:
    """Each case's tile without its outer ``MARGIN`` pixels, where the pixel filter (1.5 pixels
    in reach) mixes in the neighbouring tiles."""
    cols, _ = grid_shape(n)
    return [image[(i // cols) * TILE + MARGIN:(i // cols + 1) * TILE - MARGIN,
                  (i % cols) * TILE + MARGIN:(i % cols + 1) * TILE - MARGIN] for i in range(n)]


def worst_block(a: np.ndarray, b: np.ndarray) -> float:
    """The largest |difference| of 4x4-pixel block means, over blocks and channels."""
    h, w, c = a.shape
    d = (a - b).reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, c).mean(axis=(1, 3))
    return float(np.abs(d).max())


def parity(drt: np.ndarray, cycles0: np.ndarray, cycles1: np.ndarray) -> dict:
    """The figures of one comparison and whether it passes (DRT's worst block within 1.5x
    Cycles' own seed-to-seed worst plus 0.002)."""
    worst = worst_block(drt, cycles0)
    own = worst_block(cycles0, cycles1)
    return {"worst": worst, "cycles_seeds": own, "limit": 1.5 * own + 0.002, "ok": worst <= 1.5 * own + 0.002}


RUNS = (("DRT", 0), ("CYCLES", 0), ("CYCLES", 1))
"""The renders a parity figure compares: DRT seed 0 against Cycles seed 0, Cycles seeds 0 and 1."""


def parity_renders(scene, out, name):
    """DRT seed 0, Cycles seeds 0 and 1 of ``scene`` (render_helpers.Render each)."""
    return [rh.render(scene, engine, SAMPLES, seed, out, name=name) for engine, seed in RUNS]


def grid_tiles(scene, n: int, out, name) -> list:
    """The ``n`` case tiles of a grid scene's three ``parity_renders``: [DRT, Cycles 0, Cycles 1]."""
    return [tiles(r.rgb, n) for r in parity_renders(scene, out, name)]


def tile_figures(grid, index) -> dict:
    """``parity`` of case ``index`` from the tiles of the three ``parity_renders``."""
    return parity(*(tiles[index] for tiles in grid))


def message(name: str, figures: dict) -> str:
    """A failed case's figures, for an assertion."""
    return (f"{name}: worst block {figures['worst']:.4f} > {figures['limit']:.4f} "
            f"(Cycles' seeds: {figures['cycles_seeds']:.4f})")


def _diffuse(name, color_from):
    """A Diffuse BSDF material whose colour ``color_from(tree)`` (an output socket) gives."""
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(color_from(tree), bsdf.inputs["Color"])
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def _ground_color(tree):
    """Voronoi cell colours darkened by a noise factor."""
    vor = tree.nodes.new("ShaderNodeTexVoronoi")
    vor.inputs["Scale"].default_value = 4.0
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 1.0
    tree.links.new(vor.outputs["Color"], mix.inputs["A"])
    tree.links.new(noise.outputs["Fac"], mix.inputs["B"])
    return mix.outputs["Result"]


def _sphere_color(tree):
    """Bricks whose first colour is a wave's."""
    brick = tree.nodes.new("ShaderNodeTexBrick")
    brick.inputs["Scale"].default_value = 3.0
    wave = tree.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 2.0
    tree.links.new(wave.outputs["Color"], brick.inputs["Color1"])
    return brick.outputs["Color"]


def lit_scene(width=48):
    """Textures under light: a ground of Voronoi colours times noise and a sphere of bricks
    and waves, both diffuse, lit by a sun and a point light (shadows on textured ground)."""
    scene = _scene(width, width)
    cam = scene.camera
    cam.location = (0.0, -6.0, 4.0)
    cam.rotation_euler = (0.98, 0.0, 0.0)
    black_world(scene)
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    bpy.context.active_object.data.materials.append(_diffuse("Ground", _ground_color))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(0.0, 0.0, 1.0), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(_diffuse("Sphere", _sphere_color))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(sun)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 300.0
    lamp.location = (2.5, -2.0, 3.0)
    scene.collection.objects.link(lamp)
    return scene


def box_scene(width=48, blend=0.3):
    """An emissive sphere, turned, seen from above at an angle, coloured by an 8x8 image of random
    colours (Closest) in Box projection of its Object coordinates: the three faces and the
    blended seams between them, which follow the object-space normal."""
    scene = _scene(width, width)
    aim(scene.camera, (2.6, -3.4, 2.4))
    black_world(scene)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=64, ring_count=32, rotation=(0.3, 0.2, 0.5))
    bpy.ops.object.shade_smooth()
    image = bpy.data.images.new("Texels", 8, 8, float_buffer=True)
    texels = np.random.default_rng(11).uniform(0.05, 1.0, (8, 8, 4)).astype(np.float32)
    texels[..., 3] = 1.0
    image.pixels.foreach_set(texels.ravel())
    image.pack()  # a generated image would be generated again (blank) for the render
    mat = new_material("Box")
    tree = mat.node_tree
    tree.nodes.clear()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Location"].default_value = (0.5, 0.5, 0.5)
    mapping.inputs["Scale"].default_value = (0.5, 0.5, 0.5)
    tree.links.new(coords.outputs["Object"], mapping.inputs["Vector"])
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Closest"
    tex.projection = "BOX"
    tex.projection_blend = blend
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(tex.outputs["Color"], emission.inputs["Color"])
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    bpy.context.active_object.data.materials.append(mat)
    return scene
