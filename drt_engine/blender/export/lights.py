"""Blender lights into radiometric lights, converted exactly as Cycles converts them.

From intern/cycles/blender/light.cpp and intern/cycles/scene/light.cpp (Blender 5.0):

- strength S = color × temperature_color (if used) × energy × 2^exposure, times the
  light's node-tree emission (colour × strength) when it has one: a constant, or, where nodes
  vary it (an IES Texture, Light Falloff), a program the core evaluates at each sample and hit.
- point and spot: Cycles stores ``eval_fac = invarea / π`` with ``invarea = 1 /
  (4π r²)`` (4 for r = 0) when normalised, else 1. The sphere (or facing disk) then
  has radiance S·eval_fac, i.e. intensity S/(4π) W/sr when normalised, S·r² (r > 0)
  or S/π (r = 0) when not.
- sun: radiance S / (π sin²(angle/2)) when normalised (irradiance S), else radiance S
  over the disk of solid-angle-area π sin²(angle/2) (irradiance S·π sin²(angle/2)).
- area: sizes scale with the object's X and Y axes; area A = size_x·size_y (×π/4
  for disk and ellipse); radiance S/(π A) when normalised, else S/π.
- dropped like ``Light::has_contribution``: zero strength, area lights of zero size
  (including a zero X or Y axis in the object matrix), and portals; also spot, sun
  and area lights whose matrix has no Z axis (no direction).
"""
from __future__ import annotations

import math

import numpy as np

from ...core.errors import SceneError
from ...core.scene import Light
from ...core.lights import programs
from ...core.shading.nodes import GEOMETRY_OPS
from .materials import uses_nodes
from .nodes import Issues, flatten, input_value, report_linked_inputs, rgb
from .shader_graph import Compiler, ImageTable, is_ref


UNAVAILABLE_OPS = ("attribute", "instance_attribute", "ao", "bevel", "normal_map", "bump") + GEOMETRY_OPS
"""Program operations a light's shader has no value for in DRT (its coordinates: lights.programs)."""


def _unavailable(program) -> set[str]:
    """What a light's program reads that DRT has no value for at a light."""
    out = set()
    for node in program.nodes:
        if node.op == "coord" and node.params["name"] not in programs.COORDS:
            out.add(f"{node.params['name'].replace('_', ' ')} coordinates")
        elif node.op in UNAVAILABLE_OPS:
            out.add(f"{node.op.replace('_', ' ')} at a light")
        elif node.op == "vector_transform" and "CAMERA" in (node.params["from"], node.params["to"]):
            out.add("Vector Transform to or from camera space at a light")
    return out


def _constant_emission(output, issues: Issues) -> np.ndarray:
    """Colour x strength of the Emission nodes, linked inputs at their default values."""
    def leaf(node, weight):
        if node.bl_idname != "ShaderNodeEmission":
            issues.add(f"shader node '{node.name}'")
            return []
        report_linked_inputs(node, issues)
        color = rgb(input_value(node, issues, 1.0, "Color"))
        return [weight * color * input_value(node, issues, 1.0, "Strength")]

    parts = flatten(output.inputs["Surface"], leaf, issues)
    return np.sum(parts, axis=0) if parts else np.zeros(3)


def _node_emission(light, warnings: list[str], images: ImageTable) -> tuple:
    """(colour x strength of the light's Emission nodes, program, its output): the constant is 1
    without nodes, as in Cycles; a tree whose emission varies (an IES Texture, Light Falloff)
    becomes a program the core evaluates at each sample and hit, the constant then 1."""
    if not uses_nodes(light):
        return np.ones(3), None, None
    output = light.node_tree.get_output_node("CYCLES")
    if output is None:
        return np.zeros(3), None, None
    issues = Issues()
    compiler = Compiler(images, issues)

    def leaf(node, weight):
        if node.bl_idname != "ShaderNodeEmission":
            issues.add(f"shader node '{node.name}'")
            return []
        return [compiler.emitted(node, weight)]

    parts = flatten(output.inputs["Surface"], leaf, issues, compiler=compiler)
    constant, program, total = None, None, None
    if any(is_ref(p) for p in parts):
        unavailable = _unavailable(compiler.program)
        if unavailable:
            issues = Issues({f"{what} in its node tree" for what in unavailable})
            constant = _constant_emission(output, issues)
        else:
            program, total, constant = compiler.program, compiler.add_all(parts), np.ones(3)
            if light.type == "SUN" and any(node.op == "light_path" for node in program.nodes):
                issues.add("Light Path in a sun's node tree (evaluated once, at the first bounce)")
    else:
        constant = np.sum([rgb(p) for p in parts], axis=0) if parts else np.zeros(3)
    message = issues.message(f"Light '{light.name}'")
    if message:
        warnings.append(message)
    return constant, program, total


