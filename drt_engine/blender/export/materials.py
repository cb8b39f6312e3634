"""Blender materials into weighted closures, walked from the active Cycles output.

Without a node tree Cycles shades with a Diffuse BSDF of ``diffuse_color``
(intern/cycles/blender/shader.cpp), and so does DRT. An unconnected Surface
renders black in Cycles: such a material has no closures.
"""
from __future__ import annotations

from dataclasses import replace

import bpy
import numpy as np

from ...core.bsdf.microfacet import conductor_f82
from ...core.scene import DEFAULT_MATERIAL, Closure, Material
from ..properties import view_layer_aovs
from .nodes import Issues, find_input, flatten, rgb
from .shader_graph import DISPLACEMENT_MATCHED_FROM, Compiler, ImageTable, is_ref


def uses_nodes(idblock) -> bool:
    """Whether Cycles reads the node tree of a material, world or light.

    Blender dropped the ``use_nodes`` switch (5.0 for materials and worlds, 5.2 for lights): it is
    then deprecated, always True, and reading it warns, so it is read only where it still counts.
    """
    if idblock.node_tree is None:
        return False
    switch = idblock.bl_rna.properties["use_nodes"]
    return getattr(switch, "is_deprecated", False) or idblock.use_nodes


def _multiscatter(node, issues) -> bool:
    """Cycles compensates multiple scattering only for "Multiscatter GGX"; DRT's lobes are
    GGX, so Beckmann and Ashikhmin-Shirley render as GGX (with a warning)."""
    distribution = getattr(node, "distribution", "MULTI_GGX")
    if distribution not in ("GGX", "MULTI_GGX"):
        issues.add(f"'{node.name}' {distribution.replace('_', '-').title()} distribution (rendered as GGX)")
    return distribution == "MULTI_GGX"


VARYING = ("emission_color", "emission_strength", "color", "roughness", "metallic", "ior", "specular_ior_level",
           "specular_tint", "transmission", "coat_weight", "coat_roughness", "coat_ior", "coat_tint",
           "sheen_weight", "sheen_roughness", "sheen_tint", "diffuse_roughness", "normal", "coat_normal", "anisotropy",
           "anisotropic_rotation", "toon_size", "toon_smooth", "thin_film_thickness", "thin_film_ior",
           "hair_roughness_v", "hair_offset", "melanin", "melanin_redness", "hair_tint", "absorption",
           "radial_roughness", "hair_coat", "random_color", "random_roughness", "hair_random")
"""Closure fields the core evaluates per hit (core.shading); other linked inputs use their default."""


class _Inputs:
    """Reads a closure node's inputs: constants, or references into the material's program."""

    def __init__(self, node, compiler, issues):
        self.node, self.compiler, self.issues = node, compiler, issues
        self.varying: dict = {}

    def __call__(self, default, *names, field=None, kind=None):
        socket = find_input(self.node, *names)
        if socket is None:
            return default
        value = self.compiler.value(socket, kind)
        if not is_ref(value):
            return value
        if field in VARYING:
            self.varying[field] = value
        else:
            self.issues.add(f"'{self.node.name}' input '{socket.name}' from a texture (its default value used)")
        value = socket.default_value
        return float(value) if isinstance(value, (int, float)) else np.array(value[:], dtype=np.float64)

    def normal(self, name="Normal", field="normal"):
        """A linked normal socket as a per-hit input (unlinked: the shading normal, as Cycles)."""
        socket = find_input(self.node, name)
        if socket is not None and socket.is_linked:
            value = self.compiler.value(socket, "vector")
            if is_ref(value):
                self.varying[field] = value

    def anisotropy(self, closure, name, rotation_name):
        """The closure's anisotropy, its rotation and, when it is anisotropic, its tangent: the
        Tangent socket's, or Geometry's Tangent where it is unlinked (as Cycles links it)."""
        closure.anisotropy = self(0.0, name, field="anisotropy", kind="float")
        closure.anisotropic_rotation = self(0.0, rotation_name, field="anisotropic_rotation", kind="float")
        if closure.anisotropy == 0.0 and "anisotropy" not in self.varying:
            self.varying.pop("anisotropic_rotation", None)
            return
        socket = find_input(self.node, "Tangent")
        value = self.compiler.value(socket, "vector") if socket is not None and socket.is_linked else None
        if value is None:
            value = self.compiler.geometry_tangent()
        self.varying["tangent"] = self.compiler.ref(value, "vector")


