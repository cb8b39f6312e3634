"""Image sequences: an Image Texture showing a numbered sequence of files renders, at each frame,
the file Cycles renders there (the image user's Start Frame, Offset, Frames and Cyclic as Blender
counts them); an environment sequence too. Each frame's file is one flat colour, so the frame shown
is read off the plane's centre."""
from __future__ import annotations

from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from drt_engine.blender.export import image_sequence, shader_graph
from tests.blender.test_textures_export import diffuse_from, image_node, textured_scene
from tests.support import render_helpers as rh
from tests.support.export_helpers import render_export
from tests.support.textured_scenes import write_image

FRAMES = 5
CASES = [  # scene frame, the user's Start Frame, Offset, Frames, Cyclic; the file shown
    (3, 1, 0, 5, False, 3),
    (6, 5, 2, 5, False, 4),  # counted from the start frame, then offset
    (8, 1, 0, 3, True, 2),  # cyclic over 3 frames
    (12, 1, 0, 5, False, 5),  # past the last frame: held there
    (0, 1, 1, 5, False, 1),  # before the first: frame 0, offset to 1
    (-3, 1, 0, 4, True, 1),  # cyclic backwards
    (4, 1, -1, 5, True, 3),
]


def red(number: int) -> float:
    return number / 10


@pytest.fixture
def first_file(tmp_path):
    """The sequence's files written, the first one's path."""
    for n in range(1, FRAMES + 1):
        pixels = np.zeros((4, 4, 3), np.float32)
        pixels[..., 0], pixels[..., 1] = red(n), 0.5
        write_image(tmp_path / f"seq.{n:04d}.exr", pixels)
    return tmp_path / "seq.0001.exr"


def load_sequence(path):
    """The sequence as an image (after the scene is made: making it empties Blender's data)."""
    image = bpy.data.images.load(str(path))
    image.source = "SEQUENCE"
    return image


def _set(scene, user, frame, start, offset, frames, cyclic):
    scene.frame_set(frame)
    user.frame_start, user.frame_offset, user.frame_duration, user.use_cyclic = start, offset, frames, cyclic


def test_each_frame_shows_the_file_cycles_shows(drt, first_file, tmp_path):
    scene, mat = textured_scene()
    sequence = load_sequence(first_file)
    nodes = []
    diffuse_from(mat, lambda tree: nodes.append(image_node(tree, sequence)) or nodes[0].outputs["Color"])
    user = nodes[0].image_user
    for *settings, shown in CASES:
        _set(scene, user, *settings)
        assert not render_export(scene).warnings
        centre = {engine: rh.render(scene, engine, 1, 0, tmp_path, name="seq").rgb[8, 8]
                  for engine in ("DRT", "CYCLES")}
        assert centre["CYCLES"][0] == pytest.approx(red(shown), abs=1e-3), (settings, centre)
        assert np.allclose(centre["DRT"], centre["CYCLES"], atol=1e-3), (settings, centre)


def test_an_environment_sequence_lights_by_its_frame(drt, first_file):
    scene, _ = textured_scene()
    sequence = load_sequence(first_file)
    tree = scene.world.node_tree
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = sequence
    tree.links.new(env.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    _set(scene, env.image_user, 4, 1, 0, 5, False)
    data = render_export(scene)
    assert not data.warnings and data.images[0].path.endswith("seq.0004.exr")


def test_a_sequence_without_openimageio_keeps_the_file_of_its_frame(first_file, monkeypatch):
    """Without OpenImageIO a file image falls back to the pixels Blender has loaded; a sequence's
    may be another frame's, so the shown frame's file is kept (the core then renders magenta and
    names why). The bpy module never holds a sequence's pixels, so a stand-in image that does."""
    image = SimpleNamespace(source="SEQUENCE", packed_file=None, size=(4, 4), filepath=str(first_file),
                            library=None, name="seq", is_float=True, as_pointer=lambda: 1,
                            colorspace_settings=SimpleNamespace(name="Non-Color"),
                            pixels=SimpleNamespace(foreach_get=lambda out: out.fill(0.5)))
    user = SimpleNamespace(frame_duration=5, frame_start=1, frame_offset=0, use_cyclic=False)
    monkeypatch.setattr(shader_graph, "openimageio_available", lambda: False)
    table = shader_graph.ImageTable([], 4)
    exported = table.images[table.index(image, user)]
    assert exported.pixels is None and exported.path.endswith("seq.0004.exr")


@pytest.mark.parametrize("path, number, expected", [
    ("/a/seq.0001.exr", 12, "/a/seq.0012.exr"),
    ("/a/seq.0001.exr", 12345, "/a/seq.12345.exr"),
    ("/a/seq.0001.exr", -2, "/a/seq.0000.exr"),  # Blender writes a negative frame as 0
    ("/a/shot_7_final.png", 3, "/a/shot_3_final.png"),  # the last digits before the extension
    ("/a/plate.png", 5, "/a/plate5.png"),
    ("/a/plate.png", 0, "/a/plate.png"),
    ("/2024/take.01.tif", 2, "/2024/take.02.tif"),  # the folder's digits are not the frame's
])
def test_frame_path_replaces_the_last_digits_of_the_name(path, number, expected):
    assert image_sequence.frame_path(path, number) == expected