def light_strength(light, warnings: list[str], images: ImageTable) -> tuple:
    """Cycles' light strength (watts for point, spot and area lights, W/m² for suns) and the
    program of a node tree that varies it (None, None without one)."""
    color = np.array(light.color[:3], dtype=np.float64)
    if getattr(light, "use_temperature", False):
        color *= np.array(light.temperature_color[:3])
    exposure = getattr(light, "exposure", 0.0)
    emission, program, total = _node_emission(light, warnings, images)
    return color * light.energy * 2.0**exposure * emission, program, total


def export_light(obj, matrix: np.ndarray, warnings: list[str], images: ImageTable) -> Light | None:
    """The light of an evaluated light object placed by ``matrix``; None if Cycles drops it."""
    light = obj.data
    if light.type == "AREA" and getattr(getattr(light, "cycles", None), "is_portal", False):
        return None
    strength, program, emission = light_strength(light, warnings, images)
    if not np.isfinite(strength).all() or (strength < 0).any():
        quantity, unit = ("strength", "W/m²") if light.type == "SUN" else ("power", "W")
        raise SceneError(f"Light '{obj.name}' has an invalid {quantity} ({light.energy:g} {unit}, colour "
                         f"{tuple(round(c, 3) for c in light.color)}): it must be a finite number, not negative")
    if not strength.any():
        return None
    normalize = getattr(light, "normalize", True)
    axes = np.linalg.norm(matrix[:3, :3], axis=0)
    if light.type != "POINT" and not axes[2]:
        return None  # no direction to shine along
    rotation = matrix.copy()
    rotation[:3, :3] /= np.where(axes > 0.0, axes, 1.0)
    common = dict(matrix=rotation, name=obj.name, visible_camera=bool(getattr(obj, "visible_camera", False)),
                  program=program, emission=emission, object_scale=tuple(float(a) for a in axes),
                  cast_shadow=bool(getattr(light, "use_shadow", True)),
                  **{f"visible_{kind}": bool(getattr(obj, f"visible_{kind}", True))
                     for kind in ("diffuse", "glossy", "transmission")})
    if light.type in ("POINT", "SPOT"):
        radius = float(light.shadow_soft_size)
        if normalize:
            intensity = strength / (4.0 * math.pi)
        else:
            intensity = strength * radius**2 if radius > 0.0 else strength / math.pi
        if light.type == "SPOT":
            common.update(spot_size=light.spot_size, spot_blend=light.spot_blend)
        return Light(light.type, intensity=intensity, radius=radius, soft_falloff=light.use_soft_falloff, **common)
    if light.type == "SUN":
        angle = float(light.angle)
        disk = math.pi * math.sin(angle / 2.0) ** 2 if angle > 0.0 else 1.0
        irradiance = strength if normalize else strength * disk
        return Light("SUN", irradiance=irradiance, angle=angle, **common)
    size_x = light.size * axes[0]
    size_y = (light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size) * axes[1]
    area = size_x * size_y * (math.pi / 4.0 if light.shape in ("DISK", "ELLIPSE") else 1.0)
    if area == 0.0:
        return None  # zero size or a zero X or Y axis in the object matrix
    radiance = strength / (math.pi * area) if normalize else strength / math.pi
    return Light(
        "AREA",
        radiance=radiance,
        shape=light.shape,
        size_x=size_x,
        size_y=size_y,
        spread=light.spread,
        **common,
    )
