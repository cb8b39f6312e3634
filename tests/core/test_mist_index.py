"""Mist, Object Index and Material Index passes against closed forms (core.film.mist, core.film.film):
an orthographic camera looks down on two quads at known heights, so every sample of a pixel inside
one quad sees the same distance, object and material; and parts of the sample range merge into the
whole render's passes."""
import numpy as np
import pytest

from drt_engine.core.film import parts
from drt_engine.core.integrator.integrator import Integrator
from drt_engine.core.render import merge
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.core_cases import rendered_part
from tests.support.scenes import translation

RES = 16
PASSES = ("Combined", "Mist", "IndexOB", "IndexMA")
START, DEPTH = 2.0, 10.0


def quad(x0, x1, z, material):
    v = np.array([[x0, -1.5, z], [x1, -1.5, z], [x1, 1.5, z], [x0, 1.5, z]])
    return Mesh("quad", v, [[0, 1, 2], [0, 2, 3]], [material, material])


def scene(falloff=2.0, transparency=0.0):
    """Quad A (object index 3, material index 5) at height 0 under x < 0.5, quad B (7, 2) at height 4
    under 0 < x < 0.5, the background beyond; the camera 10 above, a 2 x 2 window of 16 x 16 pixels.
    B's material is ``transparency`` transparent."""
    cam = Camera(translation(0, 0, 10)[None], (-1, 1, -1, 1), (RES, RES), type="ORTHO")
    closures = [Closure("DIFFUSE", weight=np.full(3, 1 - transparency), color=(0.5, 0.5, 0.5))]
    if transparency:
        closures.append(Closure("TRANSPARENT", weight=np.full(3, transparency), color=(1.0, 1.0, 1.0)))
    mats = [Material("a", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8))], pass_index=5),
            Material("b", closures, pass_index=2)]
    world = World(np.full(3, 0.1), mist_start=START, mist_depth=DEPTH, mist_falloff=falloff)
    return SceneData(cam, [quad(-2, 0.5, 0, 0), quad(0, 0.5, 4, 1)],
                     [Instance(0, np.eye(4), pass_index=3), Instance(1, np.eye(4), pass_index=7)], mats, [], world)


def settings(samples=8, start=0, end=0, pattern="SOBOL", passes=PASSES):
    return RenderSettings(samples=samples, seed=1, threads=1, sampling_pattern=pattern, passes=passes,
                          filter_type="BOX", filter_size=1.0, sample_start=start, sample_end=end)


def render(data, s):
    renderer = Renderer(data, s)
    return renderer, renderer.render()


def columns(image):
    """(quad A's pixels, quad B's, the background's): whole pixel columns, rows from the bottom."""
    return image[:, :RES // 2, 0], image[:, RES // 2:3 * RES // 4, 0], image[:, 3 * RES // 4:, 0]


def mist(distance, falloff):
    return np.clip((distance - START) / DEPTH, 0, 1) ** falloff


@pytest.mark.parametrize("falloff", [2.0, 1.0, 0.5])
def test_mist_is_the_ramp_of_the_distance(falloff):
    a, b, bg = columns(render(scene(falloff), settings())[1].passes["Mist"])
    assert np.allclose(a, mist(10.0, falloff), atol=1e-6) and np.allclose(b, mist(6.0, falloff), atol=1e-6)
    assert np.all(bg == 1.0)  # nothing seen: Cycles' background reads 1


def test_mist_weighs_each_hit_by_its_opacity():
    """B is a quarter transparent: its pixels read 1 - (0.75 (1 - mist B) + 0.25 (1 - mist A)) on average."""
    _, b, _ = columns(render(scene(1.0, transparency=0.25), settings(samples=256))[1].passes["Mist"])
    expected = 1.0 - (0.75 * (1 - mist(6.0, 1.0)) + 0.25 * (1 - mist(10.0, 1.0)))
    assert abs(b.mean() - expected) < 0.01, (b.mean(), expected)


@pytest.mark.parametrize("pattern", ["SOBOL", "GRID"])
def test_indices_are_the_first_hits(pattern):
    p = render(scene(), settings(pattern=pattern))[1].passes
    for name, (ia, ib) in (("IndexOB", (3, 7)), ("IndexMA", (5, 2))):
        a, b, bg = columns(p[name])
        assert np.all(a == ia) and np.all(b == ib) and np.all(bg == 0), name


@pytest.mark.parametrize("transparency, threshold, index", [(0.75, 0.5, 3.0), (0.25, 0.5, 7.0), (0.75, 0.2, 7.0),
                                                          (0.75, 0.0, 7.0)])
def test_a_mostly_transparent_hit_passes_the_indices_on(transparency, threshold, index):
    """Under the view layer's alpha threshold (Cycles' default 0.5) a hit's index is replaced by the
    next hit's on the path: B a quarter opaque shows A's index, B three quarters opaque its own, and
    so does B a quarter opaque under a threshold of 0.2 or 0 (0: the first hit). (DRT's paths always
    continue through a transparent lobe, its only non-diffuse one; Cycles' pick it or the diffuse by
    weight and end at the diffuse, so there a sample 0 stops at such a B now and then.)"""
    s = settings(samples=4)
    s.pass_alpha_threshold = threshold
    _, b, _ = columns(render(scene(transparency=transparency), s)[1].passes["IndexOB"])
    assert np.all(b == index)


def test_indices_are_not_averaged_over_an_edge():
    """A pixel straddling quad A's edge keeps one sample's index (3 or 0), not their mean."""
    s = settings()
    s.filter_type, s.filter_size = "GAUSSIAN", 3.0
    edge = render(scene(), s)[1].passes["IndexOB"][:, RES // 2 - 1:RES // 2 + 1, 0]
    assert set(np.unique(edge)) <= {3.0, 7.0}


def test_no_work_when_off():
    """Without the passes the integrator neither allocates nor computes them."""
    data = scene()
    renderer, result = render(data, settings(passes=("Combined",)))
    assert set(result.passes) == {"Combined"}
    assert renderer.integrator.mist is None


def test_parts_merge_into_the_whole_render(tmp_path):
    data = scene(transparency=0.75)

    def part(start, end):
        return rendered_part(data, settings(start=start, end=end))

    _, whole = part(0, 0)
    pieces = [part(a, b)[0] for a, b in ((3, 8), (1, 3), (0, 1))]
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    images = merge.merge_parts([parts.read(tmp_path / f"{i}.exr") for i in range(3)], ["A", "B", "C"]).film.images()
    assert np.array_equal(images["IndexOB"], whole.passes["IndexOB"])
    assert np.array_equal(images["IndexMA"], whole.passes["IndexMA"])
    assert np.allclose(images["Mist"], whole.passes["Mist"], rtol=1e-6, atol=1e-12)


def test_the_checks_fail_without_the_computation(monkeypatch):
    """With the integrator's data passes switched off, the closed forms above are not met."""
    monkeypatch.setattr(Integrator, "_data_passes", lambda self, group, shader, out: None)
    p = render(scene(), settings())[1].passes
    a, _, _ = columns(p["Mist"])
    assert not np.allclose(a, mist(10.0, 2.0), atol=1e-6)
    assert not np.all(columns(p["IndexOB"])[0] == 3) and not np.all(columns(p["IndexMA"])[0] == 5)
