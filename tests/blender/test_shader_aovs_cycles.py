"""Shader AOVs against Cycles: a floor, a sphere and a box under a perspective camera; the view layer
has a colour AOV "col", a value AOV "val" and a value AOV "unused" no material writes. The sphere
writes constants into both (and into "elsewhere", an AOV the view layer does not have, which Cycles
ignores); the floor writes a Checker texture's colour into "col" and a Noise texture's Fac into
"val"; the box writes nothing; the (black) world writes a colour into "col"; a pane 30% opaque in
front writes constants, and so does what its pixels see through it, in the share of Cycles' samples
its closure sampling sends through.

Each AOV follows the node parity's rule (procedural_scenes.parity): DRT's worst 4x4-block
difference from Cycles (seed 0) at most 1.5x Cycles' own between seeds 0 and 1, plus 0.002. Where
Cycles' image holds one value over a pixel's 3x3 neighbourhood (a constant seen by every sample,
away from edges and checker lines) DRT's pixel must be that value.
"""
from __future__ import annotations

import subprocess
import sys

import bpy
import numpy as np
import pytest

from drt_engine.core.integrator import integrator as integrator_module
from drt_engine.core.integrator.integrator import Integrator
from tests.support import procedural_scenes as ps
from tests.support import render_helpers as rh
from tests.support.datablocks import new_material
from tests.support.export_helpers import render_export

WIDTH, HEIGHT = 48, 32
SAMPLES = 16
AOVS = (("col", "COLOR"), ("val", "VALUE"), ("unused", "VALUE"))
SPHERE_COLOR, SPHERE_VALUE = (0.2, 0.6, 0.3), 0.8
VEIL_ALPHA = 0.3  # under the view layer's alpha threshold: what is behind writes too
WORLD_COLOR = (0.05, 0.1, 0.15)


def _aov(tree, name, color=None, value=None):
    """An AOV Output node writing ``name``: constants, or the given node outputs."""
    node = tree.nodes.new("ShaderNodeOutputAOV")
    node.aov_name = name
    for socket, given in (("Color", color), ("Value", value)):
        if isinstance(given, bpy.types.NodeSocket):
            tree.links.new(given, node.inputs[socket])
        elif given is not None:
            node.inputs[socket].default_value = (*given, 1.0) if socket == "Color" else given
    return node


def _material(name, color):
    mat = new_material(name)
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    return mat


def aov_scene():
    scene = ps._scene(WIDTH, HEIGHT)
    ps.aim(scene.camera, (0.0, -8.0, 4.0))
    scene.camera.data.lens = 35.0
    ps.black_world(scene)
    floor, sphere, box = (_material("Floor", (0.5, 0.5, 0.5)), _material("Sphere", (0.8, 0.1, 0.1)),
                          _material("Box", (0.1, 0.3, 0.8)))
    tree = floor.node_tree
    coords = tree.nodes.new("ShaderNodeTexCoord")
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 1.0
    checker.inputs["Color1"].default_value = (0.9, 0.2, 0.1, 1.0)
    checker.inputs["Color2"].default_value = (0.1, 0.3, 0.9, 1.0)
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 0.8
    for texture in (checker, noise):
        tree.links.new(coords.outputs["Object"], texture.inputs["Vector"])
    _aov(tree, "col", color=checker.outputs["Color"])
    _aov(tree, "val", value=noise.outputs["Fac"])
    _aov(sphere.node_tree, "col", color=SPHERE_COLOR, value=0.3)
    _aov(sphere.node_tree, "val", color=(1.0, 1.0, 1.0), value=SPHERE_VALUE)
    _aov(sphere.node_tree, "elsewhere", color=(1.0, 1.0, 1.0), value=1.0)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, floor, size=12.0)
    ps.add_primitive(bpy.ops.mesh.primitive_uv_sphere_add, sphere, radius=1.0, location=(-1.2, 0.0, 1.0))
    ps.add_primitive(bpy.ops.mesh.primitive_cube_add, box, size=1.4, location=(1.5, 0.5, 0.7))
    veil = _material("Veil", (0.2, 0.7, 0.2))
    veil.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = VEIL_ALPHA
    _aov(veil.node_tree, "col", color=(0.9, 0.9, 0.2))
    _aov(veil.node_tree, "val", value=0.1)
    ps.add_primitive(bpy.ops.mesh.primitive_plane_add, veil, size=1.6, location=(0.0, -2.5, 1.2), rotation=(1.2, 0.0, 0.0))
    _aov(scene.world.node_tree, "col", color=WORLD_COLOR)
    layer = scene.view_layers[0]
    for name, kind in AOVS:
        aov = layer.aovs.add()
        aov.name, aov.type = name, kind
    return scene


def renders(scene, tmp_path, name):
    """DRT seed 0, Cycles seeds 0 and 1 (procedural_scenes.RUNS), with the view layer's AOVs."""
    return [rh.render(scene, engine, SAMPLES, seed, tmp_path, name=name) for engine, seed in ps.RUNS]


