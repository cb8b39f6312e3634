"""Panoramic cameras in DRT against Cycles: a camera inside a box whose six walls glow in
different colours under a checker, so the whole view sphere shows and any turn, flip or wrong
range of a projection moves colours and edges. The rule is the node parity's
(procedural_scenes.parity) over RGBA: DRT's worst 4x4-block difference from Cycles (seed 0) at
most 1.5x Cycles' own between seeds 0 and 1, plus 0.002; outside a fisheye's circle both are
black and opaque. Depth of field is compared strongly enough (a quarter-metre aperture focused at
half a metre) that DRT without it fails, and so is the camera's motion blur. A panorama type DRT does not render is refused with one line naming it."""
from __future__ import annotations

import sys
from pathlib import Path

import bpy
import mathutils
import numpy as np
import pytest

from drt_engine.blender.export.shader_graph import FISHEYE_WINDOW_MATCHED_FROM, VERSION_FISHEYE_WINDOW
from drt_engine.core.errors import SceneError
from drt_engine.core.scene import PANORAMA_TYPES
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material
from tests.support.export_helpers import render_export

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sample_scenes"))
from scene_helpers import linear_keys  # noqa: E402

WALLS = {  # outward axis and sign -> emitted colour
    (0, 1): (1.0, 0.2, 0.1), (0, -1): (0.1, 0.9, 0.2), (1, 1): (0.2, 0.3, 1.0),
    (1, -1): (1.0, 0.9, 0.1), (2, 1): (0.9, 0.2, 0.9), (2, -1): (0.1, 0.9, 0.9),
}

CASES = {  # name -> (panorama type, camera settings, depth of field (f-stop, focus distance) or None,
    # the camera's turn about its view axis over the frames 0 to 2, seen with a one-frame shutter at frame 1)
    "equirectangular": ("EQUIRECTANGULAR", dict(latitude_min=-1.2, latitude_max=1.4, longitude_min=-2.8,
                                                longitude_max=2.2), None, 0.0),
    "fisheye_equidistant": ("FISHEYE_EQUIDISTANT", dict(fisheye_fov=3.6), None, 0.0),
    "fisheye_equisolid": ("FISHEYE_EQUISOLID", dict(fisheye_lens=8.0, sensor_width=30.0), None, 0.0),
    "mirrorball": ("MIRRORBALL", {}, None, 0.0),
    "equirectangular_dof": ("EQUIRECTANGULAR", {}, (0.1, 0.5), 0.0),
    "fisheye_equidistant_dof": ("FISHEYE_EQUIDISTANT", dict(fisheye_fov=3.6), (0.1, 0.5), 0.0),
    "fisheye_equidistant_turning": ("FISHEYE_EQUIDISTANT", dict(fisheye_fov=3.6), None, 0.6),
    "equiangular_cubemap_face": ("EQUIANGULAR_CUBEMAP_FACE", {}, None, 0.0),
    "equiangular_cubemap_face_dof": ("EQUIANGULAR_CUBEMAP_FACE", {}, (0.1, 0.5), 0.0),
    "fisheye_lens_polynomial": ("FISHEYE_LENS_POLYNOMIAL", dict(
        fisheye_fov=3.4, fisheye_polynomial_k0=0.02, fisheye_polynomial_k1=-0.09, fisheye_polynomial_k2=0.0,
        fisheye_polynomial_k3=-2e-5, fisheye_polynomial_k4=0.0), None, 0.0),
    "central_cylindrical": ("CENTRAL_CYLINDRICAL", dict(
        central_cylindrical_range_u_min=-2.0, central_cylindrical_range_u_max=1.5, central_cylindrical_range_v_min=-0.8,
        central_cylindrical_range_v_max=1.3, central_cylindrical_radius=1.3), None, 0.0),
}
OFFERED = bpy.types.Camera.bl_rna.properties["panorama_type"].enum_items.keys()
CASES = {name: case for name, case in CASES.items() if case[0] in OFFERED}
"""The cases of the types this Blender offers (4.2 has no Central Cylindrical)."""

SAMPLES = 256
"""More than the node parity's 64: a fisheye's or mirror ball's rim squeezes half the view into a
few pixels, where 64 samples leave single blocks noisier than Cycles' seed-to-seed worst."""


def _wall_material(color):
    """Emission of ``color`` times a checker (0.35 or 1), 2 squares per metre."""
    mat = new_material(f"wall-{color}")
    tree = mat.node_tree
    tree.nodes.clear()
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 2.0
    checker.inputs["Color1"].default_value = (*color, 1.0)
    checker.inputs["Color2"].default_value = (0.35 * color[0], 0.35 * color[1], 0.35 * color[2], 1.0)
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Object"], checker.inputs["Vector"])
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(checker.outputs["Color"], emission.inputs["Color"])
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    return mat


