"""The Sky Texture's sun disc as the world's light sampling sees it: the map's sun cone lands every
one of its samples on the disc, and the light it gives a surface through the map's density
equals a quadrature of the disc's radiance (the density of the cone-and-table mixture is
right where the sun is). Hosek / Wilkie over its whole range, its table's rows and blends;
Blender 4's Nishita disc and ground (each model against Cycles: tests/blender/test_node_parity.py)."""
import math

import numpy as np
import pytest

from drt_engine.core.lights.environment import Environment, map_pdf
from drt_engine.core.scene import Program, World
from drt_engine.core.shading import sky, sky_hosek
from drt_engine.core.shading.sky_hosek_table import CONFIGURATIONS, RADIANCES

RNG = np.random.default_rng(5)
SKY = dict(sky_type="MULTIPLE_SCATTERING", sun_disc=True, sun_size=0.0095, sun_intensity=1.0,
           sun_elevation=0.5, sun_rotation=0.7, altitude=100.0, air_density=1.0, aerosol_density=1.0,
           ozone_density=1.0)


def sky_world(params=SKY):
    prog = Program()
    d = prog.add("coord", name="generated")
    return World(program=prog, color=(prog.add("sky", [(d, 0)], **params), 0))


@pytest.fixture(scope="module")
def env():
    return Environment(sky_world(), [])


def test_the_sun_cone_holds_most_samples_and_each_lands_on_the_disc(env):
    direction, radius = sky.sky_sun(SKY)
    assert env.sun[4] > 0.5  # the sun outshines the sky by far
    n = 20_000
    dirs, pdf = env.sample(RNG.random((n, 2)))
    on_disc = dirs @ direction >= math.cos(radius)
    assert on_disc.mean() >= env.sun[4]
    sun_radiance = sky.evaluate(SKY, dirs[on_disc]).mean()
    assert sun_radiance > 1e3 * sky.evaluate(SKY, dirs[~on_disc]).mean()
    assert np.allclose(pdf[:100], [map_pdf(env.cell, env.cell_area, env.sun, *d) for d in dirs[:100]])


def test_disc_light_through_the_map_density_equals_its_quadrature(env):
    direction, radius = sky.sky_sun(SKY)
    normal = np.array([0.0, 0.0, 1.0])
    # quadrature over the disc in polar coordinates about its centre
    t0 = np.cross(direction, [0.0, 0.0, 1.0])
    t0 /= np.linalg.norm(t0)
    t1 = np.cross(direction, t0)
    r = (np.arange(400) + 0.5) / 400 * radius
    phi = (np.arange(400) + 0.5) / 400 * 2 * np.pi
    rr, pp = (x.ravel() for x in np.meshgrid(r, phi))
    d = (np.cos(rr)[:, None] * direction + np.sin(rr)[:, None] * (np.cos(pp)[:, None] * t0
                                                                   + np.sin(pp)[:, None] * t1))
    weight = np.sin(rr) * (radius / 400) * (2 * np.pi / 400)
    expected = (sky.evaluate(SKY, d) * ((d @ normal) * weight)[:, None]).sum(axis=0)
    n = 400_000
    dirs, pdf = env.sample(RNG.random((n, 2)))
    off_disc = dirs @ direction < math.cos(radius)
    value = sky.evaluate(SKY, dirs) * (np.maximum(dirs @ normal, 0.0) / pdf)[:, None]
    value[off_disc] = 0.0
    estimate = value.mean(axis=0)
    assert np.allclose(estimate, expected, rtol=0.01), (estimate, expected)


HOSEK = dict(sky_type="HOSEK_WILKIE", sun_direction=(0.3, 0.8, 0.35), turbidity=2.2, ground_albedo=0.3)


def _directions(n=4000):
    d = RNG.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


@pytest.mark.parametrize("turbidity", [1.0, 2.2, 6.5, 9.99, 10.0])
@pytest.mark.parametrize("albedo", [0.0, 0.6, 1.0])
def test_hosek_wilkie_is_finite_and_positive_over_its_whole_range(turbidity, albedo):
    """Every turbidity and albedo Blender allows, the sun from the zenith to below the horizon
    (Cycles holds it on the horizon): a finite, non-negative sky in every direction."""
    for sun in [(0.0, 0.0, 1.0), (0.3, 0.8, 0.35), (1.0, 0.0, 0.0), (0.2, 0.3, -0.5)]:
        rgb = sky.evaluate(dict(HOSEK, turbidity=turbidity, ground_albedo=albedo, sun_direction=sun), _directions())
        assert np.isfinite(rgb).all() and (rgb >= 0.0).all() and rgb.max() > 0.0


def test_hosek_wilkie_takes_the_tables_rows_at_their_own_settings():
    """At a whole turbidity and albedo 0 or 1 the coefficients are the table's row for them: its
    first control point with the sun on the horizon, its last with the sun at the zenith."""
    for sun, point in (((1.0, 0.0, 0.0), 0), ((0.0, 0.0, 1.0), 5)):
        for turbidity in (1, 4, 10):
            for albedo in (0, 1):
                _, _, config, radiance = sky_hosek.coefficients(dict(HOSEK, sun_direction=sun, turbidity=float(turbidity),
                                                                     ground_albedo=float(albedo)))
                assert np.allclose(config, CONFIGURATIONS[:, albedo, turbidity - 1, point])
                assert np.allclose(radiance, RADIANCES[:, albedo, turbidity - 1, point])


def test_hosek_wilkie_blends_turbidity_and_albedo_linearly():
    half = sky_hosek.coefficients(dict(HOSEK, turbidity=3.5, ground_albedo=0.5))
    ends = [sky_hosek.coefficients(dict(HOSEK, turbidity=t, ground_albedo=a)) for t in (3.0, 4.0) for a in (0.0, 1.0)]
    assert np.allclose(half[2], np.mean([e[2] for e in ends], axis=0))
    assert np.allclose(half[3], np.mean([e[3] for e in ends], axis=0))


NISHITA = dict(SKY, sky_type="NISHITA", sun_elevation=0.3, sun_size=0.02)


def test_nishita_shows_the_disc_in_place_of_the_sky():
    """Blender 4's Nishita: inside the disc the sky behind it is not added (Blender 5's models add
    it), so the disc's centre is the disc's colour alone, as its Single Scattering disc minus the sky."""
    centre = sky.sun_direction(sky.settings(NISHITA))[None, :]
    single = dict(NISHITA, sky_type="SINGLE_SCATTERING")
    behind = sky.evaluate(dict(single, sun_disc=False), centre)
    assert np.allclose(sky.evaluate(NISHITA, centre), sky.evaluate(single, centre) - behind, rtol=1e-3)


def test_nishita_ground_fades_the_horizon_to_black():
    d = np.array([[np.sqrt(1.0 - z * z), 0.0, z] for z in (0.0, -0.1, -0.2, -0.39, -0.41, -0.9)])
    rgb = sky.evaluate(dict(NISHITA, sun_disc=False), d)
    horizon = rgb[0]
    assert np.allclose(rgb[1:4], horizon * ((1.0 + 2.5 * d[1:4, 2]) ** 3)[:, None])
    assert (rgb[4:] == 0.0).all() and horizon.max() > 0.0
