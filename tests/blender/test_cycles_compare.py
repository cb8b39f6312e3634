"""DRT against Cycles, both rendered in this bpy session through ``bpy.ops.render.render``.

Cycles is set up as a distribution ray tracer (render_helpers.configure_cycles: diffuse
bounces 0, glossy and transmission bounces = DRT's max depth, no glossy blur, no clamping,
no denoising, DRT's pixel filter), so a converged DRT image must equal a converged Cycles one.

Each scene is rendered small, twice by each renderer with different seeds. The two renders
of one renderer differ only by noise, which measures that renderer's noise in the very
statistics the test asserts on; the averages are then compared:

- relative difference of the image means (all channels together);
- MARD, the mean absolute relative difference per pixel and channel, and the same over
  4x4-pixel blocks ("block MARD"), which averages the noise down 4x while a localised bias
  (a wrong highlight, shadow or light shape) stays; both over the pixels (blocks) whose
  reference value is above 5% of the reference image mean, so black pixels do not divide.

If the images differed by noise only, the expected MARD of the averages would be
``noise = ½·hypot(MARD(DRT seed 0, seed 1), MARD(Cycles seed 0, seed 1))`` (the difference
of two renders has twice the variance of one, the average of two renders half of it). The
tolerance is that noise, with 50% margin for its own scatter, plus a bias budget of 1% (half
the issue's goal of 2% on diffuse and metal scenes); the image means must agree within the
bias budget alone, their noise being below 0.3%. The samples per case are chosen so that the
block noise is about 0.3% (measured 0.1% to 0.3%); a renderer too noisy for the budget to mean
anything fails the resolving-power checks instead (block noise at most 0.5%).

Measured at 64 px on 2 shared cores (Nov 2026), block MARD minus its noise: 0.0-0.1% on the
Cornell box, glossy spheres, depth-of-field row and Ignis lights; 0.47% on the motion-blur
scene (the spot light's cone edge, see test_spot_light_blend_region) and 0.29% on Ignis sun
(its smooth-shaded 32-sided cone near the terminator; 0.38% before DRT, like Cycles, judged
light samples by the shading normal and lifted diffuse shadow rays toward the smooth surface).
On the Ignis roughness sphere (highlight left out, see highlight()) 0.17%, on the rough glass of
Ignis flipped-prim 0.79% (image means -0.47%, the same at 64 and 128 spp); since the world is
sampled around the shading normal (Dec 2026) its image means agree (+0.02%) but DRT's rough glass
is noisier there (block noise 0.89% at 128 spp against 0.49% before), so it renders 512 spp. Ignis box, once a known
difference (DRT's Principled dielectric with GGX was Multiscatter GGX's, +1.4% on the image mean),
now agrees: +0.27% on the image mean, block MARD 0.18% against noise 0.06% (measured Dec 2026).

The main cases switch depth of field and motion blur off in both renderers, so each effect is
tested on its own: two extra cases render them on as the scenes are saved, the thin lens
(dof_row_lens: block MARD 0.24% against noise 0.24%) and the shutter (motion_blur_shutter: 0.23%
against 0.15%, measured Dec 2026); both pass. The Ignis scenes' ground is checker-textured (and
the roughness sphere's Base Color comes from an image through a Mix node): the main comparison
unlinks those textures in both renderers (both then use the BSDF's own colour), and the textured
originals are compared too (ignis_roughness_textured below, and test_textured_scene_matches_cycles
on the image means of Ignis lights and sun); all pass. Moving lights and a moving camera are
compared in test_moving_lights.py.

Each comparison saves ``out/compare/<case>.png`` (DRT | Cycles | |difference| x 10).

The focused scenes at the end (one light or one material, built in code) pin down single
behaviours where the sample scenes are not sensitive enough: lights invisible to camera rays,
the spot cone's edge with a light radius, and the GGX versus Multiscatter GGX distributions.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import bpy
import numpy as np
import pytest

from tests.support import render_helpers as rh
from tests.support.datablocks import new_material, new_world

SAMPLE_SCENES = rh.ROOT / "sample_scenes"
DATA = rh.ROOT / "tests" / "data"
LONG_SIDE = 64  # pixels on the long side of every comparison render
BLOCK = 4
FLOOR = 0.05  # pixels below this fraction of the reference mean are left out of relative errors
BIAS_BUDGET = 0.01
NOISE_MARGIN = 1.5
MAX_BLOCK_NOISE = 0.005
MAX_MEAN_NOISE = 0.003


# -- scene preparation (in memory only) ----------------------------------------------------
def no_depth_of_field(scene):
    scene.camera.data.dof.use_dof = False


def no_motion_blur(scene):
    scene.render.use_motion_blur = False


def untextured_ground(scene):
    """Unlink the Checker Texture from the ground's Diffuse BSDF (both renderers use Color)."""
    tree = bpy.data.materials["Ground"].node_tree
    links = [link for link in tree.links if link.from_node.type == "TEX_CHECKER"]
    assert links, "the Ignis ground material is expected to hold a Checker Texture"
    for link in links:
        tree.links.remove(link)


