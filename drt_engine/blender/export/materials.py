"""Blender materials into weighted closures, walked from the active Cycles output.

Without a node tree Cycles shades with a Diffuse BSDF of ``diffuse_color``
(intern/cycles/blender/shader.cpp), and so does DRT. An unconnected Surface
renders black in Cycles: such a material has no closures.
"""
from __future__ import annotations

from dataclasses import replace

import bpy
import numpy as np

from ...core.scene import DEFAULT_MATERIAL, Closure, Material
from .nodes import Issues, flatten, input_value, report_linked_inputs, rgb


def uses_nodes(idblock) -> bool:
    """Whether Cycles reads the node tree (5.0 dropped the ``use_nodes`` switch)."""
    if idblock.node_tree is None:
        return False
    return bpy.app.version >= (5, 0, 0) or idblock.use_nodes


def _multiscatter(node, issues) -> bool:
    """Cycles compensates multiple scattering only for "Multiscatter GGX"; DRT's lobes are
    GGX, so Beckmann and Ashikhmin-Shirley render as GGX (with a warning)."""
    distribution = getattr(node, "distribution", "MULTI_GGX")
    if distribution not in ("GGX", "MULTI_GGX"):
        issues.add(f"'{node.name}' {distribution.replace('_', '-').title()} distribution (rendered as GGX)")
    return distribution == "MULTI_GGX"


def _principled(node, weight, issues):
    def value(default, *names):
        return input_value(node, issues, default, *names)

    alpha = float(np.clip(value(1.0, "Alpha"), 0.0, 1.0))
    for feature, names in (
        ("Subsurface", ("Subsurface Weight", "Subsurface")),
        ("Sheen", ("Sheen Weight", "Sheen")),
        ("Anisotropic", ("Anisotropic",)),
        ("Thin Film", ("Thin Film Thickness",)),
    ):
        if value(0.0, *names) > 0.0:
            issues.add(f"'{node.name}' {feature}")
    principled = Closure(
        "PRINCIPLED",
        weight=weight * alpha,
        color=rgb(value(0.8, "Base Color")),
        metallic=value(0.0, "Metallic"),
        roughness=value(0.5, "Roughness"),
        ior=value(1.5, "IOR"),
        specular_ior_level=value(0.5, "Specular IOR Level"),
        specular_tint=rgb(value(1.0, "Specular Tint")),
        transmission=value(0.0, "Transmission Weight", "Transmission"),
        coat_weight=value(0.0, "Coat Weight", "Coat"),
        coat_roughness=value(0.03, "Coat Roughness"),
        coat_ior=value(1.5, "Coat IOR"),
        coat_tint=rgb(value(1.0, "Coat Tint")),
        emission=rgb(value(1.0, "Emission Color", "Emission")) * value(0.0, "Emission Strength"),
        multiscatter=_multiscatter(node, issues),
    )
    closures = [principled] if alpha > 0.0 else []
    if alpha < 1.0:
        closures.append(Closure("TRANSPARENT", weight=weight * (1.0 - alpha), color=np.ones(3)))
    return closures


def _bsdf(kind):
    def make(node, weight, issues):
        closure = Closure(kind, weight=weight, color=rgb(input_value(node, issues, 0.8, "Color")))
        if kind != "TRANSPARENT":
            closure.roughness = input_value(node, issues, 0.5, "Roughness")
        if kind in ("GLOSSY", "GLASS", "REFRACTION"):
            closure.multiscatter = _multiscatter(node, issues)
        if kind in ("GLASS", "REFRACTION"):
            closure.ior = input_value(node, issues, 1.5, "IOR")
        if kind == "DIFFUSE" and closure.roughness > 0.0:
            issues.add(f"'{node.name}' Oren-Nayar roughness")
        if kind == "GLOSSY" and input_value(node, issues, 0.0, "Anisotropy") > 0.0:
            issues.add(f"'{node.name}' anisotropy")
        return [closure]

    return make


def _emission(node, weight, issues):
    color = rgb(input_value(node, issues, 1.0, "Color"))
    strength = input_value(node, issues, 1.0, "Strength")
    return [Closure("EMISSION", weight=weight, color=color, emission=color * strength)]


CLOSURE_NODES = {
    "ShaderNodeBsdfPrincipled": _principled,
    "ShaderNodeBsdfDiffuse": _bsdf("DIFFUSE"),
    "ShaderNodeBsdfGlossy": _bsdf("GLOSSY"),
    "ShaderNodeBsdfAnisotropic": _bsdf("GLOSSY"),
    "ShaderNodeBsdfGlass": _bsdf("GLASS"),
    "ShaderNodeBsdfRefraction": _bsdf("REFRACTION"),
    "ShaderNodeEmission": _emission,
    "ShaderNodeBsdfTransparent": _bsdf("TRANSPARENT"),
}


def export_material(material) -> tuple[Material, str | None]:
    """The material as closures, and a warning (or None) about what was approximated."""
    if not uses_nodes(material):
        color = np.array(material.diffuse_color[:3], dtype=np.float64)
        return Material(material.name, [Closure("DIFFUSE", color=color, roughness=0.0)]), None
    issues = Issues()

    def leaf(node, weight):
        make = CLOSURE_NODES.get(node.bl_idname)
        if make is None:
            issues.add(f"shader node '{node.name}' ({node.bl_label}, rendered as default grey)")
            return [replace(c, weight=weight * c.weight) for c in DEFAULT_MATERIAL.closures]
        report_linked_inputs(node, issues)
        return make(node, weight, issues)

    output = material.node_tree.get_output_node("CYCLES")
    closures = [] if output is None else flatten(output.inputs["Surface"], leaf, issues)
    return Material(material.name, closures), issues.message(f"Material '{material.name}'")


class MaterialTable:
    """The scene's material list, each Blender material exported once.

    Index 0 is ``DEFAULT_MATERIAL``, used for empty slots and objects without
    materials, as Cycles uses its default surface.
    """

    def __init__(self, warnings: list[str]):
        self.materials = [DEFAULT_MATERIAL]
        self.warnings = warnings
        self._index: dict[int, int] = {}

    def index(self, material) -> int:
        if material is None:
            return 0
        key = material.original.as_pointer()
        found = self._index.get(key)
        if found is None:
            exported, warning = export_material(material)
            if warning:
                self.warnings.append(warning)
            found = self._index[key] = len(self.materials)
            self.materials.append(exported)
        return found
