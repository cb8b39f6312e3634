"""The light kernels' one contract, kind by kind: what ``sample_light`` returns is what the
same light's ``hit_light`` and ``light_pdf`` give for that direction (distance, radiance over
pdf, pdf), the choice among many lights picks each light as often as its stated probability,
and the environment table's samples follow the density ``map_pdf`` states."""
import numpy as np
import pytest

from drt_engine.core.lights.environment import Environment, direction_at, map_pdf
from drt_engine.core.lights.choice import pick_light, pick_probability
from drt_engine.core.lights.table import light_table
from drt_engine.core.lights.collection import _intersect_batch, _pdf_batch, _sample_batch
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, TextureImage
from drt_engine.core.settings import RenderSettings
from drt_engine.core.shading.textures import Texture, equirect_direction
from tests.support.scenes import look_at, plane, top_camera, translation
from tests.support.textured_scenes import environment_world

RNG = np.random.default_rng(17)
ABOVE = look_at((0.2, -0.1, 1.5), (0.0, 0.0, 0.0))  # shines down onto the shading points


def tilted_up():
    return look_at((0.3, 0.2, 1.2), (0.1, 0.0, 0.0))


LIGHTS = {
    "sphere": Light("POINT", translation(0.3, 0.1, 1.0), intensity=np.array([3.0, 2.0, 1.0]), radius=0.2,
                    soft_falloff=False),
    "soft disk": Light("POINT", translation(0.3, 0.1, 1.0), intensity=np.full(3, 3.0), radius=0.2),
    "spot sphere": Light("SPOT", ABOVE, intensity=np.full(3, 5.0), radius=0.1, soft_falloff=False,
                         spot_size=1.2, spot_blend=0.5),
    "spot disk": Light("SPOT", ABOVE, intensity=np.full(3, 5.0), radius=0.1, spot_size=1.2, spot_blend=0.5),
    "rectangle": Light("AREA", tilted_up(), radiance=np.array([1.0, 2.0, 3.0]), size_x=0.8, size_y=0.3),
    "square with spread": Light("AREA", tilted_up(), radiance=np.full(3, 2.0), size_x=0.5, size_y=0.5,
                                spread=1.0),
    "tiny rectangle (area sampled)": Light("AREA", tilted_up(), radiance=np.full(3, 2.0), size_x=1e-3,
                                           size_y=2e-3),
    "disk": Light("AREA", tilted_up(), radiance=np.full(3, 2.0), shape="DISK", size_x=0.6, size_y=0.6),
    "ellipse with spread": Light("AREA", tilted_up(), radiance=np.full(3, 2.0), shape="ELLIPSE", size_x=0.9,
                                 size_y=0.3, spread=2.0),
}


@pytest.mark.parametrize("name", list(LIGHTS))
def test_sampled_direction_hits_the_light_with_the_sampled_radiance_and_pdf(name):
    table = light_table([LIGHTS[name]])
    n = 4000
    pos = np.column_stack([RNG.uniform(-1, 1, n), RNG.uniform(-1, 1, n), np.zeros(n)])
    wi, dist, value, pdf = _sample_batch(table, 0, pos, RNG.random((n, 2)))
    lit = np.flatnonzero(value.max(axis=1) > 0)
    assert len(lit) > n // 4, "the light lights the points below it"
    assert np.allclose(np.linalg.norm(wi, axis=1), 1.0, atol=1e-12)
    o, d = pos[lit], wi[lit]
    t, hit, radiance = np.full(len(lit), np.inf), np.full(len(lit), -1, np.int64), np.zeros((len(lit), 3))
    _intersect_batch(table, np.array([0], np.int64), o, d, t, hit, radiance)
    assert (hit == 0).all()
    assert np.allclose(t, dist[lit], rtol=1e-6)
    assert np.allclose(radiance / pdf[lit, None], value[lit], rtol=1e-6)
    assert np.allclose(_pdf_batch(table, table, hit, 0, o, d, t, o), pdf[lit], rtol=1e-6)