def _weighted(closure, weight, inputs):
    """The closure with its (constant or varying) weight and varying inputs."""
    closure.inputs = dict(inputs)
    if is_ref(weight):
        closure.inputs["weight"] = weight
    else:
        closure.weight = np.asarray(weight, float) * closure.weight
    return closure


def _principled(node, weight, issues, compiler):
    value = _Inputs(node, compiler, issues)
    alpha_socket = find_input(node, "Alpha")
    alpha = compiler.value(alpha_socket, "float") if alpha_socket is not None else 1.0
    if value(0.0, "Subsurface Weight", "Subsurface") > 0.0:
        issues.add(f"'{node.name}' Subsurface")
    principled = Closure(
        "PRINCIPLED",
        color=rgb(value(0.8, "Base Color", field="color", kind="color")),
        metallic=value(0.0, "Metallic", field="metallic", kind="float"),
        roughness=value(0.5, "Roughness", field="roughness", kind="float"),
        ior=value(1.5, "IOR", field="ior", kind="float"),
        specular_ior_level=value(0.5, "Specular IOR Level", field="specular_ior_level", kind="float"),
        specular_tint=rgb(value(1.0, "Specular Tint", field="specular_tint", kind="color")),
        transmission=value(0.0, "Transmission Weight", "Transmission", field="transmission", kind="float"),
        coat_weight=value(0.0, "Coat Weight", "Coat", field="coat_weight", kind="float"),
        coat_roughness=value(0.03, "Coat Roughness", field="coat_roughness", kind="float"),
        coat_ior=value(1.5, "Coat IOR", field="coat_ior", kind="float"),
        coat_tint=rgb(value(1.0, "Coat Tint", field="coat_tint", kind="color")),
        sheen_weight=value(0.0, "Sheen Weight", "Sheen", field="sheen_weight", kind="float"),
        sheen_roughness=value(0.5, "Sheen Roughness", field="sheen_roughness", kind="float"),
        sheen_tint=rgb(value(1.0, "Sheen Tint", field="sheen_tint", kind="color")),
        diffuse_roughness=value(0.0, "Diffuse Roughness", field="diffuse_roughness", kind="float"),
        multiscatter=_multiscatter(node, issues),
    )
    _thin_film(node, principled, value, issues)
    value.anisotropy(principled, "Anisotropic", "Anisotropic Rotation")
    _oren_nayar_version(node, principled, value, issues)
    _emission_input(principled, value, compiler, 0.0, ("Emission Color", "Emission"), ("Emission Strength",))
    value.normal()
    value.normal("Coat Normal", "coat_normal")
    sheen = principled.sheen_weight > 0.0 or "sheen_weight" in value.varying
    coated = principled.coat_weight > 0.0 or "coat_weight" in value.varying
    if sheen and coated and "coat_normal" in value.varying:
        issues.add(f"'{node.name}' Sheen with a Coat Normal (the sheen shades about the main Normal, not "
                   "Cycles' blend of the two by Coat Weight)")
    if is_ref(alpha):
        opaque = compiler.scale(weight, compiler.clamp01(alpha))
        clear = compiler.scale(weight, compiler.one_minus(compiler.clamp01(alpha)))
        return [_weighted(principled, opaque, value.varying),
                _weighted(Closure("TRANSPARENT", color=np.ones(3)), clear, {})]
    alpha = float(np.clip(alpha, 0.0, 1.0))
    closures = [_weighted(principled, compiler.scale(weight, alpha), value.varying)] if alpha > 0.0 else []
    if alpha < 1.0:
        closures.append(_weighted(Closure("TRANSPARENT", color=np.ones(3)), compiler.scale(weight, 1.0 - alpha), {}))
    return closures


