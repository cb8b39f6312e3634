"""Cycles' light passes (core.integrator.lightpasses): Diffuse, Glossy and Transmission, Direct and
Indirect, each read out divided by its colour pass. What the camera sees itself (Emit, Env) and the
light passes times their colours sum to Combined, to float rounding; without them nothing changes."""
import numpy as np
import pytest

from drt_engine.core.film.film import divide_even_color
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import LIGHT_PASSES, RenderSettings
from tests.support import split_render
from tests.support.scenes import plane, render_passes, top_camera, translation, uv_sphere

LIGHT = tuple(LIGHT_PASSES)
PASSES = ("Combined", "Emit", "Env", "DiffCol", "GlossCol", "TransCol") + LIGHT


def scene() -> SceneData:
    """A floor (diffuse and glossy), a metal sphere, a glass sphere, an emissive sphere, an area light
    the camera sees, a point light, a sun and a lit world: every kind of contribution."""
    floor = Material("floor", [Closure("DIFFUSE", color=(0.5, 0.4, 0.3), weight=(0.7,) * 3),
                               Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.3, weight=(0.3,) * 3)])
    metal = Material("metal", [Closure("GLOSSY", color=(0.9, 0.7, 0.5), roughness=0.2)])
    glass = Material("glass", [Closure("GLASS", color=(0.9, 0.95, 1.0), roughness=0.1, ior=1.45)])
    glow = Material("glow", [Closure("EMISSION", emission=(3.0, 1.0, 0.3))])
    meshes = [plane(10.0), uv_sphere(0.4, (0.4, 0.3, 0.4), 24, 12, material=1),
              uv_sphere(0.35, (-0.4, 0.35, 0.35), 24, 12, material=2),
              uv_sphere(0.2, (-0.6, -0.4, 0.6), 16, 8, material=3)]
    instances = [Instance(k, np.eye(4)) for k in range(len(meshes))]
    lights = [Light("AREA", translation(0.5, -0.5, 2.0), radiance=np.array([4.0, 3.0, 2.0]), size_x=0.5, size_y=0.5),
              Light("POINT", translation(-0.8, 0.6, 1.5), intensity=np.array([2.0, 5.0, 8.0]), radius=0.2),
              Light("SUN", np.eye(4), irradiance=np.array([0.5, 0.5, 0.6]), angle=0.2)]
    return SceneData(top_camera(3.0, 0.5, 24), meshes, instances, [floor, metal, glass, glow], lights,
                     World(radiance=np.array([0.1, 0.15, 0.3])))


def render(data, passes=PASSES, **settings):
    return render_passes(data, passes, **settings)


@pytest.mark.parametrize("settings", [{}, {"diffuse_bounces": 2}, {"sample_clamp_direct": 0.5,
                                                                   "sample_clamp_indirect": 0.2}],
                         ids=["classic", "diffuse bounces", "clamped"])
def test_emit_env_and_light_passes_times_colours_sum_to_combined(settings):
    p = {name: image.astype(np.float64) for name, image in render(scene(), **settings).items()}
    combined = p["Combined"][..., :3]
    total = p["Emit"] + p["Env"] + sum(p[name] * p[LIGHT_PASSES[name]] for name in LIGHT)
    np.testing.assert_allclose(total, combined, rtol=1e-4, atol=1e-5)
    # each holds light (TransDir hardly: light reaches a closed glass sphere's far side after two bounces)
    for name in ("DiffDir", "GlossDir", "GlossInd", "TransInd"):
        assert (p[name] * p[LIGHT_PASSES[name]]).mean() > 1e-3 * combined.mean(), name
    # without diffuse bounces too: a glossy bounce off the floor carries its diffuse lobe's share of the
    # BSDF there (Cycles' pass weights of the whole closure mixture)
    assert p["DiffInd"].mean() > 1e-3 * p["DiffDir"].mean()


def test_light_passes_leave_combined_as_it_was():
    with_passes = render(scene())["Combined"]
    without = render(scene(), passes=("Combined",))["Combined"]
    assert np.array_equal(with_passes, without)


def test_a_light_pass_alone_returns_no_colour_pass():
    """Its colour is summed to divide by (as Cycles allocates it) but not returned, as Cycles writes
    only the enabled passes: the pass reads the same as with its colour asked for."""
    alone = render(scene(), passes=("Combined", "GlossInd"))
    assert set(alone) == {"Combined", "GlossInd"}
    with_colour = render(scene(), passes=("Combined", "GlossInd", "GlossCol"))
    np.testing.assert_array_equal(alone["GlossInd"], with_colour["GlossInd"])


def test_divide_even_color_is_cycles():
    """Cycles' safe_divide_even_color: a zero channel of the divisor takes the others' quotients."""
    a = np.array([[1.0, 2.0, 3.0]] * 5)
    b = np.array([[2.0, 4.0, 6.0], [0.0, 4.0, 3.0], [0.0, 0.0, 6.0], [2.0, 0.0, 0.0], [2.0, 4.0, 0.0]])
    np.testing.assert_allclose(divide_even_color(a, b), [[0.5, 0.5, 0.5], [0.75, 0.5, 1.0], [0.5, 0.5, 0.5],
                                                         [0.5, 0.5, 0.5], [0.5, 0.5, 0.5]])


def test_a_light_pass_alone_travels_through_parts_and_merge(tmp_path):
    """A split render's parts keep the colour a light pass is divided by; merged, the pass is the whole
    render's and the colour is not among the merged passes."""
    def part(start, end):
        settings = RenderSettings(samples=8, threads=1, max_depth=4, passes=("Combined", "DiffInd"),
                                  sample_start=start, sample_end=end)
        return split_render.render_part(scene(), settings)

    _, whole = part(0, 0)
    merged = split_render.merged([part(a, b)[0] for a, b in ((0, 3), (3, 8))], tmp_path).images()
    assert set(merged) == {"Combined", "DiffInd"}
    np.testing.assert_allclose(merged["DiffInd"], whole.passes["DiffInd"], rtol=1e-5, atol=1e-7)
