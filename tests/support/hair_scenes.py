"""The hair closures' scene against Cycles (tests/blender/test_hair_cycles.py, and the Huang row of
bench/node_parity.py): two smooth UV spheres of one closure under an area and a point light."""
from __future__ import annotations

from tests.support import procedural_scenes as ps

WIDTH, HEIGHT = 96, 48


def _hair_bsdf(name, component, colour):
    material, node = ps.closure_material(name, "ShaderNodeBsdfHair", Color=colour)
    node.component = component
    return material


def _principled_hair(name, model, parametrization, **inputs):
    material, node = ps.closure_material(name, "ShaderNodeBsdfHairPrincipled")
    node.model, node.parametrization = model, parametrization  # before the inputs they enable
    for socket, value in inputs.items():
        node.inputs[socket].default_value = value
    return material


def hair_scene(node):
    """Two spheres of ``node``'s closure ("ShaderNodeBsdfHair": Reflection and Transmission;
    "CHIANG": Direct Coloring and Melanin with a Coat; "HUANG": Direct Coloring and Melanin with an
    Aspect Ratio of 0.6), lit by an area and a point light over a black world."""
    scene = ps.sphere_pair_stage(WIDTH, HEIGHT)
    ps.add_light(scene, "Area", "AREA", 150.0, (1.5, -3.0, 3.0), size=2.0)
    ps.add_light(scene, "Point", "POINT", 400.0, (-3.0, -2.5, 1.0))
    if node == "ShaderNodeBsdfHair":
        left = _hair_bsdf("Reflection", "Reflection", (0.9, 0.6, 0.3, 1.0))
        right = _hair_bsdf("Transmission", "Transmission", (0.6, 0.8, 0.9, 1.0))
    elif node == "CHIANG":
        left = _principled_hair("Coloured", "CHIANG", "COLOR", Color=(0.6, 0.3, 0.15, 1.0))
        right = _principled_hair("Melanin", "CHIANG", "MELANIN", Melanin=0.5, Coat=0.3)
    else:
        left = _principled_hair("Coloured", "HUANG", "COLOR", Color=(0.6, 0.3, 0.15, 1.0))
        right = _principled_hair("Melanin", "HUANG", "MELANIN", Melanin=0.5, **{"Aspect Ratio": 0.6})
    ps.smooth_sphere("Left", -1.1, left)
    ps.smooth_sphere("Right", 1.1, right)
    return scene
