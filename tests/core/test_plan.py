"""The render plan leaves out what a scene does not need, and the tracer keeps to it."""
import numpy as np
import pytest

from drt_engine.core.bsdf import shader as bsdf
from drt_engine.core.sampling import dims as D
from drt_engine.core.integrator.records import Samples
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import look_at, plane, top_camera, translation, uv_sphere

DIFFUSE = Material("white", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])
MIRROR = Material("mirror", [Closure("GLOSSY", color=(0.9, 0.9, 0.9), roughness=0.0)])
GLASS = Material("glass", [Closure("GLASS", roughness=0.0, ior=1.5)])
# a Principled BSDF with transmission 0 and no coat: no refraction lobe, whatever its IOR
PLASTIC = Material("plastic", [Closure("PRINCIPLED", color=(0.5, 0.2, 0.2), roughness=0.3, transmission=0.0)])


def point(x, y, z, watts=50.0):
    return Light("POINT", translation(x, y, z), intensity=np.full(3, watts))


def sun():
    return Light("SUN", look_at((1, 1, 3), (0, 0, 0)), irradiance=np.full(3, 2.0))


def floor_scene(materials=(DIFFUSE,), lights=(), world=(0.0, 0.0, 0.0), camera=None, ball=None):
    """A floor filling the view, optionally a ball of material 1 on it seen by the camera."""
    meshes, instances = [plane(20.0)], [Instance(0, np.eye(4))]
    if ball is not None:
        meshes.append(uv_sphere(0.5, (0, 0, 0.5), material=1))
        instances.append(Instance(1, ball))
    cam = camera or Camera(look_at((0, -3, 2), (0, 0, 0.3))[None], (-0.3, 0.3, -0.3, 0.3), (16, 16))
    return SceneData(cam, meshes, instances, list(materials), list(lights), World(np.asarray(world, float)))


def run(scene, **kw):
    settings = dict(samples=4, threads=1, max_depth=4)
    settings.update(kw)
    r = Renderer(scene, RenderSettings(**settings))
    return r, r.render()


def test_diffuse_only_scene_traces_no_reflection_refraction_or_transparent_rays():
    r, res = run(floor_scene(lights=[point(0, 0, 3)]))
    rays = res.stats["rays"]
    assert rays["camera"] == 16 * 16 * 4 and rays["shadow"] > 0
    assert rays["reflection"] == rays["refraction"] == rays["transparent"] == 0
    plan = res.stats["plan"]
    assert not plan["rays"]["reflection"] and not plan["rays"]["refraction"] and not plan["rays"]["transparent"]
    assert "reflection rays" in res.stats["plan_summary"]


def test_diffuse_rays_only_with_diffuse_bounces():
    """Diffuse bounces 0 (the default) traces no diffuse ray and says so; with bounces the plan
    names them, the counter counts them, and a diffuse-only scene traces no other bounce kind."""
    _, classic = run(floor_scene((DIFFUSE, DIFFUSE), [point(0, 0, 3)], ball=np.eye(4)))
    assert classic.stats["rays"]["diffuse"] == 0 and "diffuse rays" in classic.stats["plan_summary"]
    _, bounced = run(floor_scene((DIFFUSE, DIFFUSE), [point(0, 0, 3)], ball=np.eye(4)), diffuse_bounces=2)
    rays = bounced.stats["rays"]
    assert rays["diffuse"] > 0 and bounced.stats["plan"]["rays"]["diffuse"]
    assert rays["reflection"] == rays["refraction"] == rays["transparent"] == 0


def test_a_path_out_of_diffuse_bounces_ends_where_only_diffuse_reflections_are():
    """Sheen only, diffuse bounces 1: a path's one diffuse bounce spent, its next hit has no lobe to
    continue through (no column in the lobe choice, whose one uninitialised column once let a
    path read past the lobes: a firefly of 1e28 in tests/blender/test_sheen_cycles.py)."""
    sheen = Material("sheen", [Closure("SHEEN", color=(0.8, 0.8, 0.8), roughness=0.3)])
    _, res = run(floor_scene((sheen, sheen), [point(0, 0, 3)], ball=np.eye(4)), diffuse_bounces=1)
    rays, image = res.stats["rays"], res.passes["Combined"][..., :3]
    assert 0 < rays["diffuse"] <= rays["camera"]
    assert rays["reflection"] == rays["refraction"] == rays["transparent"] == 0
    assert np.isfinite(image).all() and image.max() < 10.0


