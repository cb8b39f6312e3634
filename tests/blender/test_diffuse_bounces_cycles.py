"""Light that bounces off diffuse surfaces, against Cycles with the same Light Paths.

The four sample scenes with diffuse bounces 4 in both renderers (render_helpers.configure_cycles
gives Cycles DRT's depth and diffuse bounces). In the Cornell box (Lambertian walls and boxes
under one square area light) the ceiling, dark with diffuse bounces 0, is lit by the walls and
the walls bleed their colours; in the other three the floor and the spheres light each other
(3-5% of the image mean, 48x48). Both end paths by Russian roulette after the first bounce
(unbiased), and both let paths go on past the light's body (Cycles' integrate_light; while
DRT's paths stopped at it, DRT was 0.7% darker on the Cornell box's mean: the ceiling behind
the light missed its share of the room's light). Figures as
tests/support/procedural_scenes.parity: DRT's worst 4x4-block difference from Cycles seed 0
within 1.5x Cycles' own seed-0-against-seed-1 worst plus 0.002, and the image means within
0.5%, which fails when the indirect light is missing (3.3% darker on motion_blur, 46% on the
Cornell box) or doubled.
"""
from __future__ import annotations

import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh

SIZE = 48
SAMPLES = 256
BOUNCES = 4


def _scene(path, bounces):
    scene = rh.open_scene(path)
    rh.set_resolution(scene, SIZE, SIZE)
    scene.drt.diffuse_bounces = bounces
    return scene


@pytest.mark.parametrize("name", ["cornell_box", "dof_row", "glossy_spheres", "motion_blur"])
def test_sample_scene_with_diffuse_bounces_matches_cycles(drt, tmp_path, sample_scene, name):
    path = sample_scene(name)
    image, cycles0, cycles1 = [rh.render(_scene(path, BOUNCES), engine, SAMPLES, seed, tmp_path,
                                         name=f"{name}-{BOUNCES}").rgb for engine, seed in ps.RUNS]
    rh.save_side_by_side(f"{name}_diffuse_{BOUNCES}", image, cycles0)
    figures = ps.parity(image, cycles0, cycles1)
    means = image.mean() / cycles0.mean() - 1.0
    print(f"{name}, diffuse bounces {BOUNCES}: worst block {figures['worst']:.4f} (limit {figures['limit']:.4f}, "
          f"Cycles' seeds {figures['cycles_seeds']:.4f}); image means {means:+.4%}; "
          f"Cycles seeds' means {cycles1.mean() / cycles0.mean() - 1.0:+.4%}")
    assert figures["ok"], ps.message(f"{name}, diffuse bounces {BOUNCES}", figures)
    assert abs(means) < 0.005
    if name == "cornell_box":  # the figures can fail: without the bounces, DRT's box is far darker than Cycles'
        direct = rh.render(_scene(path, 0), "DRT", 16, 0, tmp_path, name="cornell-direct").rgb.mean()
        assert image.mean() > 1.2 * direct


def _glass_scene(bounces):
    """A clear glass sphere (Glass BSDF, IOR 1.45) on a white diffuse floor under one area light and a
    black world, 64 x 48: the floor's caustic and the light the floor and the sphere pass each other
    reach the camera only through diffuse bounces and the glass's delta lobes."""
    import bpy

    scene = ps._scene(64, 48)
    ps.aim(scene.camera, (0.0, -6.0, 4.0))
    scene.camera.data.lens = 35.0
    scene.drt.diffuse_bounces = bounces
    ps.black_world(scene)
    floor, _ = ps.closure_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    glass, _ = ps.closure_material("Glass", "ShaderNodeBsdfGlass", Roughness=0.0, IOR=1.45)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, floor, "Floor", size=20.0)
    ps.add_primitive(bpy.ops.mesh.primitive_uv_sphere_add, glass, "Glass", radius=1.0, location=(0.0, 0.0, 1.0),
                     segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    ps.add_light(scene, "Key", "AREA", 300.0, (1.0, 0.5, 5.0), size=1.0)
    return scene


def test_glass_on_a_diffuse_floor_with_diffuse_bounces_matches_cycles(drt, tmp_path):
    """Glass at diffuse bounces 2: as Cycles (the light passes' scene at 128 samples failed its
    Combined parity on one seed; 8 seeds and 1024 samples showed noise, not a missing light: see
    core.sampling.dims on Russian roulette's dimension). Without the bounces DRT is 7% darker."""
    image, cycles0, cycles1 = [rh.render(_glass_scene(2), engine, SAMPLES, seed, tmp_path, name="glass-2").rgb
                               for engine, seed in ps.RUNS]
    rh.save_side_by_side("glass_diffuse_2", image, cycles0)
    figures = ps.parity(image, cycles0, cycles1)
    means = image.mean() / cycles0.mean() - 1.0
    print(f"glass, diffuse bounces 2: worst block {figures['worst']:.4f} (limit {figures['limit']:.4f}); "
          f"image means {means:+.4%}; Cycles seeds' means {cycles1.mean() / cycles0.mean() - 1.0:+.4%}")
    assert figures["ok"], ps.message("glass, diffuse bounces 2", figures)
    assert abs(means) < 0.005
    direct = rh.render(_glass_scene(0), "DRT", 16, 0, tmp_path, name="glass-direct").rgb.mean()
    assert image.mean() > 1.04 * direct