THIN_FILM_MATCHED_FROM = (5, 0)
"""The first Blender whose Cycles computes the thin film as DRT does (core.bsdf.thin_film: 5.0's
sensitivity table, the film's IOR blended below 1 nm, the film over the metal lobe too). 4.2's
Cycles blends below 30 nm, integrates with another fit of the colour matching functions and
leaves metal bare: there DRT leaves metal bare too and names the film in the warning."""
VERSION_THIN_FILM = "thin film: rendered as Cycles 5.0 computes it"


def _thin_film(node, closure, value, issues):
    """Principled's Thin Film Thickness and IOR (linkable), on the metal lobe too from 5.0."""
    closure.thin_film_thickness = value(0.0, "Thin Film Thickness", field="thin_film_thickness", kind="float")
    if closure.thin_film_thickness == 0.0 and "thin_film_thickness" not in value.varying:
        return
    closure.thin_film_ior = value(1.33, "Thin Film IOR", field="thin_film_ior", kind="float")
    closure.thin_film_metal = bpy.app.version >= THIN_FILM_MATCHED_FROM
    if bpy.app.version < THIN_FILM_MATCHED_FROM:
        issues.add(f"'{node.name}' {VERSION_THIN_FILM}")


def _bsdf(kind):
    def make(node, weight, issues, compiler):
        value = _Inputs(node, compiler, issues)
        closure = Closure(kind, color=rgb(value(0.8, "Color", field="color", kind="color")))
        if kind == "DIFFUSE":
            closure.diffuse_roughness = value(0.0, "Roughness", field="diffuse_roughness", kind="float")
            _oren_nayar_version(node, closure, value, issues)
        elif kind not in ("TRANSPARENT", "TRANSLUCENT"):
            closure.roughness = value(0.5, "Roughness", field="roughness", kind="float")
        if kind in ("GLOSSY", "GLASS", "REFRACTION"):
            closure.multiscatter = _multiscatter(node, issues)
        if kind in ("GLASS", "REFRACTION"):
            closure.ior = value(1.5, "IOR", field="ior", kind="float")
        if kind == "GLOSSY":
            value.anisotropy(closure, "Anisotropy", "Rotation")
        if kind != "TRANSPARENT":
            value.normal()
        return [_weighted(closure, weight, value.varying)]

    return make


def _toon(node, weight, issues, compiler):
    """The Toon BSDF: Cycles' diffuse or glossy toon closure (its component), Size and Smooth as the
    node gives them (core.bsdf.shader.toon_angles clamps them as Cycles does)."""
    value = _Inputs(node, compiler, issues)
    kind = "GLOSSY_TOON" if getattr(node, "component", "DIFFUSE") == "GLOSSY" else "DIFFUSE_TOON"
    closure = Closure(kind, color=rgb(value(0.8, "Color", field="color", kind="color")),
                      toon_size=value(0.5, "Size", field="toon_size", kind="float"),
                      toon_smooth=value(0.0, "Smooth", field="toon_smooth", kind="float"))
    value.normal()
    return [_weighted(closure, weight, value.varying)]


def _sheen(node, weight, issues, compiler):
    """The Sheen BSDF: Cycles' microfiber sheen; the legacy Ashikhmin velvet is not built (rendered
    as microfiber, named in the warning)."""
    value = _Inputs(node, compiler, issues)
    if getattr(node, "distribution", "MICROFIBER") != "MICROFIBER":
        issues.add(f"'{node.name}' Ashikhmin distribution (rendered as Microfiber)")
    closure = Closure("SHEEN", color=rgb(value(0.8, "Color", field="color", kind="color")),
                      roughness=value(0.5, "Roughness", field="roughness", kind="float"))
    value.normal()
    return [_weighted(closure, weight, value.varying)]