def test_delta_lights_have_infinite_pdf_and_inverse_square_value():
    point = Light("POINT", translation(0, 0, 2.0), intensity=np.full(3, 4.0), radius=0.0)
    sun = Light("SUN", ABOVE, irradiance=np.full(3, 3.0))
    table = light_table([point, sun])
    pos = np.zeros((3, 3))
    pos[:, 0] = [0.0, 1.0, -2.0]
    u = RNG.random((3, 2))
    _, dist, value, pdf = _sample_batch(table, 0, pos, u)
    assert np.isinf(pdf).all() and np.allclose(value[:, 0], 4.0 / dist**2)
    wi, dist, value, pdf = _sample_batch(table, 1, pos, u)
    assert np.isinf(pdf).all() and np.isinf(dist).all() and np.allclose(value, 3.0)
    assert np.allclose(wi, -sun.direction)


def test_light_choice_picks_each_light_as_often_as_its_probability():
    lights = [Light("POINT", translation(*RNG.uniform([-3, -3, 0.5], [3, 3, 2])), intensity=RNG.uniform(0.5, 2, 3),
                    radius=RNG.uniform(0, 0.3)) for _ in range(9)]
    lights.append(Light("SUN", ABOVE, irradiance=np.full(3, 0.2)))
    table = light_table(lights)
    p = (0.4, -0.3, 0.0)
    prob = np.array([pick_probability(table, i, *p) for i in range(len(lights))])
    assert prob.sum() == pytest.approx(1.0, abs=1e-12) and (prob > 0).all()
    n = 20_000
    picks = [pick_light(table, *p, (k + 0.5) / n) for k in range(n)]  # stratified: counts exact to 1 / n
    counts = np.bincount([i for i, _ in picks], minlength=len(lights))
    assert np.allclose(counts / n, prob, atol=1.5 / n)
    assert all(q == pytest.approx(prob[i], rel=1e-12) for i, q in picks[:: n // 50])


def test_environment_samples_follow_the_density_map_pdf_states():
    h, w = 16, 32
    pixels = np.ones((h, w, 4), np.float32)
    pixels[..., :3] = RNG.gamma(0.5, 1.0, (h, w, 1)).astype(np.float32)  # uneven, grey
    env = Environment(environment_world(interpolation="Closest"),
                      [Texture(TextureImage("random", pixels=pixels, colorspace="Non-Color"))])
    n = 400_000
    dirs, pdf = env.sample(RNG.random((n, 2)))
    assert np.allclose(pdf, [map_pdf(env.cell, env.cell_area, env.sun, *d) for d in dirs[:200]] + list(pdf[200:]))
    # cell counts against the cells' probabilities: chi-square over the 64 x 32 table
    u = -np.arctan2(dirs[:, 1], dirs[:, 0]) / (2 * np.pi) + 0.5
    v = np.arctan2(dirs[:, 2], np.hypot(dirs[:, 0], dirs[:, 1])) / np.pi + 0.5
    cells = np.clip((v * env.h).astype(int), 0, env.h - 1) * env.w + np.clip((u * env.w).astype(int), 0, env.w - 1)
    expected = env.cell.ravel() * n
    observed = np.bincount(cells, minlength=env.h * env.w)
    keep = expected > 20
    chi2 = ((observed[keep] - expected[keep]) ** 2 / expected[keep]).sum()
    dof = keep.sum() - 1
    assert chi2 < dof + 5 * np.sqrt(2 * dof), (chi2, dof)


def test_scalar_equirect_direction_is_the_textures_one():
    uv = RNG.random((50, 2))
    scalar = np.array([direction_at(a, b) for a, b in uv])
    assert np.allclose(scalar, equirect_direction(uv), atol=1e-14)


def test_emissive_triangle_samples_have_the_pdf_of_pdf_emissive():
    mats = [Material("white", [Closure("DIFFUSE", color=(0.5,) * 3)]),
            Material("glow", [Closure("EMISSION", emission=(2.0, 1.0, 0.5))])]
    scene = SceneData(top_camera(), [plane(), plane(1.0, z=1.0, material=1)], [Instance(0, np.eye(4)),
                      Instance(1, translation(0.2, 0, 0))], mats)
    lights = Renderer(scene, RenderSettings(samples=1, threads=1)).lights
    n = 2000
    pos = np.column_stack([RNG.uniform(-1, 1, n), RNG.uniform(-1, 1, n), np.zeros(n)])
    ls = lights.sample(0, pos, np.tile([0, 0, 1.0], (n, 1)), RNG.random((n, 2)), RNG.random(n))
    hits = lights.geometry.intersect(pos + 1e-6 * ls.wi, ls.wi, np.full(n, np.inf))
    assert hits.hit.all() and np.allclose(hits.t + 1e-6, ls.dist, rtol=1e-5)
    pdf = lights.pdf_emissive(hits.prim, pos, ls.wi, ls.dist)
    assert np.allclose(pdf, ls.pdf, rtol=1e-5)
    assert np.allclose(ls.value * ls.pdf[:, None], [2.0, 1.0, 0.5], rtol=1e-9)


def _rotation_z(angle, at):
    m = translation(*at)
    c, s = np.cos(angle), np.sin(angle)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


@pytest.mark.parametrize("kind", ["AREA", "SPOT"])
def test_a_moving_light_at_a_time_is_the_still_light_where_it_is_then(kind):
    """Sampled, hit and weighted in its own frame: at mid-shutter, directions sampled toward a
    light moving from one pose to another (a quarter turn and a shift) meet the still light
    at the middle pose at the sampled distance, with the sampled radiance and pdf."""
    def light(matrix, matrices=None):
        if kind == "AREA":
            return Light("AREA", matrix, radiance=np.full(3, 2.0), size_x=0.8, size_y=0.3, matrices=matrices)
        return Light("SPOT", matrix, intensity=np.full(3, 5.0), radius=0.2, spot_size=2.0, matrices=matrices)

    start, end = _rotation_z(0.0, (-0.4, 0, 1)), _rotation_z(np.pi / 2, (0.4, 0, 1))
    mats = [Material("white", [Closure("DIFFUSE", color=(0.5,) * 3)])]
    moving, still = [Renderer(SceneData(top_camera(), [plane()], [Instance(0, np.eye(4))], mats, [lt]),
                              RenderSettings(samples=1, threads=1)).lights
                     for lt in (light(start, np.stack([start, end])), light(_rotation_z(np.pi / 4, (0, 0, 1))))]
    assert moving.moving and not still.moving
    n = 3000
    pos = np.column_stack([RNG.uniform(-1, 1, n), RNG.uniform(-1, 1, n), np.zeros(n)])
    time = np.full(n, 0.5)
    ls = moving.sample(0, pos, np.tile([0, 0, 1.0], (n, 1)), RNG.random((n, 2)), None, None, time)
    lit = np.flatnonzero(ls.value.max(axis=1) > 0)
    assert len(lit) > n // 2
    o, d, inf = pos[lit], ls.wi[lit], np.full(len(lit), np.inf)
    t_moving, hit_moving, le_moving = moving.intersect(o, d, inf, time[lit])
    t_still, hit_still, le_still = still.intersect(o, d, inf)
    assert (hit_moving == 0).all() and (hit_still == 0).all()
    assert np.allclose(t_moving, ls.dist[lit], rtol=1e-6) and np.allclose(t_still, ls.dist[lit], rtol=1e-6)
    assert np.allclose(le_moving / ls.pdf[lit, None], ls.value[lit], rtol=1e-6)
    assert np.allclose(le_still, le_moving, rtol=1e-6)
    assert np.allclose(moving.pdf(0, o, d, t_moving, time[lit]), ls.pdf[lit], rtol=1e-6)
    assert np.allclose(still.pdf(0, o, d, t_still), ls.pdf[lit], rtol=1e-6)
