"""No shader node is dropped silently: every node type this Blender defines that DRT does not
evaluate (export.coverage.left_out) is named in the material's warning when a material uses it,
and docs/shader-nodes.md's generated list is the one export.coverage gives (bench/node_coverage.py)."""
from __future__ import annotations

import bpy
import pytest

from bench import node_coverage
from drt_engine.blender.export import coverage
from tests.support.datablocks import new_material
from tests.support.export_helpers import add_object, cube_mesh, empty_scene, render_export


def _used(node_type: str):
    """A cube whose material uses a node of ``node_type`` as Cycles would read it: a shader into
    Surface (a volume shader into Volume), any other output into an Emission's Color; the node's
    name, or None for a node with nothing to connect."""
    scene = empty_scene()
    material = new_material(node_type)
    tree = material.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    node = tree.nodes.new(node_type)
    node.name = f"the {node_type}"
    shader = next((s for s in node.outputs if s.type == "SHADER"), None)
    if shader is not None:
        target = out.inputs["Volume"] if "Volume" in node_type else out.inputs["Surface"]
        tree.links.new(shader, target)
    elif node.outputs:
        emission = tree.nodes.new("ShaderNodeEmission")
        tree.links.new(node.outputs[0], emission.inputs["Color"])
        tree.links.new(emission.outputs[0], out.inputs["Surface"])
    else:
        return scene, None
    add_object(scene, "Cube", cube_mesh()).data.materials.append(material)
    return scene, node.name


@pytest.mark.parametrize("node_type", coverage.left_out())
def test_a_node_drt_leaves_out_is_named_in_the_warning(drt, node_type):
    scene, name = _used(node_type)
    if name is None:
        pytest.skip(f"{node_type} has no output to use without further set-up (a Script node without a script)")
    warnings = render_export(scene).warnings
    assert any(f"'{name}'" in w for w in warnings), warnings


def test_the_evaluated_nodes_are_not_named(drt):
    scene, name = _used("ShaderNodeTexChecker")
    assert not render_export(scene).warnings


def test_the_docs_list_is_the_one_coverage_gives():
    """Regenerate with `.venv/bin/python bench/node_coverage.py` when a node gains or loses a handler."""
    written = node_coverage.read_block()
    if f"Blender {bpy.app.version_string}" not in written:
        pytest.skip(f"the list is written for another Blender than {bpy.app.version_string}")
    assert written == node_coverage.block()
