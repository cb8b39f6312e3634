"""IES profiles read and looked up as Cycles does (core.shading.ies), and a light whose node tree
varies its emission (core.lights.programs): each light sample and each ray that hits the light
carries the program's value for that direction, and such a light has no closed form. The images
against Cycles: tests/blender/test_ies_cycles.py."""
from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.lights.collection import closed_forms
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.scene import Light, Program
from drt_engine.core.shading import ies
from tests.support.ies_profiles import ASYMMETRIC, QUADRANT, TYPE_B, V_FULL, lm63
from tests.support.scenes import lit_plane_scene, look_at, translation

RNG = np.random.default_rng(23)
SCALE = ies.CANDELA_TO_WATT


def directions(n):
    d = RNG.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def at_angles(h, v):
    """The direction whose IES angles are horizontal h, vertical v (radians): v from the nadir,
    h = atan2(x, y) + pi."""
    return np.column_stack([-np.sin(v) * np.sin(h), -np.sin(v) * np.cos(h), -np.cos(v)])


def test_a_full_type_c_profile_keeps_its_angles_and_scales_candela_to_cycles_watts():
    h, v, grid = ies.parse(ASYMMETRIC)
    assert np.allclose(np.degrees(v), V_FULL, atol=1e-4) and np.isclose(np.degrees(h[-1]), 360.0, atol=1e-4)
    text = lm63([0.0, 90.0, 180.0], [0.0, 360.0], [[10.0, 20.0, 30.0], [10.0, 20.0, 30.0]], multiplier=2.0)
    _, _, grid = ies.parse(text)
    assert np.allclose(grid, np.array([[20.0, 40.0, 60.0]] * 2) * SCALE)


def test_lookup_gives_the_table_at_its_angles():
    h, v, grid = profile = ies.parse(ASYMMETRIC)
    hh, vv = np.meshgrid(np.arange(1, len(h) - 1), np.arange(1, len(v) - 1), indexing="ij")
    got = ies.lookup(profile, at_angles(h[hh.ravel()], v[vv.ravel()]), np.ones(hh.size))
    assert np.allclose(got, grid[hh.ravel(), vv.ravel()], rtol=1e-5)


def test_one_quadrant_is_mirrored_to_the_whole_circle():
    profile = ies.parse(QUADRANT)
    assert np.isclose(np.degrees(profile[0][-1]), 360.0, atol=1e-4)
    h, v = RNG.uniform(0.0, np.pi / 2, 200), RNG.uniform(0.0, 1.4, 200)
    values = [ies.lookup(profile, at_angles(a, v), np.ones(200)) for a in (h, np.pi - h, np.pi + h, 2 * np.pi - h)]
    assert values[0].max() > 0 and all(np.allclose(values[0], other, rtol=1e-5) for other in values[1:])


def test_nothing_leaves_where_the_table_has_no_angles():
    quadrant = ies.parse(QUADRANT)  # vertical angles 0 to 90: the lower hemisphere
    up = np.column_stack([RNG.normal(size=(100, 2)), np.full(100, 0.5)])
    assert not ies.lookup(quadrant, up, np.ones(100)).any()
    type_b = ies.parse(TYPE_B)  # type B as Cycles reads it: horizontal angles 0 to 180 only
    assert np.isclose(np.degrees(type_b[0][-1]), 180.0, atol=1e-4)
    values = ies.lookup(type_b, directions(2000), np.ones(2000))
    assert (values >= 0).all() and np.isfinite(values).all() and (values == 0).mean() > 0.3


def test_a_profile_cycles_cannot_read_is_none_and_looks_up_as_cycles_constant():
    assert ies.parse("") is None and ies.parse("IESNA:LM-63\nno tilt here\n") is None
    assert ies.parse(ASYMMETRIC.replace(" 1 2 0.1", " 7 2 0.1", 1)) is None  # photometric type 7
    assert np.allclose(ies.lookup(None, directions(3), np.array([1.0, 2.0, 0.5])), [100.0, 200.0, 50.0])


