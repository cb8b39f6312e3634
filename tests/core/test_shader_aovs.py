"""Shader AOVs against closed forms (core.integrator.aovs): an orthographic camera looks down on quad A
(height 0, under x < 0.5) and quad B (height 4, under 0 < x < 0.5), the background beyond, a box filter
one pixel wide, so every sample of a pixel sees one quad. A writes a constant colour and a value from
a checker texture whose cells are two pixels wide (so each pixel reads 0 or 1); B writes another
colour; an AOV no material writes is a pass of zeros; parts merge into the whole render's AOVs."""
import numpy as np
import OpenImageIO as oiio
import pytest

from drt_engine.core.errors import SettingsError
from drt_engine.core.film import parts
from drt_engine.core.integrator.integrator import Integrator
from drt_engine.core.render import merge
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, Program, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.core_cases import rendered_part
from tests.support.scenes import translation

RES = 16
AOVS = (("col", "COLOR"), ("val", "VALUE"), ("unwritten", "VALUE"))
A_COLOR, B_COLOR = np.array([0.2, 0.5, 0.8]), np.array([1.0, 0.0, 0.0])
WORLD_COLOR = np.array([0.05, 0.1, 0.15])
CHECKER_SCALE = 4.0  # cells 0.25 wide: two pixels of the 2 x 2 window's 16


def quad(x0, x1, z, material):
    v = np.array([[x0, -1.5, z], [x1, -1.5, z], [x1, 1.5, z], [x0, 1.5, z]])
    return Mesh("quad", v, [[0, 1, 2], [0, 2, 3]], [material, material])


def checker_program():
    """A checker texture over the hit's position (core.shading.nodes), and its Fac output."""
    program = Program()
    position = program.add("coord", name="position")
    white = program.add("const", value=np.ones(3))
    black = program.add("const", value=np.zeros(3))
    scale = program.add("const", value=CHECKER_SCALE)
    checker = program.add("checker", [(position, 0), (white, 0), (black, 0), (scale, 0)])
    return program, (checker, 1)


def scene(transparency=0.0, film_transparent=False):
    """B's material ``transparency`` transparent; A also writes an AOV no render asks for; the world
    writes a colour where the camera sees it."""
    cam = Camera(translation(0, 0, 10)[None], (-1, 1, -1, 1), (RES, RES), type="ORTHO")
    b_closures = [Closure("DIFFUSE", weight=np.full(3, 1 - transparency), color=(0.5, 0.5, 0.5))]
    if transparency:
        b_closures.append(Closure("TRANSPARENT", weight=np.full(3, transparency), color=(1.0, 1.0, 1.0)))
    program, fac = checker_program()
    a = Material("a", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8))], program,
                 aovs=[("col", A_COLOR), ("val", fac), ("not in the view layer", 1.0)])
    b = Material("b", b_closures, aovs=[("col", B_COLOR)])
    return SceneData(cam, [quad(-2, 0.5, 0, 0), quad(0, 0.5, 4, 1)], [Instance(0, np.eye(4)), Instance(1, np.eye(4))],
                     [a, b], [], World(np.full(3, 0.1), aovs=[("col", WORLD_COLOR)]),
                     film_transparent=film_transparent)


def settings(samples=8, start=0, end=0, aovs=AOVS):
    return RenderSettings(samples=samples, seed=1, threads=1, filter_type="BOX", filter_size=1.0, aovs=aovs,
                          sample_start=start, sample_end=end)


def render(data, s):
    renderer = Renderer(data, s)
    return renderer, renderer.render()


