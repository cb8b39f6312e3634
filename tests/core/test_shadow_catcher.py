"""Shadow catchers in the core (core.integrator.shadow_catcher, core.film.shadow_catcher): a floor
that is a catcher under an area light and a lit world, a sphere over it. The catcher paths start on
the camera's own rays with the same sample values as the paths they split from (Cycles copies the
state): with nothing shading the floor they bring exactly its light, so the Shadow Catcher pass
reads 1; the sphere's shadow reads below 1; parts merged read as the whole render."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.film.shadow_catcher import catcher_ratio, combined_read
from drt_engine.core.integrator.shadow_catcher import NOT_DENOISED
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import RenderSettings, lightgroup_pass
from tests.support import split_render
from tests.support.scenes import plane, render_passes, top_camera, translation, uv_sphere
from tests.support.textured_scenes import with_image_world

PASSES = ("Combined", "Shadow Catcher")


def scene(sphere_z=0.5, transparent=True) -> SceneData:
    floor = Material("floor", [Closure("DIFFUSE", color=(0.6, 0.5, 0.4))])
    ball = Material("ball", [Closure("DIFFUSE", color=(0.8, 0.2, 0.1))])
    meshes = [plane(10.0), uv_sphere(0.3, (0.0, 0.0, sphere_z), 24, 12, material=1)]
    instances = [Instance(0, np.eye(4), name="floor", shadow_catcher=True), Instance(1, np.eye(4), name="ball")]
    lights = [Light("AREA", translation(0.3, 0.2, 2.0), radiance=np.array([4.0, 3.0, 2.0]), size_x=0.5, size_y=0.5)]
    return SceneData(top_camera(3.0, 0.5, 16), meshes, instances, [floor, ball], lights,
                     World(radiance=np.array([0.1, 0.15, 0.3])), film_transparent=transparent)


def test_the_pass_reads_one_where_nothing_shades_the_catcher():
    """The sphere far above the camera's view and the light (no shadow on the floor in view): the
    catcher paths bring what the split paths bring, so the pass is 1 and Combined transparent there."""
    passes = render_passes(scene(sphere_z=50.0), PASSES)
    np.testing.assert_allclose(passes["Shadow Catcher"], 1.0, atol=1e-5)
    assert passes["Combined"][..., 3].max() < 1e-5 and passes["Combined"][..., :3].max() == 0.0


@pytest.mark.parametrize("transparent", [True, False])
def test_the_shadow_reads_below_one_and_is_the_alpha_of_combined(transparent):
    """With the sphere's shadow: the pass dark under it. With the pass, Combined is the matte (the
    sphere over a transparent floor); without it, Cycles' approximate shadow: alpha
    (1 - a) (1 - mean(pass)) + a over a transparent film (a the matte's alpha), and over an opaque
    one the world darkened by the pass where the floor alone shows."""
    data = scene(transparent=transparent)
    with_pass = render_passes(data, PASSES)
    shadow, matte = with_pass["Shadow Catcher"].mean(axis=2), with_pass["Combined"]
    combined = render_passes(data, ("Combined",))["Combined"]
    assert shadow.min() < 0.7 and with_pass["Shadow Catcher"].max() <= 1.0 + 1e-5
    a = matte[..., 3]
    assert a.min() == 0.0 and a.max() == 1.0  # the floor held out of the matte, the sphere in it
    if transparent:
        np.testing.assert_allclose(combined[..., 3], (1.0 - a) * (1.0 - shadow) + a, atol=1e-5)
        np.testing.assert_allclose(combined[..., :3], matte[..., :3], atol=1e-6)
    else:
        assert np.all(combined[..., 3] == 1.0)
        floor = a == 0.0
        world = np.array([0.1, 0.15, 0.3])
        np.testing.assert_allclose(combined[..., :3][floor], world * shadow[floor][:, None], rtol=1e-4, atol=1e-6)


def grouped_scene(transparent) -> SceneData:
    """The scene with its light in group ``key`` and its world in ``sky``."""
    data = scene(transparent=transparent)
    data.lights = [replace(light, lightgroup=0) for light in data.lights]
    data.world = replace(data.world, lightgroup=1)
    data.light_groups = ["key", "sky"]
    return data


@pytest.mark.parametrize("transparent", [True, False])
def test_light_passes_and_groups_leave_out_what_paths_bring_after_a_catcher(transparent):
    """As Cycles' film (nothing for a path that met a catcher): the floor's pixels, every sample split
    there, hold no direct diffuse light nor any group's light; the sphere's hold its light; the groups
    sum to the matte with the world the camera sees (Combined over an opaque film with the pass),
    whatever the film. Env takes, over an opaque film, the world behind the floor (Cycles' split-off
    path shades its Background pass there)."""
    data = grouped_scene(transparent)
    groups = [lightgroup_pass("key"), lightgroup_pass("sky")]
    passes = render_passes(data, PASSES + ("DiffDir", "Env", *groups))
    opaque = render_passes(grouped_scene(False), PASSES)["Combined"]
    floor = opaque[..., 3] == 0.0  # the matte: the floor held out
    ball = opaque[..., 3] == 1.0  # the sphere, every sample on it
    assert floor.mean() > 0.5 and ball.any()
    assert passes["DiffDir"][floor].max() == 0.0 and passes["DiffDir"][ball].min() > 0.0
    assert passes[groups[0]][floor].max() == 0.0
    np.testing.assert_allclose(passes[groups[0]] + passes[groups[1]], opaque[..., :3], rtol=1e-5, atol=1e-6)
    world = np.array([0.1, 0.15, 0.3])
    np.testing.assert_allclose(passes["Env"][floor], 0.0 if transparent else np.broadcast_to(world, (floor.sum(), 3)),
                               atol=1e-6)


def test_emit_counts_an_emissive_catcher_twice_as_cycles():
    """Cycles writes a catcher's own emission to Emit from the path that split there and from the one
    split off (neither is a light-pass bounce: film_write_emission_or_background_pass): twice."""
    data = scene(sphere_z=50.0)
    data.materials[0] = Material("floor", [Closure("DIFFUSE", color=(0.6, 0.5, 0.4)),
                                           Closure("EMISSION", emission=(0.5, 0.25, 0.125))])
    emit = render_passes(data, PASSES + ("Emit",))["Emit"]
    np.testing.assert_allclose(emit, np.broadcast_to([1.0, 0.5, 0.25], emit.shape), rtol=1e-5)


def test_film_reads_as_cycles():
    """Cycles' film_calculate_shadow_catcher and matte-with-shadow on sums: no split reads 1, a 0
    catcher light reads 1 in that channel, Combined's alpha lays the ratio over white."""
    combined = np.array([[0.5, 0.2, 0.0, 1.0], [0.3, 0.3, 0.3, 0.5], [0.2, 0.2, 0.2, 1.0]])
    matte = np.array([[0.1, 0.0, 0.0, 0.0], [0.1, 0.1, 0.1, 0.5], [0.2, 0.2, 0.2, 1.0]])
    light = np.array([[0.8, 0.4, 0.0], [0.4, 0.4, 0.4], [0.0, 0.0, 0.0]])
    ratio = catcher_ratio(combined, matte, light, np.array([4.0, 2.0, 0.0]))
    np.testing.assert_allclose(ratio, [[0.5, 0.5, 1.0], [0.75, 0.75, 0.75], [1.0, 1.0, 1.0]])
    np.testing.assert_allclose(combined_read(matte, ratio, None)[:, 3], [1 / 3, 0.625, 1.0])
    opaque = combined_read(matte, ratio, np.array([[1.0, 1.0, 1.0]] * 3))
    np.testing.assert_allclose(opaque[:, 3], 1.0)
    np.testing.assert_allclose(opaque[0, :3], [0.1 + 2 / 3, 2 / 3, 2 / 3])


@pytest.mark.parametrize("transparent", [True, False])
def test_shadow_catcher_travels_through_parts_and_merge(tmp_path, transparent):
    """A split render's parts carry the catcher sums; merged, Combined and the pass are the whole render's."""
    def part(start, end, passes):
        settings = RenderSettings(samples=8, threads=1, max_depth=4, passes=passes, sample_start=start,
                                  sample_end=end)
        return split_render.render_part(scene(transparent=transparent), settings)

    for passes in (PASSES, ("Combined",)):
        _, whole = part(0, 0, passes)
        merged = split_render.merged([part(a, b, passes)[0] for a, b in ((0, 3), (3, 8))], tmp_path).images()
        assert set(merged) == set(whole.passes) == set(passes)
        for name in passes:
            np.testing.assert_allclose(merged[name], whole.passes[name], rtol=1e-5, atol=1e-6)


def test_what_is_not_matched_is_named():
    """Denoise on: the image stays as rendered (a denoised Combined would be the whole scene's, not
    the matte), named in the warnings; the light passes, as Cycles', need no warning."""
    settings = RenderSettings(samples=4, threads=1, max_depth=2, passes=("Combined", "DiffDir"), use_denoising=True)
    renderer = Renderer(scene(), settings)
    result = renderer.render()
    assert [w for w in result.warnings if "shadow catcher" in w] == [NOT_DENOISED]
    assert "Noisy Image" not in result.passes
    plain = Renderer(replace(scene(), instances=[replace(i, shadow_catcher=False) for i in scene().instances]),
                     replace(settings, use_denoising=False))
    assert not any("shadow catcher" in w for w in plain.warnings)


def test_renders_of_one_prepared_scene_share_the_catchers_preparation():
    """The viewport renders a view as a coarse image and a full one, each a Renderer on one
    prepared scene: the catchers' own preparation (lights, world table, top-level Embree scene) is
    made once for them all, shares the scene's world table, and renders what a fresh one does."""
    data = with_image_world(scene())
    prepared = PreparedScene(data)
    settings = RenderSettings(samples=4, threads=1, max_depth=4, passes=PASSES)
    zoomed = replace(data, camera=top_camera(2.0, 0.5, 8))
    first, second = Renderer(data, settings, prepared), Renderer(zoomed, settings, prepared)
    only = prepared.catchers
    assert first.integrator.catchers.paths.prepared is only and second.integrator.catchers.paths.prepared is only
    assert only.lights.environment is prepared.lights.environment is not None
    assert [i.name for i in only.scene.instances] == ["floor"]
    ours, fresh = first.render().passes, Renderer(data, settings).render().passes
    for name in PASSES:
        assert np.array_equal(ours[name], fresh[name]), name
    assert prepared.update(replace(data, instances=data.instances[:1])).catchers is not only
