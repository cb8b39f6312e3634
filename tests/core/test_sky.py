"""The Sky Texture's sun disc as the world's light sampling sees it: the map's sun cone lands every
one of its samples on the disc, and the light it gives a surface through the map's density
equals a quadrature of the disc's radiance (the density of the cone-and-table mixture is
right where the sun is)."""
import math

import numpy as np
import pytest

from drt_engine.core.lights.environment import Environment, map_pdf
from drt_engine.core.scene import Program, World
from drt_engine.core.shading import sky

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
