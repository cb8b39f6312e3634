"""Image-based lighting: the world from an environment map, importance sampled, with MIS."""
import numpy as np
import pytest

from drt_engine.core.bsdf import microfacet as mf
from drt_engine.core.lights.environment import Environment
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, SceneData, TextureImage
from drt_engine.core.settings import RenderSettings
from drt_engine.core.shading.textures import Texture, equirect_direction, equirect_uv
from tests.support.scenes import look_at, uv_sphere
from tests.support.textured_scenes import environment_world, ortho_top, uv_plane

L = 0.7


def constant_map(value=L, w=16, h=8):
    return TextureImage("constant", pixels=np.full((h, w, 4), value, np.float32), colorspace="Non-Color")


def sun_map(w=128, h=64, sun=(90, 40), sky=0.05, peak=2.0e4):
    """A dim sky with one 2 x 2 texel sun at texel (column, row from the bottom)."""
    px = np.full((h, w, 4), sky, np.float32)
    px[..., 3] = 1.0
    c, r = sun
    px[r:r + 2, c:c + 2, :3] = peak
    return TextureImage("sun", pixels=px, colorspace="Non-Color")


def render(scene, samples, seed=0):
    result = Renderer(scene, RenderSettings(samples=samples, seed=seed, threads=1)).render()
    return result.passes["Combined"][..., :3].astype(np.float64)


def test_equirect_mapping_round_trip():
    uv = np.random.default_rng(3).random((100, 2))
    assert np.allclose(equirect_uv(equirect_direction(uv)), uv, atol=1e-12)
    assert np.allclose(equirect_uv(np.array([[1.0, 0, 0], [0, 0, 1.0]])), [[0.5, 0.5], [0.5, 1.0]])


def test_white_furnace_with_image_based_lighting():
    """A white diffuse sphere (convex: direct light only is all there is) under a constant
    environment map of radiance L renders L everywhere, background included."""
    sphere = uv_sphere(radius=1.0, segments=48, rings=24)
    mat = Material("white", [Closure("DIFFUSE", color=(1, 1, 1), roughness=0.0)])
    camera = ortho_top(16, half=1.2, height=3.0)
    scene = SceneData(camera=camera, meshes=[sphere], instances=[Instance(0, np.eye(4))], materials=[mat],
                      world=environment_world(), images=[constant_map()])
    img = render(scene, samples=64)
    assert abs(img.mean() / L - 1) < 0.01
    blocks = img.reshape(4, 4, 4, 4, 3).mean(axis=(1, 3))  # 4 x 4 pixel blocks, centre to rim
    assert np.abs(blocks / L - 1).max() < 0.05


def test_glossy_lobe_and_environment_weights_sum_to_one():
    """A GGX plane (tint 1, no multiscatter) under a constant map reflects L times the lobe's
    albedo: map sampling and lobe sampling, weighted by the power heuristic, add up exactly."""
    mat = Material("gloss", [Closure("GLOSSY", color=(1, 1, 1), roughness=0.5, multiscatter=False)])
    camera = Camera(look_at((0, -1, 1), (0, 0, 0))[None], (-0.02, 0.02, -0.02, 0.02), (4, 4))
    scene = SceneData(camera=camera, meshes=[uv_plane(half=50)], instances=[Instance(0, np.eye(4))],
                      materials=[mat], world=environment_world(), images=[constant_map()])
    img = render(scene, samples=256)
    mu, e = mf.white_albedo(0.25)
    expected = L * np.interp(np.cos(np.pi / 4), mu, e)
    assert abs(img.mean() / expected - 1) < 0.01


def irradiance_estimates(env, n, trials, importance, rng):
    """Monte Carlo irradiance on an upward normal from n samples, ``trials`` times."""
    out = []
    for _ in range(trials):
        u = rng.random((n, 2))
        if importance:
            d, pdf = env.sample(u)
        else:
            z = 1 - 2 * u[:, 0]
            r = np.sqrt(np.maximum(1 - z * z, 0))
            d = np.stack([r * np.cos(2 * np.pi * u[:, 1]), r * np.sin(2 * np.pi * u[:, 1]), z], 1)
            pdf = np.full(n, 1 / (4 * np.pi))
        f = env.radiance(d)[:, 0] * np.maximum(d[:, 2], 0) / pdf
        out.append(f.mean())
    return np.array(out)