def test_each_lobe_kind_traces_its_own_ray_kind_and_only_that():
    _, mirror = run(floor_scene((DIFFUSE, MIRROR), [point(0, 0, 3)], ball=np.eye(4)))
    assert mirror.stats["rays"]["reflection"] > 0 and mirror.stats["rays"]["refraction"] == 0
    _, glass = run(floor_scene((DIFFUSE, GLASS), [point(0, 0, 3)], ball=np.eye(4)))
    assert glass.stats["rays"]["refraction"] > 0 and glass.stats["plan"]["rays"]["refraction"]
    _, plastic = run(floor_scene((DIFFUSE, PLASTIC), [point(0, 0, 3)], ball=np.eye(4)))
    assert plastic.stats["rays"]["refraction"] == 0 and not plastic.stats["plan"]["rays"]["refraction"]
    assert plastic.stats["rays"]["reflection"] > 0


def test_delta_lights_cast_exactly_one_shadow_ray_each_per_hit():
    """Every camera ray hits the floor (top view); three delta lights above it, black world."""
    scene = floor_scene(lights=[point(0, 0, 3), point(1, 0, 2), sun()], camera=top_camera(2.0, 0.2, 8))
    r, res = run(scene)
    assert res.stats["rays"]["shadow"] == 3 * res.stats["rays"]["camera"]
    assert all(s.endswith("(delta)") for s in res.stats["plan"]["strategies"])


def test_a_black_world_is_not_sampled_and_a_lit_one_is():
    camera = top_camera(2.0, 0.2, 8)
    _, black = run(floor_scene(lights=[point(0, 0, 3)], camera=camera))
    _, lit = run(floor_scene(lights=[point(0, 0, 3)], world=(0.1, 0.1, 0.1), camera=camera))
    assert black.stats["rays"]["shadow"] == black.stats["rays"]["camera"]
    assert "world" not in black.stats["plan"]["strategies"] and "world sampling (black world)" in \
        black.stats["plan"]["left_out"]
    assert lit.stats["rays"]["shadow"] == 2 * lit.stats["rays"]["camera"]


class Recording:
    """A sampler that remembers which dimensions were asked for."""

    def __init__(self, sampler):
        self.inner, self.dims = sampler, set()

    def get(self, pixel, sample, dim):
        self.dims.add(dim)
        return self.inner.get(pixel, sample, dim)

    def get2d(self, pixel, sample, dim):
        self.dims.update((dim, dim + 1))
        return self.inner.get2d(pixel, sample, dim)

    def __getattr__(self, name):
        return getattr(self.inner, name)


def dims_drawn(scene):
    r = Renderer(scene, RenderSettings(samples=2, threads=1))
    sampler = Recording(r.sampler)
    r.integrator.trace(Samples(np.arange(16), np.arange(16, dtype=np.uint32), np.zeros(16, np.int64)), sampler)
    return r, sampler.dims


def test_no_lens_dimension_at_aperture_zero():
    sharp = Camera(look_at((0, -3, 2), (0, 0, 0))[None], (-0.3, 0.3, -0.3, 0.3), (4, 4))
    blurred = Camera(look_at((0, -3, 2), (0, 0, 0))[None], (-0.3, 0.3, -0.3, 0.3), (4, 4), aperture_radius=0.1,
                     focus_distance=3.0)
    r, dims = dims_drawn(floor_scene(lights=[point(0, 0, 3)], camera=sharp))
    assert not r.plan.lens and D.LENS not in dims and D.LENS + 1 not in dims
    r, dims = dims_drawn(floor_scene(lights=[point(0, 0, 3)], camera=blurred))
    assert r.plan.lens and D.LENS in dims


def test_no_time_dimension_when_nothing_moves():
    r, dims = dims_drawn(floor_scene((DIFFUSE, DIFFUSE), [point(0, 0, 3)], ball=np.eye(4)))
    assert not r.plan.time and D.TIME not in dims and r.plan.moving == []
    moving = np.stack([translation(-0.3, 0, 0), translation(0.3, 0, 0)])
    scene = floor_scene((DIFFUSE, DIFFUSE), [point(0, 0, 3)], ball=moving)
    scene.instances[1].name = "Ball"
    r, dims = dims_drawn(scene)
    assert r.plan.time and D.TIME in dims and r.plan.moving == ["Ball"]


@pytest.mark.parametrize("name", ["DiffCol", "GlossCol"])
def test_disabling_a_pass_removes_its_work(monkeypatch, name):
    calls = []
    original = bsdf.MaterialShader.colors
    monkeypatch.setattr(bsdf.MaterialShader, "colors", lambda self, mu: calls.append(len(mu)) or original(self, mu))
    scene = floor_scene(lights=[point(0, 0, 3)])
    _, without = run(scene)
    assert calls == [] and name not in without.passes and without.stats["plan"]["passes"] == ["Combined"]
    _, with_pass = run(scene, passes=("Combined", name))
    assert sum(calls) == 16 * 16 * 4 and name in with_pass.passes
