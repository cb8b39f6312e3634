"""Clamp Direct and Clamp Indirect (core.integrator.clamp), per contribution as Cycles clamps.

In a closed mirror furnace of emission E and mirror colour a (tests/core/test_bounce_limits), the
camera sees E (direct, bounce 0) and each mirror bounce i adds a^i E (indirect): clamped to c,
each of them alone is min(a^i E, c) for a white one (the sum of its RGB within 3 c), so

    L = min(E, c_direct) + sum over i = 1..8 of min(a^i E, c_indirect)   (Total 8),

which a clamp of the sample's total, or of the wrong bounces, misses.
"""
import numpy as np
import pytest

from drt_engine.core.errors import SettingsError
from drt_engine.core.film.parts import Part
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import top_camera, uv_sphere

ALBEDO, E = 0.8, 5.0


def mirror_furnace():
    mat = Material("glowing mirror", [Closure("GLOSSY", color=np.full(3, ALBEDO), roughness=0.0),
                                      Closure("EMISSION", emission=np.full(3, E))])
    sphere = uv_sphere(1.0, segments=16, rings=8, smooth=False)
    camera = top_camera(height=0.0, half_width=0.5, res=8)
    return SceneData(camera, [sphere], [Instance(0, np.eye(4))], [mat], [], World(np.zeros(3)))


def mean(**settings):
    result = Renderer(mirror_furnace(), RenderSettings(samples=4, threads=1, **settings)).render()
    return result.passes["Combined"][..., :3].mean()


@pytest.mark.parametrize("direct, indirect", [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (2.0, 3.0)])
def test_each_contribution_is_clamped_by_its_bounce(direct, indirect):
    def within(value, c):
        return min(value, c) if c > 0 else value

    expected = within(E, direct) + sum(within(ALBEDO ** i * E, indirect) for i in range(1, 9))
    assert mean(sample_clamp_direct=direct, sample_clamp_indirect=indirect) == pytest.approx(expected, rel=1e-4)


def test_negative_clamps_are_refused():
    with pytest.raises(SettingsError):
        RenderSettings(sample_clamp_indirect=-1.0)


def test_a_part_from_before_the_two_clamps_reads_its_one_clamp_as_both():
    settings = {"samples": 4, "passes": ["Combined"], "clamp": 2.5}
    old = Part(1, 1, np.ones(1), np.ones(1), np.zeros((1, 3)), {}, header={"settings": settings})
    read = old.settings()
    assert read.sample_clamp_direct == read.sample_clamp_indirect == 2.5


def test_the_ratio_estimator_is_clamped_as_combined():
    """A diffuse plane of albedo 0.5 under a soft sun of irradiance 100 (radiance 15.9): each light
    sample is clamped to 1, and the ratio estimator's U N / D, with N the clamped samples, is too."""
    from tests.support.scenes import lit_plane_scene

    sun = Light("SUN", np.eye(4), irradiance=np.full(3, 100.0), angle=0.1)
    values = {}
    for estimator in ("MONTE_CARLO", "RATIO"):
        settings = RenderSettings(samples=4, threads=1, sample_clamp_direct=1.0, shadow_estimator=estimator)
        values[estimator] = Renderer(lit_plane_scene(sun), settings).render().passes["Combined"][..., :3].mean()
    assert values["MONTE_CARLO"] == pytest.approx(1.0, rel=1e-4)
    assert values["RATIO"] == pytest.approx(1.0, rel=1e-4)  # 15.9 when N and D both took the clamp
