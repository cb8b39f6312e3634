"""Which of the running Blender's shader nodes DRT evaluates, read from the export's own handlers:
the shader-graph compiler's node methods, the closure table, the world's emitters and the nodes
the export walks through. Every other node Cycles renders is left out, and the export names it in
the material's (or world's) warning where it is used, since it has no handler either: its socket
keeps its own value, a closure renders default grey. docs/shader-nodes.md's list is written from
here (bench/node_coverage.py), so it and the warnings come from one place.
"""
from __future__ import annotations

import bpy

from .materials import CLOSURE_NODES
from .shader_graph import Compiler
from .world import EMITTERS

STRUCTURE = ("ShaderNodeMixShader", "ShaderNodeAddShader", "ShaderNodeOutputMaterial", "ShaderNodeOutputWorld",
             "ShaderNodeOutputLight", "ShaderNodeOutputAOV")
"""Nodes the export walks through rather than evaluates (a material's AOV Output: its inputs become the
material's AOV writes, export.materials.aov_outputs)."""

NOT_IN_CYCLES = ("ShaderNodeEeveeSpecular", "ShaderNodeShaderToRGB", "ShaderNodeOutputLineStyle",
                 "ShaderNodeUVAlongStroke", "ShaderNodeCustomGroup")
"""EEVEE's and Freestyle's own nodes, and the base of Python-defined groups: Cycles renders none."""


def shader_node_types() -> list[str]:
    """The bl_idname of every shader node type this Blender defines."""
    return sorted(name for name in dir(bpy.types) if name.startswith("ShaderNode") and name != "ShaderNode"
                  and isinstance(getattr(bpy.types, name), type) and issubclass(getattr(bpy.types, name),
                                                                               bpy.types.ShaderNode))


def evaluated() -> set[str]:
    """The node types DRT evaluates (textures, colour, vector and input nodes) or renders as closures."""
    return {name[len("_node_"):] for name in dir(Compiler) if name.startswith("_node_")} | set(CLOSURE_NODES) \
        | set(EMITTERS)


def left_out() -> list[str]:
    """The shader node types of this Blender that Cycles renders and DRT does not yet."""
    done = evaluated() | set(STRUCTURE) | set(NOT_IN_CYCLES)
    return [name for name in shader_node_types() if name not in done]


def label(name: str) -> str:
    """The node type's name as Blender's Add menu shows it."""
    return getattr(bpy.types, name).bl_rna.name
