"""Denoising Albedo and Denoising Normal hold what Cycles writes there (kernel/film/denoising_passes.h)."""
import numpy as np
import pytest

from drt_engine.core.bsdf import shader as bsdf
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Material, SceneData, World
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import look_at, plane, top_camera

DENOISING = ("Combined", "Denoising Albedo", "Denoising Normal")
COLOUR = (0.2, 0.4, 0.6)


def render(scene, passes=DENOISING, samples=4, weighted=False):
    return Renderer(scene, RenderSettings(samples=samples, threads=1, max_depth=4, passes=passes,
                                          weighted_denoising_normal=weighted)).render()


def floor_scene(material, camera=None, ceiling=None):
    """A 20 m floor of ``material``, optionally a diffuse ceiling 2 m up; black world, no lights."""
    meshes, materials = [plane(20.0)], [material]
    if ceiling is not None:
        meshes.append(plane(20.0, z=2.0, material=1))
        materials.append(ceiling)
    cam = camera or Camera(look_at((0, -3, 2), (0, 0, 0))[None], (-0.3, 0.3, -0.3, 0.3), (8, 8))
    return SceneData(cam, meshes, [Instance(i, np.eye(4)) for i in range(len(meshes))], materials, [],
                     World(np.zeros(3)))


def cycles_camera_space(matrix, v):
    """v in Cycles' camera space: Blender's camera axes x, y and minus z."""
    x, y, z = (matrix[:3, k] for k in range(3))
    return np.array([v @ x, v @ y, -(v @ z)])


def test_albedo_of_a_diffuse_surface_is_its_colour_and_normal_in_camera_space():
    scene = floor_scene(Material("paint", [Closure("DIFFUSE", color=COLOUR)]))
    passes = render(scene).passes
    assert np.allclose(passes["Denoising Albedo"], COLOUR, atol=1e-6)
    expected = cycles_camera_space(scene.camera.matrix, np.array([0.0, 0.0, 1.0]))
    assert np.allclose(expected, np.array([0.0, 3.0, -2.0]) / np.sqrt(13.0), atol=1e-9)  # tilted up, facing the camera
    assert np.allclose(passes["Denoising Normal"], expected, atol=1e-6)


def test_rough_principled_albedo_is_its_diffuse_and_glossy_colours():
    """Roughness 0.5 (alpha 0.25 > 0.075): Cycles counts the specular layer as diffuse-like too."""
    scene = floor_scene(Material("plastic", [Closure("PRINCIPLED", color=COLOUR, roughness=0.5)]))
    passes = render(scene, passes=DENOISING + ("DiffCol", "GlossCol")).passes
    assert np.allclose(passes["Denoising Albedo"], passes["DiffCol"] + passes["GlossCol"], atol=1e-6)
    assert (passes["Denoising Albedo"] > np.array(COLOUR) + 0.01).all()  # the specular layer's share


def test_through_a_mirror_albedo_is_tint_times_the_seen_surface():
    tint = np.array([0.9, 0.5, 0.7])
    mirror = Material("mirror", [Closure("GLOSSY", color=tuple(tint), roughness=0.0)])
    ceiling = Material("ceiling", [Closure("DIFFUSE", color=COLOUR)])
    camera = top_camera(1.0, 0.2, 8)
    passes = render(floor_scene(mirror, camera, ceiling)).passes
    glossy = render(floor_scene(mirror, camera), passes=("Combined", "GlossCol")).passes["GlossCol"]
    assert np.allclose(glossy, tint, atol=0.02)  # a smooth tinted mirror reflects its tint
    assert np.allclose(passes["Denoising Albedo"], glossy * np.array(COLOUR), atol=1e-6)
    # the ceiling's normal faces the reflected ray (world -z): away from this camera, as in Cycles
    assert np.allclose(passes["Denoising Normal"], [0.0, 0.0, 1.0], atol=1e-6)
    # Blender 5.2's Cycles scales it by the walk's mean throughput: the mirror's mean reflectance
    weighted = render(floor_scene(mirror, camera, ceiling), weighted=True).passes
    assert np.allclose(weighted["Denoising Normal"], [0.0, 0.0, 1.0] * glossy.mean(axis=-1)[..., None], atol=1e-6)
    assert np.array_equal(weighted["Denoising Albedo"], passes["Denoising Albedo"])


def test_a_mirror_with_nothing_to_reflect_has_no_features():
    mirror = Material("mirror", [Closure("GLOSSY", color=(0.9, 0.9, 0.9), roughness=0.0)])
    passes = render(floor_scene(mirror, top_camera(1.0, 0.2, 8))).passes
    assert not passes["Denoising Albedo"].any() and not passes["Denoising Normal"].any()


def test_the_world_seen_directly_is_the_albedo():
    scene = floor_scene(Material("paint", [Closure("DIFFUSE", color=COLOUR)]),
                        Camera(look_at((0, -3, 0.5), (0, 0, 2))[None], (-0.1, 0.1, -0.1, 0.1), (4, 4)))
    scene.world = World(np.array([0.3, 0.2, 0.1]))
    passes = render(scene).passes
    assert np.allclose(passes["Denoising Albedo"], [0.3, 0.2, 0.1], atol=1e-6)
    assert not passes["Denoising Normal"].any()


@pytest.mark.parametrize("name", ["Denoising Albedo", "Denoising Normal"])
def test_no_work_when_the_passes_are_off(monkeypatch, name):
    calls = []
    original = bsdf.MaterialShader.denoising_albedos
    monkeypatch.setattr(bsdf.MaterialShader, "denoising_albedos",
                        lambda self, *a: calls.append(len(a[0])) or original(self, *a))
    scene = floor_scene(Material("paint", [Closure("DIFFUSE", color=COLOUR)]))
    assert name not in render(scene, passes=("Combined", "Depth")).passes and calls == []
    assert name in render(scene, passes=("Combined", name)).passes and sum(calls) == 8 * 8 * 4


def test_the_film_sums_the_halved_features_per_replicate_half():
    """A denoiser guides each half with its own half's features (core.render.denoise): the film's
    class A sums of a halved pass give each replicate's mean; passes not halved cost nothing."""
    from drt_engine.core.film.film import Film

    rng = np.random.default_rng(3)
    film = Film(4, 2, ("Combined", "Denoising Albedo", "Denoising Normal"), halved=("Denoising Albedo",))
    assert set(film.sums_a) == {"Denoising Albedo"}
    waves = []
    for replicate in (0, 1, 1, 0):
        pixel = rng.integers(0, 8, 64)
        pixel[:8] = np.arange(8)  # every pixel has samples in both halves
        values = {"Combined": rng.random((64, 4)), "Denoising Albedo": rng.random((64, 3)),
                  "Denoising Normal": rng.random((64, 3))}
        film.add(pixel, values, np.arange(64), replicate=replicate)
        waves.append((replicate, pixel, values["Denoising Albedo"]))
    half_a, half_b = film.half_images(["Denoising Albedo"])
    for replicate, half in ((1, half_a), (0, half_b)):
        pixel = np.concatenate([p for r, p, _ in waves if r == replicate])
        albedo = np.concatenate([v for r, _, v in waves if r == replicate])
        mean = np.stack([albedo[pixel == i].mean(axis=0) for i in range(8)]).reshape(2, 4, 3)
        np.testing.assert_allclose(half["Denoising Albedo"], mean, rtol=1e-6)
    assert Film(4, 2, DENOISING).sums_a == {}
