"""The world: Background colour x strength, constant or from shader nodes per direction.

Mix and Add Shader are flattened; a World without a node tree uses ``world.color`` as
Cycles does; no world at all is black. A Background whose colour or strength comes from
nodes (an Environment Texture through Mapping, say) becomes a program the core evaluates
per ray direction and importance samples. Ray visibility: Camera, Diffuse, Glossy and
Transmission. The world's mist settings go with it (the Mist pass reads them, as Cycles' film does).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...core.scene import World
from .materials import aov_outputs, unread_outputs, uses_nodes
from .nodes import Issues, flatten, rgb
from .shader_graph import Compiler, ImageTable, is_ref

EMITTERS = ("ShaderNodeBackground", "ShaderNodeEmission")


def _constant_aovs(tree, compiler, view_layer, issues) -> list:
    """The world's AOV Output writes (export.materials.aov_outputs) of constant values; one fed by a
    texture is named in the warning and not written."""
    out = []
    for name, value in aov_outputs(tree, compiler, view_layer):
        if is_ref(value):
            issues.add(f"AOV Output of '{name}' from a texture in a world (not written yet)")
        else:
            out.append((name, value))
    return out


def _visibility(world) -> dict:
    vis = world.cycles_visibility
    return {"visible_camera": vis.camera, "visible_diffuse": vis.diffuse, "visible_glossy": vis.glossy,
            "visible_transmission": vis.transmission}


MIST_FALLOFF = {"QUADRATIC": 2.0, "LINEAR": 1.0, "INVERSE_QUADRATIC": 0.5}
"""Blender's mist falloff as the exponent Cycles raises the mist ramp to."""


def export_world(world, warnings: list[str], images: ImageTable, view_layer=None) -> World:
    if world is None:
        return World()
    mist = world.mist_settings
    return replace(_background(world, warnings, images, view_layer), mist_start=float(mist.start),
                   mist_depth=float(mist.depth), mist_falloff=MIST_FALLOFF[mist.falloff])


def _background(world, warnings: list[str], images: ImageTable, view_layer=None) -> World:
    if not uses_nodes(world):
        return World(radiance=world.color[:3])
    output = world.node_tree.get_output_node("CYCLES")
    if output is None:
        return World()
    issues = Issues()
    compiler = Compiler(images, issues, world=True)

    def leaf(node, weight):
        if node.bl_idname not in EMITTERS:
            issues.add(f"shader node '{node.name}'")
            return []
        return [compiler.emitted(node, weight)]

    parts = flatten(output.inputs["Surface"], leaf, issues, compiler=compiler)
    unread_outputs(world.node_tree, output, issues)
    visibility = dict(_visibility(world), aovs=_constant_aovs(world.node_tree, compiler, view_layer, issues))
    message = issues.message(f"World '{world.name}'")
    if message:
        warnings.append(message)
    if not any(is_ref(p) for p in parts):
        radiance = np.sum([rgb(p) for p in parts], axis=0) if parts else np.zeros(3)
        return World(radiance=radiance, **visibility)
    return World(program=compiler.program, color=compiler.add_all(parts), **visibility)