def _ies_program(text):
    """Incoming carried into the light's space, into an IES Texture: a light's default."""
    prog = Program()
    incoming = prog.add("coord", name="incoming")
    local = prog.add("vector_transform", [(incoming, 0)], type="NORMAL", **{"from": "WORLD", "to": "OBJECT"})
    strength = prog.add("const", value=1.0)
    return prog, (prog.add("ies", [(local, 0), (strength, 0)], profile=ies.parse(text)), 0)


@pytest.fixture(scope="module")
def lit():
    """A floor under a turned point light and a sphere light, with the asymmetric profile and without."""
    program, emission = _ies_program(ASYMMETRIC)
    lights = [Light("POINT", look_at((0.2, -0.1, 1.5), (0.5, 0.3, 0.0)), intensity=np.full(3, 2.0)),
              Light("POINT", translation(-0.4, 0.2, 1.2), intensity=np.full(3, 1.0), radius=0.2, soft_falloff=False)]
    base = replace(lit_plane_scene(lights[0]), lights=lights)
    with_ies = replace(base, lights=[replace(light, program=program, emission=emission) for light in lights])
    return PreparedScene(base).lights, PreparedScene(with_ies).lights


def test_each_light_sample_carries_the_profile_toward_its_point(lit):
    plain, profiled = lit
    n = 500
    pos = np.column_stack([RNG.uniform(-1, 1, (n, 2)), np.zeros(n)])
    up, u = np.tile([0.0, 0.0, 1.0], (n, 1)), RNG.random((n, 2))
    profile = ies.parse(ASYMMETRIC)
    for k, light in enumerate(profiled.lights):
        a, b = plain.sample(k, pos, up, u), profiled.sample(k, pos, up, u)
        assert np.allclose(a.wi, b.wi) and np.allclose(a.pdf, b.pdf)
        rotation = light.matrix[:3, :3]
        local = -b.wi @ rotation  # from the light toward the point, in its space
        factor = ies.lookup(profile, local, np.ones(n))
        assert factor.max() > 0 and np.allclose(b.value, a.value * factor[:, None], rtol=1e-9)


def test_a_ray_that_hits_the_light_sees_the_profile_along_it(lit):
    plain, profiled = lit
    n = 400
    origins = np.column_stack([RNG.uniform(-1, 1, (n, 2)), np.zeros(n)])
    centre = profiled.lights[1].matrix[:3, 3]
    dirs = centre + RNG.normal(scale=0.05, size=(n, 3)) - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    t, light_id, le = plain.intersect(origins, dirs, np.full(n, np.inf))
    assert (light_id == 1).mean() > 0.5
    seen = profiled.emitted(light_id, origins, dirs, t, le.copy())
    factor = ies.lookup(ies.parse(ASYMMETRIC), -dirs, np.ones(n))  # from the light back along the ray
    hit = light_id == 1
    assert np.allclose(seen[hit], le[hit] * factor[hit, None], rtol=1e-9)


def test_a_light_whose_tree_varies_has_no_closed_form(lit):
    plain, profiled = lit
    assert closed_forms(plain.table).all() and not closed_forms(profiled.table).any()


def test_a_sun_takes_its_tree_once_along_the_direction_it_shines():
    program, emission = _ies_program(ASYMMETRIC)
    sun = Light("SUN", look_at((0.3, -0.2, 1.0), (0.0, 0.0, 0.0)), irradiance=np.full(3, 2.0))
    lights = PreparedScene(lit_plane_scene(replace(sun, program=program, emission=emission))).lights
    along = ies.lookup(ies.parse(ASYMMETRIC), np.array([[0.0, 0.0, -1.0]]), np.ones(1))[0]
    assert lights.lights[0].program is None and np.allclose(lights.lights[0].irradiance, 2.0 * along)