def exact_irradiance(image):
    """Closest lookups make the map piecewise constant per texel: integrate cos over each cell."""
    h, w = image.pixels.shape[:2]
    e_lo = (np.arange(h) / h - 0.5) * np.pi
    e_hi = e_lo + np.pi / h
    cell = np.maximum(np.sin(np.maximum(e_hi, 0)) ** 2 - np.sin(np.maximum(e_lo, 0)) ** 2, 0) / 2 * (2 * np.pi / w)
    return float((image.pixels[:, :, 0] * cell[:, None]).sum())


def test_importance_sampling_beats_uniform_sampling_4x_on_a_sun_map():
    image = sun_map()
    env = Environment(environment_world(interpolation="Closest"), [Texture(image)])
    exact = exact_irradiance(image)
    rng = np.random.default_rng(11)
    n = 64
    mse_is = np.mean((irradiance_estimates(env, n, 200, True, rng) - exact) ** 2)
    mse_uniform = np.mean((irradiance_estimates(env, n, 200, False, rng) - exact) ** 2)
    # error variance falls as 1/n, so the ratio of squared errors is the ratio of samples needed
    assert mse_uniform > 4 * mse_is, (mse_uniform, mse_is)
    assert abs(irradiance_estimates(env, 4096, 4, True, rng).mean() / exact - 1) < 0.01


def test_mapping_rotation_turns_the_map():
    image = sun_map(sun=(32, 31))
    plain = Environment(environment_world(interpolation="Closest"), [Texture(image)])
    turned = Environment(environment_world(rotation=(0, 0, np.pi / 2), interpolation="Closest"), [Texture(image)])
    d = equirect_direction(np.array([[32.5 / 128, 32 / 64]]))
    rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    assert plain.radiance(d)[0, 0] == pytest.approx(2.0e4)
    # Mapping (Point) rotates the lookup vector: the map turns the other way
    assert turned.radiance(d)[0, 0] == pytest.approx(0.05)
    assert turned.radiance(d @ rz)[0, 0] == pytest.approx(2.0e4)


def test_world_hidden_from_camera_still_lights():
    mat = Material("white", [Closure("DIFFUSE", color=(1, 1, 1), roughness=0.0)])
    world = environment_world()
    world.visible_camera = False
    scene = SceneData(camera=ortho_top(8, half=2.0), meshes=[uv_plane(half=1.0)], instances=[Instance(0, np.eye(4))],
                      materials=[mat], world=world, images=[constant_map()])
    img = render(scene, samples=64)
    assert np.all(img[0, 0] == 0) and abs(img[3:5, 3:5].mean() / L - 1) < 0.03


@pytest.mark.parametrize("hidden", ["visible_diffuse", "visible_glossy"])
def test_world_ray_visibility_per_lobe(hidden):
    """A world hidden from diffuse rays lights a rough glossy plane but not a diffuse one, and
    hidden from glossy rays the other way round (both by light sampling and by reflected rays)."""
    expected = {}
    for kind in ("DIFFUSE", "GLOSSY"):
        closure = Closure(kind, color=(1, 1, 1), roughness=0.0 if kind == "DIFFUSE" else 0.4, multiscatter=False)
        world = environment_world()
        setattr(world, hidden, False)
        scene = SceneData(camera=ortho_top(4, half=0.5), meshes=[uv_plane(half=5.0)], instances=[Instance(0, np.eye(4))],
                          materials=[Material("m", [closure])], world=world, images=[constant_map()])
        expected[kind] = render(scene, samples=64).mean()
    lit, dark = ("GLOSSY", "DIFFUSE") if hidden == "visible_diffuse" else ("DIFFUSE", "GLOSSY")
    assert expected[dark] == 0.0 and expected[lit] > 0.5 * L