def interior(drt, cycles) -> dict:
    """Pixels whose 3x3 neighbourhood has one value in Cycles' image (the pixel filter reaches 1.5
    pixels): how many, and how many of them DRT gives otherwise."""
    h, w, _ = cycles.shape
    pad = np.pad(cycles, ((1, 1), (1, 1), (0, 0)), mode="edge")
    same = np.ones((h, w), bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= np.all(np.abs(pad[dy:dy + h, dx:dx + w] - cycles) <= 1e-6, axis=-1)
    return {"interior": int(same.sum()), "differ": int((np.abs(drt - cycles) > 1e-5).any(axis=-1)[same].sum())}


@pytest.mark.parametrize("name", [name for name, _ in AOVS])
def test_aovs_match_cycles(drt, name, tmp_path):
    drt_r, c0, c1 = renders(aov_scene(), tmp_path, f"aov-{name}")
    figures = ps.parity(drt_r.passes[name], c0.passes[name], c1.passes[name])
    figures.update(interior(drt_r.passes[name], c0.passes[name]))
    print(f"AOV {name}: {figures}")
    assert figures["ok"], ps.message(f"AOV {name}", figures)
    assert figures["differ"] == 0, figures
    if name == "unused":
        assert np.all(drt_r.passes[name] == 0.0) and np.all(c0.passes[name] == 0.0)
    else:
        assert figures["interior"] > 100 and np.ptp(c0.passes[name]) > 0.5  # the scene shows them


def test_the_comparisons_fail_without_the_computation(drt, monkeypatch, tmp_path):
    """With DRT's AOV writes switched off, both written AOVs fail the comparisons above."""
    scene = aov_scene()
    _, c0, c1 = renders(scene, tmp_path, "off")
    monkeypatch.setattr(Integrator, "_shader_aovs", lambda *args: None)
    off = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="off-drt")
    for name in ("col", "val"):
        assert not ps.parity(off.passes[name], c0.passes[name], c1.passes[name])["ok"], name


def test_behind_the_pane_fails_in_the_throughput_share(drt, monkeypatch, tmp_path):
    """What is seen through the pane weighed by the transparency DRT's throughput carries (no
    correction to Cycles' share) fails the comparison."""
    scene = aov_scene()
    _, c0, c1 = renders(scene, tmp_path, "share")
    monkeypatch.setattr(integrator_module, "reach_scale", lambda shader, group, rows: np.ones(len(rows)))
    wrong = rh.render(scene, "DRT", SAMPLES, 0, tmp_path, name="share-drt")
    assert not ps.parity(wrong.passes["col"], c0.passes["col"], c1.passes["col"])["ok"]


def test_what_the_export_writes_and_names(drt):
    """The sphere's AOV Output nodes become its writes (the view layer's AOVs only, a colour AOV from
    the node's Color, a value AOV from its Value), the floor's come from its program, the box's from
    inside a node group (its Value from the group node's input), and no material is named in a
    warning; the world's constant is its write, its textured one is named (not written yet)."""
    scene = aov_scene()
    tree = scene.world.node_tree
    _aov(tree, "val", value=tree.nodes.new("ShaderNodeTexNoise").outputs["Fac"])
    box = bpy.data.materials["Box"]
    group = bpy.data.node_groups.new("Grouped", "ShaderNodeTree")
    group.interface.new_socket("Amount", in_out="INPUT", socket_type="NodeSocketFloat")
    grouped = _aov(group, "val", value=0.5)
    group.links.new(group.nodes.new("NodeGroupInput").outputs["Amount"], grouped.inputs["Value"])
    user = box.node_tree.nodes.new("ShaderNodeGroup")
    user.node_tree = group
    user.inputs["Amount"].default_value = 0.25
    data = render_export(scene)
    materials = {m.name: m for m in data.materials}
    sphere = dict(materials["Sphere"].aovs)
    assert set(sphere) == {"col", "val"} and np.allclose(sphere["col"], SPHERE_COLOR)
    assert sphere["val"] == pytest.approx(SPHERE_VALUE)
    floor = materials["Floor"]
    assert floor.program is not None and all(isinstance(v, tuple) for _, v in floor.aovs)
    assert materials["Box"].aovs == [("val", pytest.approx(0.25))]
    assert [name for name, _ in data.world.aovs] == ["col"] and np.allclose(data.world.aovs[0][1], WORLD_COLOR)
    named = " ".join(data.warnings)
    assert "AOV Output of 'val' from a texture in a world" in named and "Material" not in named, data.warnings


def test_the_cli_writes_them_and_its_merged_parts_equal_the_single_render(drt, tmp_path):
    """The CLI's EXR (Blender's render result) holds the AOVs, and two sample ranges merged (the
    farm's path: parts, merge, the merged EXR) give the single render's AOVs."""
    blend = tmp_path / "aovs.blend"
    aov_scene().render.engine = "DRT"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    options = ["--samples", "6", "--seed", "2", "--engine-threads", "1"]

    def cli(out, *extra):
        result = subprocess.run([sys.executable, "-m", "drt_engine", "render", str(blend), "-o", str(out), *options,
                                 *extra], cwd=rh.ROOT, capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr
        return out

    single = rh.read_channels(cli(tmp_path / "single.exr"))
    parts = [cli(tmp_path / f"part{i}.exr", "--sample-range", r) for i, r in enumerate(("0:2", "2:6"))]
    merged = subprocess.run([sys.executable, "-m", "drt_engine", "merge", *map(str, parts), "-o",
                             str(tmp_path / "merged.exr")], cwd=rh.ROOT, capture_output=True, text=True, timeout=300)
    assert merged.returncode == 0, merged.stderr
    merged = rh.read_channels(tmp_path / "merged.exr")
    names = [f"ViewLayer.{name}.{c}" for name, kind in AOVS for c in ("RGBA" if kind == "COLOR" else "X")]
    assert set(names) <= set(single) and set(names) <= set(merged), sorted(single)
    assert single["ViewLayer.col.A"].max() > 1.5 and single["ViewLayer.val.X"].max() > 0.5  # through the pane too
    for name in names:
        scale = np.maximum(np.abs(single[name]), np.abs(merged[name]))
        assert np.all(np.abs(single[name] - merged[name]) <= 1e-6 * scale), name
