"""The world as a uniform environment: Background colour × strength.

Mix and Add Shader with constant factors are flattened; a World without a node
tree uses ``world.color`` as Cycles does; no world at all is black.
"""
from __future__ import annotations

import numpy as np

from ...core.scene import World
from .materials import uses_nodes
from .nodes import Issues, flatten, input_value, report_linked_inputs, rgb

EMITTERS = ("ShaderNodeBackground", "ShaderNodeEmission")


def export_world(world, warnings: list[str]) -> World:
    if world is None:
        return World()
    if not uses_nodes(world):
        return World(radiance=world.color[:3])
    output = world.node_tree.get_output_node("CYCLES")
    if output is None:
        return World()
    issues = Issues()

    def leaf(node, weight):
        if node.bl_idname not in EMITTERS:
            issues.add(f"shader node '{node.name}'")
            return []
        report_linked_inputs(node, issues)
        color = rgb(input_value(node, issues, 0.05, "Color"))
        return [weight * color * input_value(node, issues, 1.0, "Strength")]

    parts = flatten(output.inputs["Surface"], leaf, issues)
    message = issues.message(f"World '{world.name}'")
    if message:
        warnings.append(message)
    return World(radiance=np.sum(parts, axis=0) if parts else np.zeros(3))