def box_scene(panorama: str, **settings):
    """The camera off-centre and turned inside a 3.8 m glowing box (64 x 48 pixels; the walls off the checker's edges)."""
    scene = ps._scene(64, 48)
    ps.black_world(scene)
    for (axis, sign), color in WALLS.items():
        u, v = [a for a in range(3) if a != axis]
        corners = []
        for a, b in ((-1.9, -1.9), (1.9, -1.9), (1.9, 1.9), (-1.9, 1.9)):
            p = [0.0, 0.0, 0.0]
            p[axis], p[u], p[v] = 1.9 * sign, a, b
            corners.append(tuple(p))
        mesh = bpy.data.meshes.new(f"wall{axis}{sign}")
        mesh.from_pydata(corners, [], [(0, 1, 2, 3)])
        mesh.materials.append(_wall_material(color))
        scene.collection.objects.link(bpy.data.objects.new(mesh.name, mesh))
    cam = scene.camera
    cam.location = (0.4, -0.3, 0.25)
    cam.rotation_euler = (1.2, 0.15, 0.6)
    cam.data.type = "PANO"
    cam.data.panorama_type = panorama
    for name, value in settings.items():
        setattr(cam.data, name, value)
    return scene


def _turn(scene, angle):
    """Key the camera turning by ``angle`` about its view axis, linearly over frames 0 to 2, and
    blur frame 1 over one frame."""
    cam = scene.camera
    base = cam.rotation_euler.to_matrix()
    for frame, a in ((0, -0.5 * angle), (2, 0.5 * angle)):
        cam.rotation_euler = (base @ mathutils.Matrix.Rotation(a, 3, "Z")).to_euler()
        cam.keyframe_insert("rotation_euler", frame=frame)
    linear_keys(cam)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    scene.frame_set(1)


def case_scene(case: str):
    """The box seen by the camera of ``case`` (CASES), with its depth of field and turn."""
    panorama, settings, dof, turn = CASES[case]
    scene = box_scene(panorama, **settings)
    if dof is not None:
        scene.camera.data.dof.use_dof = True
        scene.camera.data.dof.aperture_fstop, scene.camera.data.dof.focus_distance = dof
    if turn:
        _turn(scene, turn)
    return scene


@pytest.mark.parametrize("case", CASES)
def test_panoramic_camera_matches_cycles(drt, tmp_path, case):
    scene = case_scene(case)
    drt_render, c0, c1 = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name=case) for engine, seed in ps.RUNS]
    rh.save_side_by_side(f"panorama-{case}", drt_render.rgb, c0.rgb)
    combined = [r.passes["Combined"] for r in (drt_render, c0, c1)]
    figures = ps.parity(*combined)
    print(f"{case}: DRT {figures['worst']:.4f}, Cycles' seeds {figures['cycles_seeds']:.4f}")
    assert figures["ok"], ps.message(case, figures)
    assert combined[1][..., :3].mean() > 0.1  # the box is seen


def _window_material():
    """Emission of Texture Coordinate's Window (u red, v green)."""
    mat = new_material("window")
    tree = mat.node_tree
    tree.nodes.clear()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(coords.outputs["Window"], emission.inputs["Color"])
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    return mat


WINDOW_CASES = {name: case[:2] for name, case in CASES.items() if case[2] is None and not case[3]}


@pytest.mark.parametrize("case", WINDOW_CASES)
def test_window_coordinates_under_a_panoramic_camera_match_cycles(drt, tmp_path, case):
    """Cycles inverts the panorama's projection for Window; the perspective formula paints
    other gradients here and fails. A Blender whose Cycles mirrors it under a fisheye (4.2's) has
    the node named in the material's warning."""
    panorama, settings = WINDOW_CASES[case]
    scene = box_scene(panorama, **settings)
    window = _window_material()
    for obj in scene.collection.objects:
        if obj.type == "MESH":
            obj.data.materials[0] = window
    warnings = render_export(scene).warnings
    if panorama.startswith("FISHEYE") and bpy.app.version < FISHEYE_WINDOW_MATCHED_FROM:
        assert len(warnings) == 1 and VERSION_FISHEYE_WINDOW in warnings[0], warnings
        return
    assert not warnings, warnings
    renders = [rh.render(scene, engine, SAMPLES, seed, tmp_path, name=f"window-{case}") for engine, seed in ps.RUNS]
    combined = [r.passes["Combined"] for r in renders]
    figures = ps.parity(*combined)
    print(f"window {case}: DRT {figures['worst']:.4f}, Cycles' seeds {figures['cycles_seeds']:.4f}")
    assert figures["ok"], ps.message(f"window {case}", figures)
    assert combined[1][..., :2].std() > 0.1  # the gradients are seen


LEFT_OUT = [t for t in OFFERED if t not in PANORAMA_TYPES]
"""The panorama types DRT does not render that this Blender offers (none in 4.2 to 5.0)."""


@pytest.mark.parametrize("panorama", LEFT_OUT)
def test_a_panorama_type_left_out_is_one_clear_error(drt, panorama):
    scene = box_scene(panorama)
    with pytest.raises(SceneError) as error:
        render_export(scene)
    message = str(error.value)
    assert panorama in message and "\n" not in message


def test_outside_the_disc_is_black_and_opaque_as_in_cycles_even_with_transparent_film(drt, tmp_path):
    """Cycles writes nothing for an image point without a ray: black, alpha 1 (not the film's 0)."""
    scene = box_scene("MIRRORBALL")
    scene.render.film_transparent = True
    for engine in ("DRT", "CYCLES"):
        corner = rh.render(scene, engine, 4, 0, tmp_path, name="transparent").passes["Combined"][:4, :4]
        np.testing.assert_array_equal(corner.reshape(-1, 4), np.tile([0.0, 0.0, 0.0, 1.0], (16, 1)), err_msg=engine)