def columns(image):
    """(quad A's pixels, quad B's, the background's): whole pixel columns, rows from the bottom."""
    return image[:, :RES // 2], image[:, RES // 2:3 * RES // 4], image[:, 3 * RES // 4:]


def checker_fac():
    """(RES, RES // 2) the checker's Fac at A's pixel centres (height 0: Cycles' rule, cells of
    unequal x and y parity white)."""
    centre = -1.0 + (np.arange(RES) + 0.5) * 2.0 / RES
    x, y = np.meshgrid(centre[:RES // 2], centre, indexing="xy")
    cell = lambda c: np.abs(np.floor(c * CHECKER_SCALE)).astype(int) % 2  # noqa: E731
    return (cell(x) != cell(y)).astype(float)


def test_a_constant_colour_and_a_textured_value_at_the_first_hits():
    p = render(scene(), settings())[1].passes
    a, b, bg = columns(p["col"])
    assert p["col"].shape == (RES, RES, 4) and p["val"].shape == (RES, RES, 1)
    assert np.allclose(a, [*A_COLOR, 1.0], atol=1e-6) and np.allclose(b, [*B_COLOR, 1.0], atol=1e-6)
    assert np.allclose(bg, [*WORLD_COLOR, 1.0], atol=1e-6)  # the world's
    val_a, val_b, val_bg = columns(p["val"][..., 0])
    fac = checker_fac()
    assert 0.3 < fac.mean() < 0.7  # both kinds of cell under A
    assert np.allclose(val_a, fac, atol=1e-6) and np.all(val_b == 0.0) and np.all(val_bg == 0.0)


@pytest.mark.parametrize("film_transparent, visible", [(True, True), (False, False)])
def test_a_transparent_film_or_a_hidden_world_leaves_it_unwritten(film_transparent, visible):
    """As Cycles, which evaluates no background that a transparent film shows or the camera does not see."""
    data = scene(film_transparent=film_transparent)
    data.world.visible_camera = visible
    _, _, bg = columns(render(data, settings())[1].passes["col"])
    assert np.all(bg == 0.0)


def test_an_aov_no_material_writes_is_zeros_and_costs_no_work():
    p = render(scene(), settings())[1].passes
    assert np.all(p["unwritten"] == 0.0)
    renderer, result = render(scene(), settings(aovs=(("unwritten", "VALUE"),)))
    assert renderer.integrator.aovs is None and np.all(result.passes["unwritten"] == 0.0)


def test_no_aovs_no_passes_no_work():
    renderer, result = render(scene(), settings(aovs=()))
    assert set(result.passes) == {"Combined"} and renderer.integrator.aovs is None
    assert renderer.plan.passes == ["Combined"]


SHARE = 0.75 / (0.75 + 0.25 * 0.5)
"""Cycles' share of samples through B a quarter opaque: its transparent closure's sampling weight
over its closures' (the diffuse's its weight times its colour, 0.5)."""


@pytest.mark.parametrize("transparency, expected", [
    (0.25, [*B_COLOR, 1.0]),  # three quarters opaque: at least the alpha threshold, B alone
    (0.75, [*(B_COLOR + SHARE * A_COLOR), 1.0 + SHARE]),  # a quarter opaque: B, and A in Cycles' share
])
def test_writes_go_on_through_transparency_to_the_alpha_threshold(transparency, expected):
    _, b, _ = columns(render(scene(transparency), settings())[1].passes["col"])
    assert np.allclose(b, expected, atol=1e-6), b[0, 0]


def test_the_aov_names_must_be_their_own():
    for aovs in ((("Depth", "VALUE"),), (("x", "COLOR"), ("x", "VALUE")), (("", "VALUE"),), (("x", "VECTOR"),)):
        with pytest.raises(SettingsError):
            settings(aovs=aovs)


def test_parts_merge_into_the_whole_render(tmp_path):
    data = scene(transparency=0.75)

    def part(start, end):
        return rendered_part(data, settings(start=start, end=end))

    _, whole = part(0, 0)
    pieces = [part(a, b)[0] for a, b in ((3, 8), (0, 3))]
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    merger = merge.merge_parts([parts.read(tmp_path / f"{i}.exr") for i in range(2)], ["A", "B"])
    images = merger.images()
    for name, _ in AOVS:
        assert np.allclose(images[name], whole.passes[name], rtol=1e-6, atol=1e-12), name
    merge.write_exr(tmp_path / "merged.exr", images, "ViewLayer", merger.first.settings().aovs)
    written = oiio.ImageBuf(str(tmp_path / "merged.exr"))
    names = list(written.spec().channelnames)
    assert {"ViewLayer.col.R", "ViewLayer.col.A", "ViewLayer.val.X", "ViewLayer.unwritten.X"} <= set(names)
    alpha = written.get_pixels(oiio.FLOAT)[..., names.index("ViewLayer.col.A")]
    assert np.allclose(alpha[::-1], whole.passes["col"][..., 3])


def test_the_checks_fail_without_the_computation(monkeypatch):
    """With the integrator's AOV writes switched off, the closed forms above are not met."""
    monkeypatch.setattr(Integrator, "_shader_aovs", lambda self, *args: None)
    p = render(scene(), settings())[1].passes
    a, _, _ = columns(p["col"])
    assert not np.allclose(a, [*A_COLOR, 1.0], atol=1e-6)
    assert not np.allclose(columns(p["val"][..., 0])[0], checker_fac(), atol=1e-6)
