"""Reading constant values out of shader node trees, and flattening Mix/Add Shader.

The tracer evaluates constant closures only. A linked input is followed through
reroutes to a constant node (RGB, Value); anything else falls back to the socket's
default value and is recorded as an issue, so the caller can warn once per
material or world.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.base.colour import LUMINANCE

CONSTANT_NODES = ("ShaderNodeRGB", "ShaderNodeValue")


@dataclass
class Issues:
    """What a tree uses that the tracer cannot evaluate, gathered for one warning."""

    items: set[str] = field(default_factory=set)

    def add(self, text: str) -> None:
        self.items.add(text)

    def message(self, owner: str) -> str | None:
        if not self.items:
            return None
        details = "; ".join(sorted(self.items))
        return (f"{owner} uses what DRT cannot evaluate yet ({details}): each takes its default value unless "
                "its note says how it is rendered")


def find_input(node, *names):
    """The input socket with one of ``names`` (identifier first, then label), or None."""
    for name in names:
        for socket in node.inputs:
            if socket.identifier == name and socket.enabled:
                return socket
        socket = node.inputs.get(name)
        if socket is not None and socket.enabled:
            return socket
    return None


def linked_from(socket):
    """The (node, output socket) feeding ``socket`` through reroutes, or None."""
    found = follow(socket)
    return None if found is None or found[0] is None else found[:2]


def follow(socket, groups=()):
    """(node, output socket, group stack) feeding ``socket`` through reroutes and, inside the
    group nodes ``groups`` (outermost first), out through their Group Input nodes; node None
    for an unlinked input of a group node (``socket`` is then that input); None when nothing
    feeds it."""
    stack = list(groups)
    while socket.is_linked:
        link = socket.links[0]
        if link.is_muted or not link.is_valid:
            return None
        node = link.from_node
        if node.bl_idname == "NodeReroute":
            socket = node.inputs[0]
            continue
        if node.bl_idname == "NodeGroupInput" and stack:
            group = stack.pop()
            outer = next((s for s in group.inputs if s.identifier == link.from_socket.identifier), None)
            if outer is None:
                return None
            if not outer.is_linked:
                return None, outer, stack
            socket = outer
            continue
        return node, link.from_socket, stack
    return None


def _constant(value) -> float | np.ndarray:
    if isinstance(value, (int, float)):
        return float(value)
    return np.array(value[:], dtype=np.float64)


def socket_value(socket, issues: Issues):
    """Constant value of an input socket: float, or an array for colours and vectors."""
    source = linked_from(socket)
    if source is not None:
        node, output = source
        if node.bl_idname in CONSTANT_NODES:
            value = _constant(output.default_value)
            return _coerce(value, socket)
        issues.add(f"'{socket.node.name}' input '{socket.name}' linked to '{node.name}'")
    return _constant(socket.default_value)




def _coerce(value, socket):
    """Match the value's shape to the socket, converting as Blender's implicit conversions do."""
    target = socket.default_value
    if isinstance(target, (int, float)):
        return float(LUMINANCE @ value[:3]) if isinstance(value, np.ndarray) else value
    if isinstance(value, float):
        return np.full(len(target), value)
    return value[: len(target)]


def input_value(node, issues: Issues, default, *names):
    """Value of the first present input among ``names``; ``default`` if none exists."""
    socket = find_input(node, *names)
    if socket is None:
        return default
    return socket_value(socket, issues)


def rgb(value) -> np.ndarray:
    """First three channels of a colour value (a float becomes grey)."""
    if isinstance(value, float):
        return np.full(3, value)
    return np.asarray(value, dtype=np.float64)[:3]


def report_linked_inputs(node, issues: Issues, ignored=("Weight",)) -> None:
    """Record linked inputs a closure node has but the tracer does not read (normal maps...)."""
    for socket in node.inputs:
        if socket.type == "SHADER" or socket.name in ignored or not socket.enabled:
            continue
        source = linked_from(socket)
        if source is not None and source[0].bl_idname not in CONSTANT_NODES:
            issues.add(f"'{node.name}' input '{socket.name}' linked to '{source[0].name}'")


def flatten(socket, leaf, issues: Issues, weight=None, compiler=None) -> list:
    """Walk Mix and Add Shader nodes down from ``socket`` into weighted leaves.

    ``leaf(node, weight)`` turns a closure node into a list of closures with
    ``weight`` (RGB) applied. An unconnected shader socket contributes nothing, as
    in Cycles. With a ``compiler`` (shader_graph.Compiler) a Mix Shader factor may vary
    over the surface: the weight is then a reference into its program.
    """
    weight = np.ones(3) if weight is None else weight
    source = linked_from(socket)
    if source is None:
        return []
    node, output = source
    if node.mute:  # Blender passes a muted node's matching input through, if it has one
        inputs = [link.from_socket for link in node.internal_links if link.to_socket == output]
        return flatten(inputs[0], leaf, issues, weight, compiler) if inputs else []
    kind = node.bl_idname
    if kind == "ShaderNodeMixShader":
        shaders = [s for s in node.inputs if s.type == "SHADER"]
        if compiler is None:
            fac = float(np.clip(input_value(node, issues, 0.5, "Fac", "Factor"), 0.0, 1.0))
            first, second = weight * (1.0 - fac), weight * fac
        else:
            fac = compiler.clamp01(compiler.value(find_input(node, "Fac", "Factor"), "float"))
            first, second = compiler.scale(weight, compiler.one_minus(fac)), compiler.scale(weight, fac)
        return flatten(shaders[0], leaf, issues, first, compiler) + flatten(shaders[1], leaf, issues, second,
                                                                            compiler)
    if kind == "ShaderNodeAddShader":
        shaders = [s for s in node.inputs if s.type == "SHADER"]
        return flatten(shaders[0], leaf, issues, weight, compiler) + flatten(shaders[1], leaf, issues, weight,
                                                                             compiler)
    return leaf(node, weight)
