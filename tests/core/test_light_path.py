"""Light Path at the points DRT shades, per ray kind, against what Cycles' path_state_next and
svm_node_light_path give the same path: an emissive wall whose emission is made of the node's
outputs, seen by the camera straight, through a transparent sheet, off a mirror, a rough
mirror and through a glass slab, and a world made of them seen by the camera, off a mirror
and by the light sampling of a diffuse floor."""
import numpy as np
import pytest

from drt_engine.core.scene import Program
from drt_engine.core.shading.lightpath import ESTIMATE_LENGTH, OUTPUTS, RayPath, outputs
from tests.support.core_cases import Closure, Instance, Material, SceneData, World, ortho_camera, render
from tests.support.scenes import look_at, plane, translation

HEIGHT = 5.0  # the camera's, looking straight down at the origin


def _program(names, scale=None):
    """A program whose output 0 of its last node is the colour (Light Path's ``names``, the first
    times ``scale`` when given)."""
    prog = Program()
    node = prog.add("light_path")
    refs = [(node, OUTPUTS.index(name)) for name in names]
    if scale is not None:
        factor = prog.add("const", value=np.asarray(scale, float)), 0
        refs[0] = prog.add("math", [refs[0], factor, factor], operation="MULTIPLY"), 0
    return prog, (prog.add("combine", refs), 0)


def _emitting(names) -> Material:
    prog, colour = _program(names)
    return Material("wall", [Closure("EMISSION", emission=(1.0, 1.0, 1.0), inputs={"emission": colour})],
                    program=prog)


def _scene(names, between=None, mirror=None):
    """The camera above the origin; without ``mirror`` it sees the wall lying at z = 0, with one
    (a Closure) the mirror at the origin tilted 45 degrees sends its rays along -y to the wall
    standing at y = -3; ``between`` (a Closure) is a sheet at z = 2 under the camera."""
    materials = [_emitting(names)]
    parts = []
    if mirror is None:
        parts.append((plane(4.0), np.eye(4)))
    else:
        parts.append((plane(8.0), look_at((0, -3, 0), (0, 0, 0))))  # the wall, facing +y
        materials.append(Material("mirror", [mirror]))
        tilt = look_at((0, 0, 0), (0, 1, -1), up=(0, 1, 0))  # normal (0, -1, 1) / sqrt 2
        parts.append((plane(2.0, material=1), tilt))
    if between is not None:
        materials.append(Material("between", [between]))
        parts.append((plane(2.0, material=len(materials) - 1), translation(z=2.0)))
    meshes = [m for m, _ in parts]
    instances = [Instance(i, matrix) for i, (_, matrix) in enumerate(parts)]
    camera = ortho_camera(translation(z=HEIGHT))
    return SceneData(camera=camera, meshes=meshes, instances=instances, materials=materials)


def _pixel(scene, samples=1, **settings):
    passes, _ = render(scene, samples=samples, passes=("Combined",), max_depth=4, **settings)
    return passes["Combined"][..., :3].reshape(-1, 3).mean(axis=0)


def test_camera_rays_straight_and_through_a_transparent_sheet():
    clip = 0.1  # the camera's clip start: Cycles' camera rays leave the near plane
    names = ("Is Camera Ray", "Ray Length", "Ray Depth")
    assert np.allclose(_pixel(_scene(names)), [1.0, HEIGHT - clip, 0.0])
    sheet = Closure("TRANSPARENT", color=(1.0, 1.0, 1.0))
    names = ("Is Camera Ray", "Transparent Depth", "Ray Length")
    assert np.allclose(_pixel(_scene(names, between=sheet)), [1.0, 1.0, 2.0], atol=1e-4)


def test_a_mirror_bounce_is_a_singular_glossy_reflection():
    mirror = Closure("GLOSSY", color=(1.0, 1.0, 1.0), roughness=0.0)
    expected = {("Is Camera Ray", "Is Reflection Ray", "Is Transmission Ray"): [0.0, 1.0, 0.0],
                ("Is Glossy Ray", "Is Singular Ray", "Is Shadow Ray"): [1.0, 1.0, 0.0],
                ("Ray Depth", "Glossy Depth", "Transmission Depth"): [1.0, 1.0, 0.0],
                ("Ray Length", "Diffuse Depth", "Is Diffuse Ray"): [3.0, 0.0, 0.0]}
    for names, values in expected.items():
        assert np.allclose(_pixel(_scene(names, mirror=mirror)), values, atol=1e-4), names
    sheet = Closure("TRANSPARENT", color=(1.0, 1.0, 1.0))  # a transparent bounce keeps the kind and depth
    names = ("Transparent Depth", "Ray Depth", "Is Reflection Ray")
    assert np.allclose(_pixel(_scene(names, between=sheet, mirror=mirror)), [1.0, 1.0, 1.0])


def test_a_rough_mirror_bounce_is_glossy_but_not_singular():
    """The wall is black to light samples (no kind), so what the camera sees is the rough lobe's rays' alone."""
    rough = Closure("GLOSSY", color=(1.0, 1.0, 1.0), roughness=0.3)
    r, g, b = _pixel(_scene(("Is Glossy Ray", "Is Singular Ray", "Is Reflection Ray"), mirror=rough), samples=16)
    assert r > 0.1 and g == 0.0 and r == pytest.approx(b, rel=1e-12)