OREN_NAYAR_MATCHED_FROM = (4, 3)
"""The first Blender taken to have the Oren-Nayar DRT computes (Fujii's with a multiple-scattering
term, kernel/closure/bsdf_oren_nayar.h), the version that added the Principled BSDF's Diffuse
Roughness; matched against 5.0's Cycles. 4.2's is the older model (measured: a white plane seen
head-on under a sun 69 degrees off, roughness 1, 0.0896 against this model's 0.1021); 4.3 and 4.4
were not measured. Before this version a rough diffuse is named in the material's warning."""
VERSION_OREN_NAYAR = "this Blender's Oren-Nayar: rendered as Cycles 4.3+ computes it"


def _oren_nayar_version(node, closure, value, issues):
    """Name a rough diffuse on a Blender whose Cycles computes Oren-Nayar otherwise."""
    rough = closure.diffuse_roughness > 0.0 or "diffuse_roughness" in value.varying
    if rough and bpy.app.version < OREN_NAYAR_MATCHED_FROM:
        issues.add(f"'{node.name}' roughness ({VERSION_OREN_NAYAR})")


BUMP_SHADOWING_GGX_FROM = (5, 0)
"""The first Blender taken to shadow bumps as Cycles 5 does (Conty Estevez et al.'s microfacet
term, kernel/closure/bsdf.h bump_shadowing_term; read in 5.0's and 5.2's Cycles); 4.2's and 4.3's
Cycles have Chiang et al.'s term. 4.4 and 4.5 were not read: taken as 4.3's."""


def bump_shadowing_model() -> str:
    """The bump shadowing of the running Blender's Cycles (core.scene.Material.bump_shadowing)."""
    return "GGX" if bpy.app.version >= BUMP_SHADOWING_GGX_FROM else "CHIANG"


def _emission_input(closure, value, compiler, default_strength, color_names, strength_names):
    """Emission colour x strength: constant, or a varying input of the closure."""
    color = value(1.0, *color_names, field="emission_color", kind="color")
    strength = value(default_strength, *strength_names, field="emission_strength", kind="float")
    color_ref = value.varying.pop("emission_color", None)
    strength_ref = value.varying.pop("emission_strength", None)
    closure.emission = rgb(color) * strength
    if color_ref is not None or strength_ref is not None:
        value.varying["emission"] = compiler.scale(color_ref if color_ref is not None else rgb(color),
                                                   strength_ref if strength_ref is not None else strength)
    return rgb(color)


def _emission(node, weight, issues, compiler):
    value = _Inputs(node, compiler, issues)
    closure = Closure("EMISSION")
    closure.color = _emission_input(closure, value, compiler, 1.0, ("Color",), ("Strength",))
    return [_weighted(closure, weight, value.varying)]


def _metallic(node, weight, issues, compiler):
    """Blender 5's Metallic BSDF. With its F82 Fresnel it is Cycles' Principled metal (the base
    colour as f0, Edge Tint as the F82 tint, through the same bsdf_microfacet_setup_fresnel_f82_tint),
    so a Principled closure of metallic 1, its thin film too; Physical Conductor's IOR and extinction
    go through their F82-tint fit (core.bsdf.microfacet.conductor_f82), named in the warning, as is a
    film over it (Cycles' exact conductor film is not built)."""
    value = _Inputs(node, compiler, issues)
    conductor = getattr(node, "fresnel_type", "F82") == "PHYSICAL_CONDUCTOR"
    if conductor and value(0.0, "Thin Film Thickness") > 0.0:
        issues.add(f"'{node.name}' thin film over a Physical Conductor (not rendered yet)")
    if conductor:
        color, tint = conductor_f82(rgb(value(np.ones(3), "IOR")), rgb(value(np.zeros(3), "Extinction")))
        issues.add(f"'{node.name}' Physical Conductor (rendered through the F82-tint fit of its IOR and extinction)")
    else:
        color = rgb(value(0.8, "Base Color", field="color", kind="color"))
        tint = rgb(value(1.0, "Edge Tint", field="specular_tint", kind="color"))
    closure = Closure("PRINCIPLED", color=color, metallic=1.0, specular_tint=tint,
                      roughness=value(0.5, "Roughness", field="roughness", kind="float"),
                      multiscatter=_multiscatter(node, issues))
    if not conductor:
        _thin_film(node, closure, value, issues)
    value.anisotropy(closure, "Anisotropy", "Rotation")
    value.normal()
    return [_weighted(closure, weight, value.varying)]