def untextured_sphere(scene):
    """Unlink the Image Texture's Mix (Lighten) from the roughness sphere's Base Color (both
    renderers then use the Principled BSDF's own Base Color)."""
    tree = bpy.data.materials["Material"].node_tree
    links = [link for link in tree.links if link.to_socket.name == "Base Color" and link.from_node.type == "MIX"]
    assert links, "the Ignis roughness sphere is expected to take its Base Color from a Mix node"
    for link in links:
        tree.links.remove(link)


def local_texture(scene):
    """Point the roughness sphere's image at tests/data (the .blend's relative path leads out of it)."""
    image = bpy.data.images["grid_weight.png"]
    image.filepath = str(DATA / "grid_weight.png")
    image.reload()


@dataclass(frozen=True)
class Case:
    name: str
    path: Path
    drt_samples: int
    cycles_samples: int
    prepare: tuple[Callable, ...] = ()
    mask_highlight: bool = False  # leave a point light's sub-pixel highlight out (see highlight())


# Samples per seed, chosen so that each case's block noise is about 0.3% (measured).
CASES = (
    Case("cornell_box", SAMPLE_SCENES / "cornell_box.blend", 256, 256),
    Case("glossy_spheres", SAMPLE_SCENES / "glossy_spheres.blend", 192, 1024),
    Case("dof_row", SAMPLE_SCENES / "dof_row.blend", 64, 256, (no_depth_of_field,)),
    Case("motion_blur", SAMPLE_SCENES / "motion_blur.blend", 64, 256, (no_motion_blur,)),
    Case("ignis_lights", DATA / "lights.blend", 64, 1024, (untextured_ground,)),
    Case("ignis_sun", DATA / "sun.blend", 64, 256, (untextured_ground,)),
    Case("ignis_roughness", DATA / "roughness.blend", 64, 256, (untextured_ground, untextured_sphere),
         mask_highlight=True),
    Case("ignis_flipped_prim", DATA / "flipped-prim.blend", 512, 512),
    Case("ignis_roughness_textured", DATA / "roughness.blend", 128, 512, (local_texture,), mask_highlight=True),
    Case("ignis_box", DATA / "box.blend", 64, 256),
)

# The effects on, as the scenes are saved: the thin lens and the shutter (block MARD 0.27% and
# 0.23% against noise 0.25% and 0.15% when measured).
EFFECT_CASES = (
    pytest.param(Case("dof_row_lens", SAMPLE_SCENES / "dof_row.blend", 64, 256), id="dof_row_lens"),
    pytest.param(Case("motion_blur_shutter", SAMPLE_SCENES / "motion_blur.blend", 64, 256),
                 id="motion_blur_shutter"),
)


def load(case: Case, sample_scene) -> bpy.types.Scene:
    """The case's scene, prepared; a sample scene through the ``sample_scene`` fixture (Blender 4.x
    cannot open the committed file and renders the one its script builds)."""
    scene = rh.open_scene(sample_scene(case.path.stem) if case.path.parent == SAMPLE_SCENES else case.path)
    width, height = scene.render.resolution_x, scene.render.resolution_y
    scale = LONG_SIDE / max(width, height)
    rh.set_resolution(scene, round(width * scale / BLOCK) * BLOCK, round(height * scale / BLOCK) * BLOCK)
    for step in case.prepare:
        step(scene)
    return scene


# -- statistics -----------------------------------------------------------------------------
def blocks(image: np.ndarray) -> np.ndarray:
    h, w, c = image.shape
    return image.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, c).mean(axis=(1, 3))