def test_a_glass_slab_is_two_singular_transmissions():
    """In and out of a sharp refraction-only slab: two transmission bounces, no glossy ones (as Cycles counts)."""
    glass = Closure("REFRACTION", color=(1.0, 1.0, 1.0), roughness=0.0, ior=1.5)
    scene = _scene(("Is Transmission Ray", "Ray Depth", "Transmission Depth"), between=glass)
    slab = translation(z=2.0) @ np.diag([1.0, 1.0, -1.0, 1.0])  # the sheet's second face, 0.1 below
    slab[2, 3] = 1.9
    scene.instances.append(Instance(len(scene.meshes) - 1, slab))
    r, g, b = _pixel(scene)
    assert r > 0 and np.allclose([g / r, b / r], [2.0, 2.0])
    scene.materials[0] = _emitting(("Is Singular Ray", "Glossy Depth", "Is Reflection Ray"))
    r, g, b = _pixel(scene)
    assert r > 0 and g == 0.0 and b == 0.0


def _world(names, scale=None) -> World:
    prog, colour = _program(names, scale)
    return World(program=prog, color=colour)


def test_the_world_sees_the_camera_its_light_samples_do_not():
    """Is Camera Ray in the world: 1 for the camera, 0 for a mirror's rays and for the light samples
    of a diffuse floor; Ray Depth one bounce further (Cycles' emission flag), Ray Length Cycles'
    FLT_MAX (3.4028e38, measured)."""
    def alone(closure, matrix, names, scale=None):
        return SceneData(camera=ortho_camera(translation(z=HEIGHT)), meshes=[plane(2.0)],
                         instances=[Instance(0, matrix)], materials=[Material("alone", [closure])],
                         world=_world(names, scale))

    diffuse = Closure("DIFFUSE", color=(0.5, 0.5, 0.5))
    sky = alone(diffuse, translation(x=100.0), ("Ray Length", "Ray Depth", "Is Camera Ray"), scale=1e-38)
    assert np.allclose(_pixel(sky), [3.4028235, 1.0, 1.0])
    only = alone(diffuse, translation(x=100.0), ("Is Camera Ray",) * 3)  # black to light samples (the table)
    assert np.allclose(_pixel(only), 1.0)
    mirror = Closure("GLOSSY", color=(1.0, 1.0, 1.0), roughness=0.0)
    tilted = alone(mirror, look_at((0, 0, 0), (0, 1, -1), up=(0, 1, 0)), ("Is Camera Ray", "Ray Depth",
                                                                          "Is Reflection Ray"))
    assert np.allclose(_pixel(tilted), [0.0, 2.0, 1.0])
    floor = alone(diffuse, np.eye(4), ("Is Camera Ray", "Ray Depth", "Is Glossy Ray"))
    r, g, b = _pixel(floor, samples=64)
    assert r == 0.0 and b == 0.0 and g == pytest.approx(0.5, rel=0.05)  # albedo x the world's 1


def test_outputs_without_a_path_are_a_camera_hits_light_samples():
    out = dict(zip(OUTPUTS, outputs(None, 3)))
    assert np.all(out["Ray Depth"] == 1.0) and np.all(out["Ray Length"] == ESTIMATE_LENGTH)
    assert not any(out[k].any() for k in OUTPUTS if k not in ("Ray Depth", "Ray Length"))
    bounces = np.array([[2 | 4, 3, 2, 1, 4, 0]])
    seen = dict(zip(OUTPUTS, outputs(RayPath(np.zeros(1, bool), bounces, np.array([2.5])), 1)))
    assert [seen[k][0] for k in ("Is Transmission Ray", "Is Glossy Ray", "Is Reflection Ray", "Ray Depth",
                                 "Glossy Depth", "Transmission Depth", "Transparent Depth", "Ray Length")] == \
        [1.0, 1.0, 0.0, 3.0, 2.0, 1.0, 4.0, 2.5]
    sampled = dict(zip(OUTPUTS, outputs(RayPath.light_samples(bounces, np.array([2.5])), 1)))
    assert sampled["Is Transmission Ray"][0] == 0.0 and sampled["Ray Depth"][0] == 4.0


def test_a_diffuse_ray_is_one_with_its_depth():
    """With diffuse bounces a diffuse lobe spawns rays: Is Diffuse Ray and Diffuse Depth read the
    kind and depth core.integrator.continuation counts (here after two diffuse reflections)."""
    bounces = np.array([[1 | 16, 2, 0, 0, 0, 2]])
    seen = dict(zip(OUTPUTS, outputs(RayPath(np.zeros(1, bool), bounces, np.array([1.0])), 1)))
    assert [seen[k][0] for k in ("Is Diffuse Ray", "Diffuse Depth", "Is Reflection Ray", "Is Glossy Ray",
                                 "Ray Depth")] == [1.0, 2.0, 1.0, 0.0, 2.0]
