"""Cameras at their limits: f/0.01 focused at the clip start, orthographic depth of field, shift 10,
1x1 and 4x4 images, 7680x4320 in bounded memory, inside a closed mesh, clip 1e-6 to 1e9."""
import subprocess
import sys
from pathlib import Path

import numpy as np

from tests.support import blender_scenes as bs
from tests.support.core_cases import Camera, Closure, Instance, Material, SceneData, render
from tests.support.scenes import plane, translation

STRENGTH = 2.0


def emitter_scene(drt, width=8, height=8, samples=4, distance=5.0, half=1e3):
    """Camera at the origin looking down -Z at an emissive plane (strength 2) that fills every view."""
    scene = bs.new_scene(width, height, samples)
    bs.add_plane(scene, "Emitter", half=half, location=(0, 0, -distance), mat=bs.material("EMISSION", strength=STRENGTH))
    return scene


def test_f_0_01_focused_at_the_clip_start_sees_a_uniform_field_uniformly(drt, tmp_path):
    scene = emitter_scene(drt, samples=16)
    cam = scene.camera.data
    cam.dof.use_dof = True
    cam.dof.aperture_fstop = 0.01  # aperture radius 50 mm / 0.02 = 2.5 m
    cam.dof.focus_distance = cam.clip_start
    image = bs.render(scene, tmp_path)["Combined"]
    np.testing.assert_allclose(image[..., :3], STRENGTH, rtol=1e-5)


def edge_scene(drt, ortho_dof: bool, focus: float):
    """Orthographic camera over a bright/dim edge at 5 m; depth of field focused at ``focus``."""
    scene = bs.new_scene(32, 8, samples=64)
    bs.add_plane(scene, "Bright", half=1.0, location=(-1.0, 0, -5), mat=bs.material("EMISSION", strength=1.0))
    bs.add_plane(scene, "Dim", half=1.0, location=(1.0, 0, -5), mat=bs.material("EMISSION", strength=0.0, name="D"))
    cam = scene.camera.data
    cam.type = "ORTHO"
    cam.ortho_scale = 1.0
    cam.dof.use_dof = ortho_dof
    cam.dof.aperture_fstop = 2.0  # orthographic aperture radius 1 / (2 f) = 0.25 m
    cam.dof.focus_distance = focus
    return scene


def edge_width(image):
    """Pixels over which the mean row falls from 90% to 10% of the bright side."""
    row = image[..., 0].mean(axis=0)
    return int(((row < 0.9 * row.max()) & (row > 0.1 * row.max())).sum())


def test_orthographic_camera_with_depth_of_field(drt, tmp_path):
    """In focus at the edge's distance it stays as sharp as without depth of field; focused at 2 m,
    the 0.25 m aperture blurs it. Before the fix the orthographic camera ignored its aperture
    (the edge stayed 2 pixels wide when focused at 2 m)."""
    sharp = bs.render(edge_scene(drt, False, 5.0), tmp_path, "nodof")["Combined"]
    focused = bs.render(edge_scene(drt, True, 5.0), tmp_path, "focused")["Combined"]
    blurred = bs.render(edge_scene(drt, True, 2.0), tmp_path, "blurred")["Combined"]
    print(f"edge 10-90% widths (px): no dof {edge_width(sharp)}, focused {edge_width(focused)}, "
          f"defocused {edge_width(blurred)}")
    assert edge_width(sharp) <= 2 and edge_width(focused) <= 2
    np.testing.assert_allclose(focused[..., :3].mean(), sharp[..., :3].mean(), rtol=0.02)
    # defocus: a point 3 m beyond focus spreads over a disk of radius 0.25 * 3 / 2 = 0.375 m; the
    # edge's 10-90% rise is then about 0.5 m, 16 of the 32 pixels across the 1 m view
    assert 8 <= edge_width(blurred) <= 24
    np.testing.assert_allclose(blurred[..., :3].mean(), sharp[..., :3].mean(), rtol=0.05)


def test_shift_10_keeps_planar_depth_and_radiance(drt, tmp_path):
    scene = emitter_scene(drt, half=1e6)
    scene.camera.data.shift_x = 10.0
    scene.camera.data.clip_end = 1e7
    passes = bs.render(scene, tmp_path)
    np.testing.assert_allclose(passes["Combined"][..., :3], STRENGTH, rtol=1e-5)
    np.testing.assert_allclose(passes["Depth"][..., 0], 5.0, rtol=1e-4)  # depth along the view axis


def test_one_pixel_image_in_the_core():
    cam = Camera(translation(0, 0, 5)[None], (-0.1, 0.1, -0.1, 0.1), (1, 1))
    scene = SceneData(cam, [plane(4.0)], [Instance(0, np.eye(4))],
                      [Material("e", [Closure("EMISSION", emission=(STRENGTH,) * 3)])])
    passes, _ = render(scene, samples=4)
    assert passes["Combined"].shape == (1, 1, 4)
    np.testing.assert_allclose(passes["Combined"][0, 0], [STRENGTH] * 3 + [1.0], rtol=1e-6)
    np.testing.assert_allclose(passes["Depth"][0, 0, 0], 5.0, rtol=1e-6)


