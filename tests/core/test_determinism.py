"""Same settings and seed give the same image bit for bit, whatever the thread count."""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import PASSES, RenderSettings
from tests.support.scenes import look_at, plane, uv_sphere


def scene():
    cam = Camera(look_at((0, -5, 2), (0, 0, 0.5))[None], (-0.3, 0.3, -0.3, 0.3), (24, 24))
    mats = [Material("floor", [Closure("DIFFUSE", color=(0.6, 0.6, 0.6))]),
            Material("glass", [Closure("GLASS", roughness=0.2, ior=1.45)]),
            Material("metal", [Closure("PRINCIPLED", color=(0.9, 0.7, 0.3), metallic=1, roughness=0.3)])]
    meshes = [plane(20), uv_sphere(0.5, (-0.6, 0, 0.5), material=1), uv_sphere(0.5, (0.6, 0, 0.5), material=2)]
    light = Light("AREA", look_at((1, -2, 3), (0, 0, 0)), radiance=np.full(3, 10.0), size_x=1.0)
    return SceneData(cam, meshes, [Instance(i, np.eye(4)) for i in range(3)], mats, [light], World(np.full(3, 0.05)))


def render(threads, seed=0, pattern="SOBOL", estimator="MONTE_CARLO", diffuse_bounces=0):
    s = RenderSettings(samples=8, seed=seed, threads=threads, sampling_pattern=pattern, passes=PASSES,
                       shadow_estimator=estimator, diffuse_bounces=diffuse_bounces)
    return Renderer(scene(), s).render().passes


@pytest.mark.parametrize("estimator", ["MONTE_CARLO", "RATIO"])
def test_bit_identical_for_one_and_two_threads(estimator):
    a, b = render(1, estimator=estimator), render(2, estimator=estimator)
    for name in a:
        assert np.array_equal(a[name], b[name]), name


def test_every_pass_is_finite():
    for pattern in ("SOBOL", "JITTERED", "GRID"):
        for name, img in render(1, pattern=pattern).items():
            assert np.isfinite(img).all(), (pattern, name)


def test_another_seed_gives_another_image():
    assert not np.array_equal(render(1, seed=0)["Combined"], render(1, seed=1)["Combined"])


def test_bit_identical_when_waves_are_split_over_threads(monkeypatch):
    """Waves this small are traced whole; with a tiny piece size each is split across the threads."""
    from drt_engine.core.render import render as render_module

    monkeypatch.setattr(render_module, "_MIN_PIECE", 64)
    one, two, three = render(1), render(2), render(3)
    for name in one:
        assert np.array_equal(one[name], two[name]) and np.array_equal(one[name], three[name]), name


def test_diffuse_bounces_are_bit_identical_over_threads_and_finite(monkeypatch):
    """Paths through diffuse, glass and metal lobes, Russian roulette and the world: one thread,
    two, and waves split across three give one image; every pass finite."""
    from drt_engine.core.render import render as render_module

    monkeypatch.setattr(render_module, "_MIN_PIECE", 64)
    one, two, three = (render(t, diffuse_bounces=3) for t in (1, 2, 3))
    for name in one:
        assert np.isfinite(one[name]).all(), name
        assert np.array_equal(one[name], two[name]) and np.array_equal(one[name], three[name]), name
    assert one["Combined"].mean() > render(1)["Combined"].mean()  # the bounces add light


def test_textured_scene_under_an_environment_map_is_bit_identical_and_finite():
    from drt_engine.core.scene import TextureImage
    from tests.support.textured_scenes import environment_world, image_program

    base = scene()
    rng = np.random.default_rng(4)
    prog, ref = image_program()
    rough = prog.add("convert", [ref], kind="color_to_float")
    base.materials[0] = Material("floor", [Closure("PRINCIPLED", metallic=0.5, inputs={"color": ref, "roughness": (rough, 0)})],
                                 prog)
    base.meshes[0].uvs = rng.random((len(base.meshes[0].triangles), 3, 2)).astype(np.float32)
    base.images = [TextureImage("noise", pixels=rng.random((16, 16, 4)), colorspace="sRGB"),
                   TextureImage("sky", pixels=rng.random((8, 16, 4)) * 4, colorspace="Non-Color")]
    base.world = environment_world(image=1, rotation=(0.1, 0.2, 0.3))
    images = []
    for threads in (1, 2):
        s = RenderSettings(samples=8, seed=3, threads=threads, passes=PASSES)
        images.append(Renderer(base, s).render().passes)
    for name in images[0]:
        assert np.array_equal(images[0][name], images[1][name]), name
        assert np.isfinite(images[0][name]).all(), name


def test_two_renders_at_once_in_one_process_match_renders_alone():
    """Two renderers in two Python threads (a viewport render during F12), each with two
    threads of its own: neither crashes nor waits on the other, and each image is the one it
    gives alone."""
    import threading

    alone = [render(2, seed=seed) for seed in (0, 1)]
    together = [None, None]

    def run(i):
        together[i] = render(2, seed=i)

    workers = [threading.Thread(target=run, args=(i,)) for i in (0, 1)]
    for t in workers:
        t.start()
    for t in workers:
        t.join(timeout=300)
    assert not any(t.is_alive() for t in workers), "a render did not finish: deadlock"
    for a, b in zip(alone, together):
        for name in a:
            assert np.array_equal(a[name], b[name]), name