def mard(a: np.ndarray, b: np.ndarray, reference: np.ndarray, floor: float) -> float:
    """Mean of |a - b| / reference over the values whose reference is above ``floor``."""
    keep = reference > floor
    return float((np.abs(a - b)[keep] / reference[keep]).mean())


@dataclass
class Comparison:
    scene: str
    drt_mean: float
    cycles_mean: float
    mean_diff: float  # relative difference of the image means, DRT / Cycles - 1
    mean_noise: float
    mard: float
    mard_noise: float
    block_mard: float
    block_noise: float
    drt_samples: int
    cycles_samples: int
    drt_seconds: float  # one render of drt_samples, wall time including export and EXR writing
    cycles_seconds: float

    def row(self) -> str:
        return (f"{self.scene:<20} {self.drt_mean:9.4f} {self.cycles_mean:9.4f} {self.mean_diff:+8.2%} "
                f"{self.mard:7.2%} ({self.mard_noise:5.2%}) {self.block_mard:7.2%} ({self.block_noise:5.2%}) "
                f"{self.drt_samples:7d} {self.drt_seconds:6.2f} {self.cycles_samples:7d} {self.cycles_seconds:6.2f}")


HEADER = (f"{'scene':<20} {'DRT mean':>9} {'Cyc mean':>9} {'mean d':>8} {'MARD (noise)':>15} "
          f"{'blockMARD (noise)':>17} {'DRT spp':>7} {'DRT s':>6} {'Cyc spp':>7} {'Cyc s':>6}")


def compare(name: str, drt: list, cycles: list) -> Comparison:
    d0, d1 = (r.rgb.astype(np.float64) for r in drt)
    c0, c1 = (r.rgb.astype(np.float64) for r in cycles)
    d, c = (d0 + d1) / 2, (c0 + c1) / 2
    floor = FLOOR * c.mean()
    bd0, bd1, bc0, bc1, bd, bc = (blocks(x) for x in (d0, d1, c0, c1, d, c))
    return Comparison(
        scene=name,
        drt_mean=float(d.mean()),
        cycles_mean=float(c.mean()),
        mean_diff=float(d.mean() / c.mean() - 1.0),
        mean_noise=0.5 * float(np.hypot(d0.mean() / d1.mean() - 1.0, c0.mean() / c1.mean() - 1.0)),
        mard=mard(d, c, c, floor),
        mard_noise=0.5 * float(np.hypot(mard(d0, d1, c, floor), mard(c0, c1, c, floor))),
        block_mard=mard(bd, bc, bc, floor),
        block_noise=0.5 * float(np.hypot(mard(bd0, bd1, bc, floor), mard(bc0, bc1, bc, floor))),
        drt_samples=drt[0].samples,
        cycles_samples=cycles[0].samples,
        drt_seconds=float(np.mean([r.seconds for r in drt])),
        cycles_seconds=float(np.mean([r.seconds for r in cycles])),
    )


def average(renders: list) -> np.ndarray:
    return np.mean([r.rgb.astype(np.float64) for r in renders], axis=0)


@pytest.fixture(scope="module")
def table():
    """Rows of the comparison table, printed at the end of the module (see them with -s)."""
    rows = []
    yield rows
    if rows:
        print("\nDRT vs Cycles (MARD over pixels/blocks above 5% of the mean; noise = expected from noise alone)")
        print(HEADER)
        for row in rows:
            print(row.row())


HIGHLIGHT = 10.0  # a pixel this many times the image's 90th percentile (Cycles) belongs to a highlight
HIGHLIGHT_MARGIN = 2  # pixels around it, beyond the pixel filter's reach


def highlight(cycles: list) -> np.ndarray:
    """Pixels of a delta light's highlight on a near-mirror, and a margin around them.

    The Ignis roughness sphere (GGX alpha 0.0036) shows its point light as a highlight of 5
    pixels at 64 px (7 to 240 times the brightest other pixel) that holds about half of the
    image's energy. Its estimates are heavy-tailed (rare samples near the peak of the
    distribution): measured 9x9-pixel window sums, two seeds,
    DRT 4357, 3985 at 256 spp and 6960, 6428 at 1024; Cycles 6143, 6552 at 1024 and 6667, 6532
    at 4096. Agreeing at 1024 and beyond, but no sample count in the time budget resolves 1%
    there, and it would swamp every statistic of the rest of the image.
    """
    image = np.mean([r.rgb.astype(np.float64).sum(axis=-1) for r in cycles], axis=0)
    m = HIGHLIGHT_MARGIN
    padded = np.pad(image > HIGHLIGHT * np.percentile(image, 90), m)
    h, w = image.shape
    return np.any([padded[dy:dy + h, dx:dx + w] for dy in range(2 * m + 1) for dx in range(2 * m + 1)], axis=0)


