"""Light groups (core.integrator.lightgroups): each group's pass holds what its emitters give to
Combined, so where every emitter is in a group the groups sum to Combined up to float rounding;
light no group owns is in Combined alone; without group passes nothing changes."""
from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.render import merge
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings, lightgroup_pass
from tests.support import split_render
from tests.support.scenes import plane, render_passes, top_camera, translation, uv_sphere

GROUPS = ["key", "fill", "glow"]
PASSES = ("Combined",) + tuple(lightgroup_pass(g) for g in GROUPS)


def scene(key=0, fill=1, glow=2, world=2) -> SceneData:
    """A floor (diffuse and glossy), a glossy sphere, a see-through sheet (transparent shadows), an
    area light (``key``), a point light with a radius and a sun with an angle (``fill``), an emissive
    sphere (``glow``) and a lit world (``world``): every kind of contribution, emitters in groups."""
    floor = Material("floor", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5), weight=(0.7,) * 3),
                               Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.3, weight=(0.3,) * 3)])
    metal = Material("metal", [Closure("GLOSSY", color=(0.9, 0.7, 0.5), roughness=0.2)])
    sheet = Material("sheet", [Closure("TRANSPARENT", color=(0.6, 0.3, 0.15))])
    glow_mat = Material("glow", [Closure("EMISSION", emission=(3.0, 1.0, 0.3))])
    meshes = [plane(10.0), uv_sphere(0.4, (0.4, 0.3, 0.4), 24, 12, material=1), plane(0.5, 1.2, material=2),
              uv_sphere(0.2, (-0.6, -0.4, 0.6), 16, 8, material=3)]
    instances = [Instance(k, np.eye(4)) for k in range(len(meshes))]
    instances[3] = replace(instances[3], lightgroup=glow)
    area = translation(0.5, -0.5, 2.0)
    lights = [Light("AREA", area, radiance=np.array([4.0, 3.0, 2.0]), size_x=0.5, size_y=0.5, lightgroup=key),
              Light("POINT", translation(-0.8, 0.6, 1.5), intensity=np.array([2.0, 5.0, 8.0]), radius=0.2,
                    lightgroup=fill),
              Light("SUN", np.eye(4), irradiance=np.array([0.5, 0.5, 0.6]), angle=0.2, lightgroup=fill)]
    return SceneData(top_camera(3.0, 0.5, 24), meshes, instances, [floor, metal, sheet, glow_mat], lights,
                     World(radiance=np.array([0.1, 0.15, 0.3]), lightgroup=world), light_groups=list(GROUPS))


def render(data, passes=PASSES, **settings):
    return render_passes(data, passes, **settings)


@pytest.mark.parametrize("settings", [{}, {"diffuse_bounces": 2}, {"sample_clamp_direct": 0.5,
                                                                   "sample_clamp_indirect": 0.2}],
                         ids=["classic", "diffuse bounces", "clamped"])
def test_groups_sum_to_combined_when_every_emitter_is_in_one(settings):
    passes = render(scene(), **settings)
    combined = passes["Combined"][..., :3].astype(np.float64)
    groups = [passes[lightgroup_pass(g)].astype(np.float64) for g in GROUPS]
    for image in groups:  # each group lights the image (none is empty), none holds all of it
        assert image.shape == combined.shape and image.mean() > 0.02 * combined.mean()
        assert np.abs(image - combined).mean() > 0.05 * combined.mean()
    np.testing.assert_allclose(sum(groups), combined, rtol=1e-5, atol=1e-6)


def test_an_emitter_in_no_group_is_in_combined_alone():
    """The world and the emissive sphere in no group: the groups hold the lights' light alone, the
    rest of Combined is what a render with only those two emitters gives."""
    passes = render(scene(glow=-1, world=-1))
    lit = passes[lightgroup_pass("key")] + passes[lightgroup_pass("fill")]
    assert passes[lightgroup_pass("glow")].max() == 0.0
    data = scene(glow=-1, world=-1)
    data.lights = []
    rest = render(data, passes=("Combined",))["Combined"][..., :3]
    np.testing.assert_allclose(lit + rest, passes["Combined"][..., :3], rtol=1e-4, atol=1e-5)


def test_group_passes_leave_combined_as_it_was():
    """Light groups add passes and change no pixel of Combined (nor does a scene's groups without their passes)."""
    with_groups = render(scene())["Combined"]
    without = render(scene(), passes=("Combined",))["Combined"]
    assert np.array_equal(with_groups, without)


def test_group_passes_travel_through_parts_and_merge(tmp_path):
    """A split render's parts carry the group passes; merged, they are the whole render's."""
    def part(start, end):
        settings = RenderSettings(samples=8, threads=1, max_depth=4, passes=PASSES, sample_start=start,
                                  sample_end=end)
        return split_render.render_part(scene(), settings)

    _, whole = part(0, 0)
    merged = split_render.merged([part(a, b)[0] for a, b in ((0, 3), (3, 8))], tmp_path).film.images()
    for group in GROUPS:
        name = lightgroup_pass(group)
        np.testing.assert_allclose(merged[name], whole.passes[name], rtol=1e-5, atol=1e-7)
    merge.write_exr(tmp_path / "merged.exr", merged, "ViewLayer")
