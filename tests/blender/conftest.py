"""Fixtures for the Blender layer: DRT registered in this bpy session, tiny scenes, EXR channels.

The scenes are chosen so the right image is known exactly: a camera 5 m above an
emissive plane that fills the view sees the emission strength at every pixel and a
depth of 5 m, whatever the sampling.
"""
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

import drt_engine
from drt_engine.blender.engine import DRTRenderEngine
from drt_engine.blender.properties import result_pass_name
from drt_engine.core.settings import PASS_CHANNELS
from drt_engine.headless.cli import exit_now
from tests.support import sample_scene_files
from tests.support.datablocks import new_material, new_world
from tests.support.render_helpers import read_channels, set_exr_output

CAMERA_HEIGHT = 5.0
_EXIT_STATUS = pytest.StashKey[int]()


def drt_is_registered() -> bool:
    return DRTRenderEngine.is_registered


@pytest.fixture(scope="session")
def drt():
    """DRT registered for the session (tests that unregister it register it again)."""
    if not drt_is_registered():
        drt_engine.register()
    yield
    if drt_is_registered():
        drt_engine.unregister()


def pytest_sessionfinish(session, exitstatus):
    session.config.stash[_EXIT_STATUS] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    """Under the bpy 4.2 module, end the test session here with pytest's own status.

    That module crashes (SIGSEGV, exit 139) while Python tears it down once a property with an
    update callback was registered, as DRT's are, after every test has passed or failed: the
    status must be the tests'. The CLI ends the same way (drt_engine.headless.cli.exit_now).
    """
    if bpy.app.version[:2] == (4, 2) and _EXIT_STATUS in config.stash:
        exit_now(config.stash[_EXIT_STATUS])


@pytest.fixture(scope="session")
def sample_scene(tmp_path_factory):
    """``sample_scene(name)``: the path of that sample scene's .blend for this Blender to open; the
    committed file, or under Blender 4.x a copy built by its script (once per session)."""
    folder = tmp_path_factory.mktemp("sample_scenes")

    def path(name: str) -> Path:
        if sample_scene_files.OPENS_COMMITTED_FILES:
            return sample_scene_files.SCENES_DIR / f"{name}.blend"
        target = folder / f"{name}.blend"
        return target if target.exists() else sample_scene_files.build(name, target)

    return path


def _plane_mesh(name: str, half: float):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)], [], [(0, 1, 2, 3)])
    mesh.update()
    return mesh


def emission_material(strength: float, color=(1.0, 1.0, 1.0)):
    mat = new_material("Emitter")
    tree = mat.node_tree
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*color, 1.0)
    emission.inputs["Strength"].default_value = strength
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return mat


def set_world(scene, color=(0.0, 0.0, 0.0), strength=1.0):
    world = scene.world or new_world("World")
    scene.world = world
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    return world


def emission_scene(width=16, height=12, strength=2.0, world=(0.0, 0.0, 0.0), samples=4):
    """Factory-empty scene rendered by DRT: camera at z=5 looking down at a 4x4 m emitter.

    The emitter lives in the collection "Subject" so a view layer can exclude it.
    """
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    render = scene.render
    render.engine = "DRT"
    render.resolution_x, render.resolution_y = width, height
    render.resolution_percentage = 100
    scene.drt.samples = samples
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, 0.0, CAMERA_HEIGHT)
    scene.collection.objects.link(camera)
    scene.camera = camera
    subject = bpy.data.collections.new("Subject")
    scene.collection.children.link(subject)
    plane = bpy.data.objects.new("Emitter", _plane_mesh("Emitter", 2.0))
    plane.data.materials.append(emission_material(strength))
    subject.objects.link(plane)
    set_world(scene, world)
    return scene


def render_exr(scene, path) -> dict:
    """Render ``scene`` with bpy.ops.render.render, write a multilayer EXR, read its channels back."""
    set_exr_output(scene, path)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return read_channels(path)


def pass_pixels(channels: dict, layer: str, name: str) -> np.ndarray:
    """(h, w, C) pixels of one pass of one view layer (by DRT's name), channels in PASS_CHANNELS order."""
    names = [f"{layer}.{result_pass_name(name)}.{c}" for c in PASS_CHANNELS[name]]
    missing = [key for key in names if key not in channels]
    assert not missing, f"channels {missing} not in the file: {sorted(channels)}"
    return np.stack([channels[key] for key in names], axis=-1)


def passes_in(channels: dict, layer: str) -> set:
    """Pass names present for one view layer."""
    return {key[len(layer) + 1:].rsplit(".", 1)[0] for key in channels if key.startswith(layer + ".")}


@pytest.fixture
def bl(drt):
    """The helpers above, for test modules (conftest is not importable by name)."""
    return SimpleNamespace(
        emission_scene=emission_scene,
        emission_material=emission_material,
        set_world=set_world,
        read_channels=read_channels,
        render_exr=render_exr,
        pass_pixels=pass_pixels,
        passes_in=passes_in,
        camera_height=CAMERA_HEIGHT,
    )