def without(renders: list, mask: np.ndarray) -> list:
    """The renders with the masked pixels black in every channel (left out of all statistics)."""
    return [rh.Render({"Combined": np.where(mask[..., None], 0.0, r.passes["Combined"])}, r.seconds, r.samples)
            for r in renders]


@pytest.mark.parametrize("case", CASES + EFFECT_CASES, ids=lambda case: case.name)
def test_matches_cycles(drt, tmp_path, table, case, sample_scene):
    scene = load(case, sample_scene)
    drt_renders = [rh.render(scene, "DRT", case.drt_samples, seed, tmp_path) for seed in (0, 1)]
    cycles_renders = [rh.render(scene, "CYCLES", case.cycles_samples, seed, tmp_path) for seed in (0, 1)]
    for render in drt_renders + cycles_renders:
        assert np.isfinite(render.passes["Combined"]).all()
    rh.save_side_by_side(case.name, average(drt_renders), average(cycles_renders))
    if case.mask_highlight:
        mask = highlight(cycles_renders)
        assert 0 < mask.sum() <= 0.02 * mask.size, f"{mask.sum()} highlight pixels"
        drt_renders, cycles_renders = without(drt_renders, mask), without(cycles_renders, mask)
    result = compare(case.name, drt_renders, cycles_renders)
    table.append(result)
    print("\n" + HEADER + "\n" + result.row())

    assert result.block_noise <= MAX_BLOCK_NOISE, "too noisy for the bias budget to mean anything"
    assert result.mean_noise <= MAX_MEAN_NOISE, "too noisy for the bias budget to mean anything"
    assert abs(result.mean_diff) <= BIAS_BUDGET, f"image means differ by {result.mean_diff:+.2%}"
    block_tolerance = BIAS_BUDGET + NOISE_MARGIN * result.block_noise
    assert result.block_mard <= block_tolerance, (
        f"block MARD {result.block_mard:.2%} > {block_tolerance:.2%} (noise alone: {result.block_noise:.2%})")
    pixel_tolerance = BIAS_BUDGET + NOISE_MARGIN * result.mard_noise
    assert result.mard <= pixel_tolerance, (
        f"MARD {result.mard:.2%} > {pixel_tolerance:.2%} (noise alone: {result.mard_noise:.2%})")


TEXTURED = (
    Case("ignis_lights", DATA / "lights.blend", 16, 64),
    Case("ignis_sun", DATA / "sun.blend", 16, 64),
)


@pytest.mark.parametrize("case", TEXTURED, ids=lambda case: case.name)
def test_textured_scene_matches_cycles(drt, tmp_path, case, sample_scene):
    scene = load(case, sample_scene)
    drt_mean = rh.render(scene, "DRT", case.drt_samples, 0, tmp_path).rgb.mean()
    cycles_mean = rh.render(scene, "CYCLES", case.cycles_samples, 0, tmp_path).rgb.mean()
    assert abs(drt_mean / cycles_mean - 1.0) <= BIAS_BUDGET


