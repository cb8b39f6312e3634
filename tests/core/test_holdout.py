"""Holdouts as Cycles' integrate_surface_holdout (core.integrator.holdout): an orthographic camera
looks down on quad A (under x < 0.5) and quad B above it (0 < x < 0.5); a holdout's share of what
the camera sees leaves the pixel's alpha and its colour, with Film Transparent off as well, while
the scene's light (shadows included) stays as it was."""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import translation

RES = 16


def quad(x0, x1, z, material):
    v = np.array([[x0, -1.5, z], [x1, -1.5, z], [x1, 1.5, z], [x0, 1.5, z]])
    return Mesh("quad", v, [[0, 1, 2], [0, 2, 3]], [material, material])


def scene(b_closures, b_holdout=False, a_holdout=False, transparent=False):
    cam = Camera(translation(0, 0, 10)[None], (-1, 1, -1, 1), (RES, RES), type="ORTHO")
    mats = [Material("a", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8))]), Material("b", b_closures)]
    data = SceneData(cam, [quad(-2, 0.5, 0, 0), quad(0, 0.5, 4, 1)],
                     [Instance(0, np.eye(4), holdout=a_holdout), Instance(1, np.eye(4), holdout=b_holdout)],
                     mats, [], World(np.array([0.3, 0.2, 0.1])))
    data.film_transparent = transparent
    return data


def render(data, samples=16):
    s = RenderSettings(samples=samples, seed=1, threads=1, passes=("Combined",), filter_type="BOX", filter_size=1.0)
    return Renderer(data, s).render().passes["Combined"]


def columns(image):
    """(A alone, B over A, the background): whole pixel columns."""
    return image[:, :RES // 2], image[:, RES // 2:3 * RES // 4], image[:, 3 * RES // 4:]


def diffuse(weight=1.0):
    return Closure("DIFFUSE", weight=np.full(3, weight), color=(0.5, 0.5, 0.5))


@pytest.mark.parametrize("transparent", [False, True])
def test_a_holdout_closure_takes_its_share_of_colour_and_alpha(transparent):
    """B mixes 0.3 Holdout with 0.7 Diffuse: its pixels keep 0.7 of the colour and of the alpha."""
    plain = columns(render(scene([diffuse()], transparent=transparent)))
    mixed = columns(render(scene([Closure("HOLDOUT", weight=np.full(3, 0.3)), diffuse(0.7)],
                                 transparent=transparent)))
    assert np.allclose(mixed[1][..., :3], 0.7 * plain[1][..., :3], rtol=1e-6, atol=1e-7)
    assert np.allclose(mixed[1][..., 3], 0.7, atol=1e-6) and np.all(plain[1][..., 3] == 1.0)
    assert np.array_equal(mixed[0], plain[0]) and np.array_equal(mixed[2], plain[2])


def test_an_object_holdout_is_a_hole_that_still_casts_its_shadow():
    plain = columns(render(scene([diffuse()])))
    held = columns(render(scene([diffuse()], b_holdout=True)))
    assert np.all(held[1] == 0.0)  # no colour, no alpha
    assert np.array_equal(held[0], plain[0]) and np.array_equal(held[2], plain[2])  # A still in B's shade


def test_a_holdout_seen_through_a_transparent_surface():
    """B lets 0.25 through to the object holdout A: B's pixels keep 0.75 of their alpha; Film
    Transparent takes the background."""
    b = [diffuse(0.75), Closure("TRANSPARENT", weight=np.full(3, 0.25), color=(1.0, 1.0, 1.0))]
    a_alone, b_over_a, background = columns(render(scene(b, a_holdout=True, transparent=True), samples=64))
    assert np.all(a_alone == 0.0) and np.all(background[..., 3] == 0.0)
    assert np.allclose(b_over_a[..., 3], 0.75, atol=1e-6)
    assert np.all(b_over_a[..., :3] > 0.0)


def test_an_object_holdout_keeps_what_its_material_lets_through():
    """B a quarter transparent, held out as an object: the rest of B is held out and A is seen
    through the quarter, as with B's diffuse part replaced by a Holdout closure (Cycles'
    surface_shader_apply_holdout)."""
    clear = Closure("TRANSPARENT", weight=np.full(3, 0.25), color=(1.0, 1.0, 1.0))
    held = render(scene([diffuse(0.75), clear], b_holdout=True), samples=32)
    closure = render(scene([Closure("HOLDOUT", weight=np.full(3, 0.75)), clear]), samples=32)
    assert np.allclose(held, closure, rtol=1e-6, atol=1e-7)
    b_over_a = columns(held)[1]
    assert np.allclose(b_over_a[..., 3], 0.25, atol=1e-6) and np.all(b_over_a[..., :3] > 0.0)


def test_a_hit_held_out_whole_writes_no_data_passes():
    """Cycles writes Depth after the holdout: B held out whole leaves the background's depth."""
    s = RenderSettings(samples=4, seed=1, threads=1, passes=("Combined", "Depth"), filter_type="BOX", filter_size=1.0)
    depth = Renderer(scene([diffuse()], b_holdout=True), s).render().passes["Depth"][..., 0]
    a_alone, b_over_a, background = columns(depth)
    assert np.allclose(a_alone, 10.0) and np.all(b_over_a == background) and np.all(background >= 1e9)
