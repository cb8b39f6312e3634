"""Ray visibility against Cycles, on scenes built for it, RGBA compared by procedural_scenes.parity
(DRT's worst 4x4-block difference from Cycles seed 0 within 1.5x Cycles' own seed-0-against-seed-1
worst plus 0.002), the film transparent so that alpha counts:
- a mirror floor under a glowing red cube hidden from the camera: the camera sees through the cube
  to the floor, which shows it;
- a ground under two quads, one hidden from shadow rays (seen, no shadow), lit by an area light and by
  a spot light with Cast Shadow off (no shadow at all);
- a ground of diffuse + glossy (Principled, roughness 0.35) lit by an area light hidden from diffuse
  rays (its glossy highlight only) and an emissive quad hidden from the camera and glossy rays (its
  diffuse light only).
Measured (48 x 48, 128 samples, Blender 5.0): worst block / limit (Cycles' seeds) 0.0200 / 0.0352
(0.0221) mirror, 0.0045 / 0.0100 (0.0053) shadows, 0.0113 / 0.0372 (0.0234) lights; with every
object and light fully visible and casting shadows (the settings ignored) 1.98, 0.50 and 5.66."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.blender_scenes import add_light
from tests.support.datablocks import new_material

SIZE = 48
SAMPLES = 128


def _principled(name, color, roughness=1.0, metallic=0.0, emission=None):
    mat = new_material(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*color, 1.0) if any(color) else (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission
    return mat


def _add(name, mat, primitive, location, size, rotation=(0.0, 0.0, 0.0)):
    return ps.add_primitive(getattr(bpy.ops.mesh, f"primitive_{primitive}_add"), mat, name, size=size,
                            location=location, rotation=rotation)


def mirror_scene():
    scene = ps.dark_scene(SIZE, (0.0, -6.0, 5.0), 40.0, True)
    ps.aim(scene.camera, (0.0, -4.0, 2.5))
    _add("Mirror", _principled("Mirror", (0.9, 0.9, 0.9), roughness=0.05, metallic=1.0), "plane", (0, 0, 0), 8.0)
    cube = _add("Cube", _principled("Red", (0.8, 0.1, 0.1), emission=1.0), "cube", (0.0, 0.3, 0.9), 1.0,
                (0.3, 0.2, 0.5))
    cube.visible_camera = False
    add_light(scene, "AREA", location=(0.5, -0.5, 4.0), energy=150.0, size=1.0)
    return scene


def shadow_scene():
    scene = ps.dark_scene(SIZE, (0.0, -6.0, 5.0), 40.0, True)
    _add("Ground", _principled("Ground", (0.8, 0.8, 0.8)), "plane", (0, 0, 0), 4.0)
    _add("Shadowless", _principled("Blue", (0.2, 0.3, 0.8)), "plane", (-0.9, 0.2, 1.0), 1.4, (0.2, 0, 0)
         ).visible_shadow = False
    _add("Casting", _principled("Green", (0.2, 0.7, 0.3)), "plane", (1.2, 1.0, 0.8), 1.4, (0, 0.3, 0))
    add_light(scene, "AREA", location=(0.5, -0.5, 4.0), energy=100.0, size=1.0)
    add_light(scene, "SPOT", location=(-1.0, 0.5, 3.5), energy=200.0, spot_size=1.2, shadow_soft_size=0.2,
              use_shadow=False)
    return scene


def light_scene():
    scene = ps.dark_scene(SIZE, (0.0, -6.0, 5.0), 40.0, True)
    _add("Ground", _principled("Shiny", (0.6, 0.5, 0.3), roughness=0.35), "plane", (0, 0, 0), 4.0)
    lamp = add_light(scene, "AREA", location=(0.8, 0.6, 2.0), rotation=(0.3, 0.0, 0.0), energy=300.0, size=0.8)
    lamp.visible_diffuse = False
    glow = _add("Glow", _principled("Glow", (0.0, 0.0, 0.0), emission=15.0), "plane", (-1.0, 0.3, 1.2), 0.8,
                (np.pi, 0.0, 0.0))
    glow.visible_camera, glow.visible_glossy = False, False
    if bpy.app.version < (5, 0):
        # Cycles 4.2's light tree brightens the ground under Glow when the area light is hidden from
        # diffuse rays: 512 spp, the 4x4 block there reads 0.645 with the tree, 0.619 without, against
        # 5.0's 0.605 / 0.611 (DRT's image is the same under both). Without the tree 4.2 agrees.
        scene.cycles.use_light_tree = False
    return scene


def _parity(scene, tmp_path, name):
    image, cycles0, cycles1 = (rh.render(scene, engine, SAMPLES, seed, tmp_path, name=name).passes["Combined"]
                               for engine, seed in ps.RUNS)
    return ps.parity(image, cycles0, cycles1)


@pytest.mark.parametrize("build", [mirror_scene, shadow_scene, light_scene], ids=lambda b: b.__name__)
def test_ray_visibility_matches_cycles(drt, tmp_path, build):
    figures = _parity(build(), tmp_path, build.__name__)
    assert figures["ok"], ps.message(f"{build.__name__} (RGBA)", figures)