def _hair(node, weight, issues, compiler):
    """The Hair BSDF: Cycles' reflection or transmission hair closure (its component) about the
    Tangent socket's direction, or on a mesh without one the triangle's dPdv with Offset 0, as
    Cycles' svm_node_closure_bsdf sets it for a surface that is not a curve."""
    value = _Inputs(node, compiler, issues)
    kind = "HAIR_TRANSMISSION" if getattr(node, "component", "Reflection") == "Transmission" else "HAIR_REFLECTION"
    closure = Closure(kind, color=rgb(value(0.8, "Color", field="color", kind="color")),
                      roughness=value(0.1, "RoughnessU", field="roughness", kind="float"),
                      hair_roughness_v=value(1.0, "RoughnessV", field="hair_roughness_v", kind="float"))
    socket = find_input(node, "Tangent")
    if socket is not None and socket.is_linked:
        closure.hair_offset = value(0.0, "Offset", field="hair_offset", kind="float")
        value.varying["hair_tangent"] = compiler.ref(compiler.value(socket, "vector"), "vector")
    else:
        value.varying["hair_tangent"] = compiler.triangle_edge("dpdv")
    return [_weighted(closure, weight, value.varying)]


PRINCIPLED_HAIR_MATCHED_FROM = (5, 0)
"""The first Blender whose Cycles computes the Principled Hair BSDF as DRT does (5.0's kernels):
4.2's Chiang renders the test spheres 25% brighter (its closure code differs in 150 lines); there the
node is named in the warning."""
VERSION_PRINCIPLED_HAIR = "Principled Hair BSDF: rendered as Cycles 5.0 computes it"
HUANG_NOTE = ("Huang hair model (rendered as Cycles computes it, but Cycles' own evaluation and sampling of it "
              "disagree in energy, so its image depends on how it picks and weighs light samples: measured equal "
              "to Cycles under a point light alone, up to 7% darker under an area light alone, up to 13% darker "
              "under both)")
"""Named wherever the Principled Hair BSDF's Huang model is used: its parity passes the noise limit, its
image means do not (tests/blender/test_hair_cycles.py)."""


def _principled_hair(node, weight, issues, compiler):
    """The Principled Hair BSDF on a mesh, as Cycles shades it there: about the triangle's dPdu, the
    node's Random socket in place of a strand's random value (core.bsdf.shader.principled_hair_lobe)."""
    value = _Inputs(node, compiler, issues)
    model = getattr(node, "model", "CHIANG")
    if bpy.app.version < PRINCIPLED_HAIR_MATCHED_FROM:
        issues.add(f"'{node.name}' {VERSION_PRINCIPLED_HAIR}")
    parametrization = getattr(node, "parametrization", "COLOR")  # Direct Coloring, Melanin, Absorption
    closure = Closure("PRINCIPLED_HAIR", hair_model=model, hair_parametrization=parametrization,
                      roughness=value(0.3, "Roughness", field="roughness", kind="float"),
                      radial_roughness=value(0.3, "Radial Roughness", field="radial_roughness", kind="float"),
                      hair_coat=value(0.0, "Coat", field="hair_coat", kind="float"),
                      ior=value(1.55, "IOR", field="ior", kind="float"),
                      hair_offset=value(np.radians(2.0), "Offset", field="hair_offset", kind="float"),
                      random_roughness=value(0.0, "Random Roughness", field="random_roughness", kind="float"),
                      hair_random=value(0.0, "Random", field="hair_random", kind="float"))
    if parametrization == "COLOR":
        closure.color = rgb(value(0.8, "Color", field="color", kind="color"))
    elif parametrization == "MELANIN":
        closure.melanin = value(0.8, "Melanin", field="melanin", kind="float")
        closure.melanin_redness = value(1.0, "Melanin Redness", field="melanin_redness", kind="float")
        closure.hair_tint = rgb(value(1.0, "Tint", field="hair_tint", kind="color"))
        closure.random_color = value(0.0, "Random Color", field="random_color", kind="float")
    else:
        closure.absorption = rgb(value(np.array([0.245531, 0.52, 1.365]), "Absorption Coefficient",
                                       field="absorption", kind="color"))
    if model == "HUANG":
        issues.add(f"'{node.name}' {HUANG_NOTE}")
        closure.aspect_ratio = value(0.85, "Aspect Ratio", field="aspect_ratio", kind="float")
        closure.hair_gains = np.array([value(1.0, name, field=field, kind="float") for name, field in
                                       (("R lobe", "r_gain"), ("TT lobe", "tt_gain"), ("TRT lobe", "trt_gain"))])
    value.varying["hair_tangent"] = compiler.triangle_edge("dpdu")
    return [_weighted(closure, weight, value.varying)]


