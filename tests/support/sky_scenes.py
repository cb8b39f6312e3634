"""Scenes lit only by a Sky Texture world: a diffuse sphere on a diffuse ground under the sky,
seen from the side with the horizon and sky in view and the sun out of view (its disc lights
the scene and casts the sphere's shadow; the sky fills the shadow)."""
from __future__ import annotations

import bpy
import mathutils

from tests.support import procedural_scenes as ps
from tests.support.datablocks import new_material, new_world

STRENGTH = {"HOSEK_WILKIE": 1.0}
"""The Background's strength per sky type, 0.1 for the others (the skies are in physical units;
image means 0.06 to 1.2). Hosek / Wilkie's sky is dimmer (a fifth of Preetham's, a fiftieth of the
scattering models'): at 1 its image mean is 0.1, well above the parity rule's 0.002 floor."""

CASES = {
    "multiple scattering, defaults": {"sky_type": "MULTIPLE_SCATTERING"},
    "multiple scattering, every input": {
        "sky_type": "MULTIPLE_SCATTERING", "sun_elevation": 2.44, "sun_rotation": -2.5, "sun_size": 0.035,
        "sun_intensity": 0.6, "altitude": 2500.0, "air_density": 2.0, "aerosol_density": 4.0,
        "ozone_density": 5.0},
    "single scattering, defaults": {"sky_type": "SINGLE_SCATTERING"},
    "single scattering, every input": {
        "sky_type": "SINGLE_SCATTERING", "sun_elevation": 0.5, "sun_rotation": 2.0, "sun_size": 0.02,
        "sun_intensity": 1.5, "altitude": 3000.0, "air_density": 0.5, "aerosol_density": 3.0,
        "ozone_density": 4.0},
    "Preetham, defaults": {"sky_type": "PREETHAM"},
    "Preetham, low sun, hazy": {"sky_type": "PREETHAM", "turbidity": 6.0,
                                "sun_direction": (0.3, 0.8, 0.35)},  # of length 0.92
    "Hosek / Wilkie, defaults": {"sky_type": "HOSEK_WILKIE"},
    "Hosek / Wilkie, low sun, hazy, bright ground": {"sky_type": "HOSEK_WILKIE", "turbidity": 6.5,
                                                     "ground_albedo": 0.8, "sun_direction": (0.3, 0.8, 0.35)},
    "Hosek / Wilkie, clearest, dark ground": {"sky_type": "HOSEK_WILKIE", "turbidity": 1.0, "ground_albedo": 0.0,
                                              "sun_direction": (-0.5, 0.2, 0.6)},
    "Nishita, defaults": {"sky_type": "NISHITA"},
    "Nishita, every input": {
        "sky_type": "NISHITA", "sun_elevation": 0.5, "sun_rotation": 2.0, "sun_size": 0.02, "sun_intensity": 1.5,
        "altitude": 3000.0, "air_density": 0.5, "dust_density": 3.0, "ozone_density": 4.0},
    "Nishita, sun on the horizon": {"sky_type": "NISHITA", "sun_elevation": 0.004, "sun_rotation": 0.6,
                                    "sun_size": 0.03},
}
"""Sky settings per case; the second multiple-scattering case's elevation (140 degrees) passes
the zenith, so Cycles turns the sun round (rotation + pi) to 40 degrees. Nishita is Blender 4's
(5.0 replaced it by Single Scattering); Hosek / Wilkie's turbidity 6.5 blends two of its tables'
rows, 1.0 takes the first alone. The setting sun's disc is cut by the horizon."""


def offered(sky_type: str) -> bool:
    """Whether this Blender's Sky Texture has the type (5.0 replaced 4.x's Nishita by the
    Single and Multiple Scattering models)."""
    return sky_type in bpy.types.ShaderNodeTexSky.bl_rna.properties["sky_type"].enum_items.keys()


def _diffuse(name, color):
    mat = new_material(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = color + (1.0,)
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def sky_scene(props: dict, width=64, height=48):
    """The sphere, the ground and the sky of ``props`` (ShaderNodeTexSky properties)."""
    scene = ps._scene(width, height)
    cam = scene.camera
    cam.location = (-9.0, 0.0, 2.0)
    cam.rotation_euler = mathutils.Vector((1.0, 0.0, -0.12)).to_track_quat("-Z", "Y").to_euler()
    world = new_world("Sky")
    tree = world.node_tree
    sky = tree.nodes.new("ShaderNodeTexSky")
    for key, value in props.items():
        setattr(sky, key, value)
    background = tree.nodes["Background"]
    background.inputs["Strength"].default_value = STRENGTH.get(props["sky_type"], 0.1)
    tree.links.new(sky.outputs["Color"], background.inputs["Color"])
    scene.world = world
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    bpy.context.active_object.data.materials.append(_diffuse("Ground", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(0.0, 0.0, 1.0), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(_diffuse("Sphere", (0.7, 0.5, 0.3)))
    return scene