# -- focused scenes: one light, built in code --------------------------------------------------
def focused_scene(width: int, height: int, ortho_scale: float, camera_location, world: float):
    """Factory-empty scene with an orthographic camera looking down -Z and a grey world."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rh.set_resolution(scene, width, height)
    scene.world = new_world("World")
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (world, world, world, 1.0)
    background.inputs["Strength"].default_value = 1.0
    camera = bpy.data.cameras.new("Camera")
    camera.type = "ORTHO"
    camera.ortho_scale = ortho_scale
    camera_object = bpy.data.objects.new("Camera", camera)
    camera_object.location = camera_location
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object
    return scene


def add_light(scene, kind, location, **props):
    light = bpy.data.lights.new(kind, kind)
    for key, value in props.items():
        setattr(light, key, value)
    obj = bpy.data.objects.new(kind, light)
    obj.location = location  # unrotated: spot and area lights shine along -Z
    scene.collection.objects.link(obj)
    return obj


@pytest.mark.parametrize("kind, props", [
    ("AREA", {"shape": "SQUARE", "size": 1.0}),
    ("POINT", {"shadow_soft_size": 0.5}),
    ("SPOT", {"shadow_soft_size": 0.5}),
], ids=("area", "point", "spot"))
def test_lights_are_invisible_to_camera_rays(drt, tmp_path, kind, props):
    """Blender lights have ``visible_camera`` off: the camera sees the world through them."""
    world = 0.5
    scene = focused_scene(16, 16, 2.0, (0.0, 0.0, 3.0), world)
    light = add_light(scene, kind, (0.0, 0.0, 0.0), energy=100.0, **props)
    light.rotation_euler = (3.14159265, 0.0, 0.0)  # shining up, into the camera
    assert not light.visible_camera
    for engine, samples in (("CYCLES", 16), ("DRT", 16)):
        image = rh.render(scene, engine, samples, 0, tmp_path).rgb
        low, high = float(image.min()), float(image.max())
        assert abs(low - world) < 1e-3 and abs(high - world) < 1e-3, (
            f"{engine} should see the world ({world}) through the {kind} light; pixels from {low:.3f} to {high:.3f}")


@pytest.mark.parametrize("radius", (0.0, 0.1))
def test_spot_light_blend_region(drt, tmp_path, radius):
    """A Lambertian floor across the edge of a spot light's cone (size 50 degrees, blend 0.2).

    Cycles evaluates the cone's smoothstep along each sampled direction to the light's sphere
    (spot_light_attenuation(-ls->D) in kernel/light/spot.h), so a radius softens the edge.
    """
    height = 2.0
    edge = height * np.tan(np.radians(25.0))
    scene = focused_scene(32, 32, 0.6, (edge, 0.0, 1.0), 0.0)
    floor = new_material("Floor")
    floor.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    floor.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = 0.0
    mesh = bpy.data.meshes.new("Floor")
    mesh.from_pydata([(-5, -5, 0), (5, -5, 0), (5, 5, 0), (-5, 5, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(floor)
    scene.collection.objects.link(bpy.data.objects.new("Floor", mesh))
    add_light(scene, "SPOT", (0.0, 0.0, height), energy=500.0, shadow_soft_size=radius,
              spot_size=np.radians(50.0), spot_blend=0.2)
    drt_renders = [rh.render(scene, "DRT", 64, seed, tmp_path) for seed in (0, 1)]
    cycles_renders = [rh.render(scene, "CYCLES", 256, seed, tmp_path) for seed in (0, 1)]
    result = compare(f"spot r={radius}", drt_renders, cycles_renders)
    print("\n" + HEADER + "\n" + result.row())
    assert result.block_noise <= MAX_BLOCK_NOISE
    tolerance = BIAS_BUDGET + NOISE_MARGIN * result.block_noise
    assert result.block_mard <= tolerance, (
        f"block MARD {result.block_mard:.2%} > {tolerance:.2%} (noise alone: {result.block_noise:.2%})")


@pytest.mark.parametrize("node, distribution", [
    ("ShaderNodeBsdfGlossy", "GGX"),
    ("ShaderNodeBsdfGlossy", "MULTI_GGX"),
    ("ShaderNodeBsdfPrincipled", "GGX"),
    ("ShaderNodeBsdfPrincipled", "MULTI_GGX"),
], ids=("glossy-ggx", "glossy-multi", "principled-ggx", "principled-multi"))
def test_rough_metal_distribution(drt, tmp_path, node, distribution):
    """A rough (0.7) metal plane reflecting a large area light overhead, seen from above.

    Cycles adds multiple-scattering energy only for Multiscatter GGX; plain GGX loses the
    energy of the inter-reflections between microfacets (measured in Cycles: 27% of the
    Multiscatter image here).
    """
    scene = focused_scene(16, 16, 0.5, (0.0, 0.0, 1.0), 0.0)
    metal = new_material("Metal")
    tree = metal.node_tree
    tree.nodes.clear()
    shader = tree.nodes.new(node)
    shader.distribution = distribution
    shader.inputs["Roughness"].default_value = 0.7
    if node == "ShaderNodeBsdfPrincipled":
        shader.inputs["Metallic"].default_value = 1.0
        shader.inputs["Base Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    else:
        shader.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    tree.links.new(shader.outputs[0], tree.nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-5, -5, 0), (5, -5, 0), (5, 5, 0), (-5, 5, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(metal)
    scene.collection.objects.link(bpy.data.objects.new("Plane", mesh))
    add_light(scene, "AREA", (0.0, 0.0, 2.0), energy=1000.0, shape="SQUARE", size=4.0)
    drt_renders = [rh.render(scene, "DRT", 64, seed, tmp_path) for seed in (0, 1)]
    cycles_renders = [rh.render(scene, "CYCLES", 256, seed, tmp_path) for seed in (0, 1)]
    result = compare(f"{node[14:]} {distribution}", drt_renders, cycles_renders)
    print("\n" + HEADER + "\n" + result.row())
    assert result.mean_noise <= MAX_MEAN_NOISE
    assert abs(result.mean_diff) <= BIAS_BUDGET, f"image means differ by {result.mean_diff:+.2%}"


# -- image-based lighting ------------------------------------------------------------------------
def hdri(path: Path) -> str:
    """An equirectangular sky written in code: a horizon-to-zenith gradient, a warm ground and a
    sun-like spot (3 x 3 texels, 200 times the sky) up and to one side."""
    import OpenImageIO as oiio

    w, h = 64, 32
    v = (np.arange(h)[::-1] + 0.5) / h  # file rows run from the top
    sky = np.where(v[:, None, None] > 0.5, 0.3 + 0.7 * (v[:, None, None] - 0.5), 0.15) * np.ones((h, w, 3))
    sky[v <= 0.5] *= np.array([1.0, 0.8, 0.6])
    sky[7:10, 40:43] = (60.0, 55.0, 45.0)
    sky = sky.astype(np.float32)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(w, h, 3, oiio.FLOAT))
    out.write_image(sky)
    out.close()
    return str(path)


def hdri_scene(path: str):
    """A rough white Principled sphere and a rough gold metal sphere on a grey floor under the
    map, turned by a Mapping rotation; the background is in view."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rh.set_resolution(scene, 64, 48)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, -6.0, 1.6)
    camera.rotation_euler = (np.radians(78), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    for name, location, metallic, color in (("White", (-1.1, 0, 1), 0.0, (0.8, 0.8, 0.8, 1)),
                                            ("Gold", (1.1, 0, 1), 1.0, (1.0, 0.75, 0.35, 1))):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=location, segments=48, ring_count=24)
        obj = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        mat = new_material(name)
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = color
        bsdf.inputs["Metallic"].default_value = metallic
        bsdf.inputs["Roughness"].default_value = 0.35
        obj.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=20.0)
    floor = new_material("Floor")
    floor.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
    bpy.context.active_object.data.materials.append(floor)
    world = new_world("Sky")
    scene.world = world
    rh.environment_texture(world, path, np.radians(30), 1.5)
    return scene


def test_environment_map_matches_cycles(drt, tmp_path, table):
    """Image-based lighting against Cycles: the map's orientation, Mapping, strength, its
    importance sampling and MIS with the glossy lobes, and the background seen directly."""
    scene = hdri_scene(hdri(tmp_path / "sky.exr"))
    drt_renders = [rh.render(scene, "DRT", 192, seed, tmp_path) for seed in (0, 1)]
    cycles_renders = [rh.render(scene, "CYCLES", 512, seed, tmp_path) for seed in (0, 1)]
    rh.save_side_by_side("environment_map", average(drt_renders), average(cycles_renders))
    result = compare("environment_map", drt_renders, cycles_renders)
    table.append(result)
    print("\n" + HEADER + "\n" + result.row())
    assert result.block_noise <= MAX_BLOCK_NOISE and result.mean_noise <= MAX_MEAN_NOISE
    assert abs(result.mean_diff) <= BIAS_BUDGET, f"image means differ by {result.mean_diff:+.2%}"
    assert result.block_mard <= BIAS_BUDGET + NOISE_MARGIN * result.block_noise
    assert result.mard <= BIAS_BUDGET + NOISE_MARGIN * result.mard_noise