def _holdout(node, weight, issues, compiler):
    """Cycles' Holdout closure: its weight is the share of the hit held out (core.integrator.holdout)."""
    return [_weighted(Closure("HOLDOUT"), weight, {})]


CLOSURE_NODES = {
    "ShaderNodeBsdfMetallic": _metallic,
    "ShaderNodeBsdfPrincipled": _principled,
    "ShaderNodeBsdfDiffuse": _bsdf("DIFFUSE"),
    "ShaderNodeBsdfGlossy": _bsdf("GLOSSY"),
    "ShaderNodeBsdfAnisotropic": _bsdf("GLOSSY"),
    "ShaderNodeBsdfGlass": _bsdf("GLASS"),
    "ShaderNodeBsdfRefraction": _bsdf("REFRACTION"),
    "ShaderNodeEmission": _emission,
    "ShaderNodeBsdfTransparent": _bsdf("TRANSPARENT"),
    "ShaderNodeBsdfTranslucent": _bsdf("TRANSLUCENT"),
    "ShaderNodeHoldout": _holdout,
    "ShaderNodeBsdfToon": _toon,
    "ShaderNodeBsdfSheen": _sheen,
    "ShaderNodeBsdfHair": _hair,
    "ShaderNodeBsdfHairPrincipled": _principled_hair,
}


def export_material(material, images: ImageTable, layer=None) -> tuple[Material, str | None]:
    """The material as closures, and a warning (or None) about what was approximated."""
    if not uses_nodes(material):
        color = np.array(material.diffuse_color[:3], dtype=np.float64)
        return Material(material.name, [Closure("DIFFUSE", color=color, roughness=0.0)],
                        pass_index=material.pass_index), None
    issues = Issues()
    compiler = Compiler(images, issues, layer=layer, pass_index=material.pass_index)

    def leaf(node, weight):
        make = CLOSURE_NODES.get(node.bl_idname)
        if make is None:
            issues.add(f"shader node '{node.name}' ({node.bl_label}, rendered as default grey)")
            return [_weighted(replace(c), weight, {}) for c in DEFAULT_MATERIAL.closures]
        return make(node, weight, issues, compiler)

    output = material.node_tree.get_output_node("CYCLES")
    closures = [] if output is None else flatten(output.inputs["Surface"], leaf, issues, compiler=compiler)
    displacement = None if output is None else _displacement(material, output, compiler, issues)
    unread_outputs(material.node_tree, output, issues)
    _one_tangent(closures, issues)
    aovs = aov_outputs(material.node_tree, compiler, None if layer is None else layer[1])
    varying = any(c.inputs for c in closures) or displacement is not None or any(is_ref(v) for _, v in aovs)
    return (Material(material.name, closures, compiler.program if varying else None, displacement,
                     pass_index=material.pass_index, aovs=aovs,
                     transparent_shadow=bool(getattr(material, "use_transparent_shadow", True)),
                     bump_shadowing=bump_shadowing_model(),
                     bump_correction=bool(getattr(getattr(material, "cycles", None), "use_bump_map_correction", True))),
            issues.message(f"Material '{material.name}'"))