def test_four_by_four_through_blender(drt, tmp_path):
    """Blender's smallest image (4 pixels per side)."""
    passes = bs.render(emitter_scene(drt, width=4, height=4), tmp_path)
    assert passes["Combined"].shape == (4, 4, 4)
    np.testing.assert_allclose(passes["Combined"][..., :3], STRENGTH, rtol=1e-5)


BIG = """
import sys, numpy as np
sys.path.insert(0, {root!r})
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.memory import peak_resident_mb
from tests.support.scenes import plane, translation
cam = Camera(translation(0, 0, 5)[None], (-0.16, 0.16, -0.09, 0.09), (7680, 4320))
scene = SceneData(cam, [plane(4.0)], [Instance(0, np.eye(4))], [Material("e", [Closure("EMISSION", emission=(2, 2, 2))])])
image = Renderer(scene, RenderSettings(samples=1, max_depth=0, threads=2)).render().passes["Combined"]
assert image.shape == (4320, 7680, 4) and np.allclose(image[::97, ::89, :3], 2.0)
print(peak_resident_mb() / 1024)
"""


def test_8k_image_in_bounded_memory():
    """7680x4320, one sample, max depth 0, in a fresh process: its own peak resident memory under 4 GB."""
    root = Path(__file__).resolve().parents[2]
    code = BIG.format(root=str(root))
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    peak_gb = float(result.stdout.split()[-1])
    print(f"8K peak RSS {peak_gb:.2f} GB")
    assert peak_gb < 4.0


def test_camera_inside_a_closed_mesh_sees_only_its_unlit_inside(drt, tmp_path):
    scene = emitter_scene(drt, half=10.0)
    bs.set_world(scene, 1.0)
    bs.add_light(scene, "SUN", (0, 0, 10), energy=5.0, angle=0.1)
    bs.cube(scene, half=1.0, mat=bs.material("DIFFUSE"))
    passes = bs.render(scene, tmp_path)
    assert passes["Combined"][..., :3].max() == 0.0
    assert np.all(passes["Depth"][..., 0] <= 1.0 + 1e-4)  # the cube's inside, 1 m ahead at most


def test_clip_start_1e_6_and_clip_end_1e9(drt, tmp_path):
    """A plane 1e8 m away is seen at its depth; one 2e9 m away is past the clip end; nothing near is lost."""
    scene = bs.new_scene(8, 8, 4)
    cam = scene.camera.data
    cam.clip_start, cam.clip_end = 1e-6, 1e9
    bs.add_plane(scene, "Far", half=1e8, location=(0, 0, -1e8), mat=bs.material("EMISSION", strength=STRENGTH))
    bs.add_plane(scene, "Beyond", half=1e10, location=(0, 0, -2e9), mat=bs.material("EMISSION", strength=7.0))
    near = bs.add_plane(scene, "Near", half=5e-6, location=(-5e-6, 5e-6, -1e-5),
                        mat=bs.material("EMISSION", strength=3.0, name="N"))
    scene.render.filter_size = 0.0  # each sample at its pixel's centre: the quadrant's edge stays sharp
    passes = bs.render(scene, tmp_path)
    combined = passes["Combined"][..., 0]
    np.testing.assert_allclose(combined[:4, :4], 3.0, rtol=1e-5)  # the top-left quadrant: the plane 1e-5 m ahead
    np.testing.assert_allclose(passes["Depth"][:4, :4, 0], 1e-5, rtol=1e-4)
    far = np.ones_like(combined, bool)
    far[:4, :4] = False
    np.testing.assert_allclose(combined[far], STRENGTH, rtol=1e-5)
    np.testing.assert_allclose(passes["Depth"][..., 0][far], 1e8, rtol=1e-5)
    del near


def test_focus_distance_zero_gives_finite_rays():
    """Focus 0 with an open aperture: clamped at 1e-5 as Cycles does (before, every lens ray left
    in the lens plane and started at an infinite distance)."""
    from drt_engine.core.geometry import camera as camera_rays

    cam = Camera(translation(0, 0, 5)[None], (-0.36, 0.36, -0.36, 0.36), (4, 4), aperture_radius=0.01,
                 focus_distance=0.0)
    rng = np.random.default_rng(0)
    rays = camera_rays.generate(cam, rng.random(64) * 4, rng.random(64) * 4, rng.random((64, 2)))
    assert np.isfinite(rays.origins).all() and np.isfinite(rays.directions).all() and np.isfinite(rays.tmax).all()


def test_a_child_process_reports_its_own_peak_memory():
    """The 8K bound reads the child's own peak: a child of a process that held 1 GB reports far less
    (getrusage's ru_maxrss would have reported the parent's peak)."""
    held = np.ones(1 << 27)  # 1 GiB, every page touched
    code = f"import sys; sys.path.insert(0, {str(Path(__file__).resolve().parents[2])!r}); " \
           "from tests.support.memory import peak_resident_mb; print(peak_resident_mb())"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    del held
    assert float(result.stdout) < 256
