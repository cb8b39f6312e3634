"""Cycles' Glossy and Transmission bounce limits (core.integrator.bounces).

Inside a closed polyhedron whose every face emits E and is a perfect mirror of colour a, the
camera sees E, and each mirror bounce adds the emission its ray finds, a^i E after i bounces.
With glossy bounces g the path takes g bounces and the ray of bounce g + 1 still sees what it
hits (Cycles' limit is the setting + 1, and a path past it ends at its next hit):

    L_g = E (1 + a + ... + a^(g+1)),

exact (delta lobes draw no random numbers that change the value). A limit of g or more at the
Total never binds, so paths carry no depths for it and images do not change.
"""
import numpy as np
import pytest

from drt_engine.core.errors import SettingsError
from drt_engine.core.integrator.bounces import LIMIT_TRANSPARENCY, binding
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import top_camera, uv_sphere

ALBEDO, E = 0.8, 1.0


def mirror_furnace(*extra):
    mat = Material("glowing mirror", [Closure("GLOSSY", color=np.full(3, ALBEDO), roughness=0.0),
                                      Closure("EMISSION", emission=np.full(3, E)), *extra])
    sphere = uv_sphere(1.0, segments=16, rings=8, smooth=False)
    camera = top_camera(height=0.0, half_width=0.5, res=8)
    return SceneData(camera, [sphere], [Instance(0, np.eye(4))], [mat], [], World(np.zeros(3)))


def mean(scene, **settings):
    result = Renderer(scene, RenderSettings(samples=4, threads=1, **settings)).render()
    return result.passes["Combined"][..., :3].mean()


@pytest.mark.parametrize("g", [0, 1, 3])
def test_glossy_bounces_end_the_mirror_furnace(g):
    expected = E * sum(ALBEDO ** i for i in range(g + 2))
    assert mean(mirror_furnace(), max_depth=16, glossy_bounces=g) == pytest.approx(expected, rel=1e-4)


def test_a_limit_at_the_total_does_not_bind():
    assert not binding(RenderSettings())  # the defaults: Total 8, glossy and transmission 8
    assert binding(RenderSettings(max_depth=9)) and binding(RenderSettings(transmission_bounces=2))
    full = E * sum(ALBEDO ** i for i in range(9))  # the Total alone: 8 bounces
    assert mean(mirror_furnace(), max_depth=8) == pytest.approx(full, rel=1e-4)
    assert mean(mirror_furnace(), max_depth=8, transmission_bounces=0) == pytest.approx(full, rel=1e-4)


def test_a_binding_limit_over_transparency_is_named_in_a_warning():
    clear = Closure("TRANSPARENT", color=np.full(3, 0.5))
    warned = Renderer(mirror_furnace(clear), RenderSettings(samples=1, threads=1, glossy_bounces=1)).warnings
    assert LIMIT_TRANSPARENCY in warned
    assert LIMIT_TRANSPARENCY not in Renderer(mirror_furnace(clear), RenderSettings(samples=1, threads=1)).warnings


def test_negative_limits_are_refused():
    with pytest.raises(SettingsError):
        RenderSettings(glossy_bounces=-1)