def _one_tangent(closures, issues) -> None:
    """Name anisotropic closures whose tangents or rotations differ: a hit has one shading frame,
    along the first one's tangent (core.shading.surface), which the others are rendered with."""
    tangents = {(c.inputs["tangent"], c.inputs.get("anisotropic_rotation", c.anisotropic_rotation))
                for c in closures if "tangent" in c.inputs}
    if len(tangents) > 1:
        issues.add("anisotropic shaders with different tangents or rotations (rendered with the first one's)")


def aov_outputs(tree, compiler, view_layer) -> list:
    """(AOV name, value) of each AOV Output node writing an AOV of the view layer, in the tree or its
    node groups: its Color into a colour AOV, its Value into a value AOV (as Cycles' OutputAOVNode);
    a node naming no AOV of the view layer writes nothing, as in Cycles."""
    kinds = dict(view_layer_aovs(view_layer)) if view_layer is not None else {}
    out = []
    for node, groups in _aov_nodes(tree):
        kind = kinds.get(node.aov_name)
        if kind == "COLOR":
            value = compiler.value(node.inputs["Color"], "color", groups)
            out.append((node.aov_name, value if is_ref(value) else rgb(value)))
        elif kind == "VALUE":
            out.append((node.aov_name, compiler.value(node.inputs["Value"], "float", groups)))
    return out


def _aov_nodes(tree, groups=()):
    """(AOV Output node, the group nodes it sits inside, outermost first) in ``tree`` and, at any
    depth, the node groups it uses (each use of a group its own nodes, as Cycles inlines them)."""
    for node in tree.nodes:
        if node.bl_idname == "ShaderNodeOutputAOV":
            yield node, list(groups)
        elif node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None and not node.mute:
            yield from _aov_nodes(node.node_tree, groups + (node,))


VERSION_BUMP = "this Blender's bump of the displacement: rendered as Cycles 4.5+ bumps it"


def unread_outputs(tree, output, issues) -> None:
    """Name what Cycles renders from outside the Surface socket and DRT does not yet: a linked
    Volume socket."""
    volume = None if output is None else output.inputs.get("Volume")
    if volume is not None and volume.is_linked:
        issues.add(f"'{volume.links[0].from_node.name}' (a volume shader: volumes are not rendered yet)")


def _displacement(material, output, compiler, issues):
    """The output's Displacement as Cycles renders it with the material's method "Bump Only" (the
    default): a bump of the shading normal. Moving the surface itself ("Displacement Only", "Both")
    is not done: those render as bump, named in the warning."""
    socket = output.inputs.get("Displacement")
    if socket is None or not socket.is_linked:
        return None
    method = getattr(material, "displacement_method", "BUMP")
    if method != "BUMP":
        issues.add(f"displacement method {method.replace('_', ' ').title()} (rendered as Bump Only)")
    if bpy.app.version < DISPLACEMENT_MATCHED_FROM:
        issues.add(VERSION_BUMP)
    return compiler.displacement(socket)


class MaterialTable:
    """The scene's material list, each Blender material exported once.

    Index 0 is ``DEFAULT_MATERIAL``, used for empty slots and objects without
    materials, as Cycles uses its default surface.
    """

    def __init__(self, warnings: list[str], images: ImageTable, layer=None):
        self.materials = [DEFAULT_MATERIAL]
        self.warnings = warnings
        self.images = images
        self.layer = layer  # (scene, view layer) whose View Layer attributes the materials read
        self._index: dict[int, int] = {}

    def index(self, material) -> int:
        if material is None:
            return 0
        key = material.original.as_pointer()
        found = self._index.get(key)
        if found is None:
            exported, warning = export_material(material, self.images, self.layer)
            if warning:
                self.warnings.append(warning)
            found = self._index[key] = len(self.materials)
            self.materials.append(exported)
        return found
