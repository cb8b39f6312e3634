"""Light Falloff against Cycles' svm_node_light_falloff: its three outputs over lengths, strengths
and smoothing, and at the points DRT shades, where it reads Light Path's Ray Length (a camera
hit, a light-sampled emitter, the world)."""
import numpy as np
import pytest

from drt_engine.core.scene import Program
from drt_engine.core.shading.lightpath import BACKGROUND_LENGTH, ESTIMATE_LENGTH, FALLOFF, OUTPUTS, RayPath, falloff
from drt_engine.core.shading.lightpath import camera_bounces
from tests.support.core_cases import Closure, Instance, Material, SceneData, World, ortho_camera, render
from tests.support.scenes import plane, translation

HEIGHT = 5.0  # the camera's, looking straight down at the origin
CLIP = 0.1  # its clip start: Cycles' camera rays leave the near plane


def _cycles(strength, smooth, length, output):
    """One point as Cycles 5's svm_node_light_falloff computes it (float32, as the kernel)."""
    strength, smooth, length = np.float32(strength), np.float32(smooth), np.float32(length)
    if length == np.finfo(np.float32).max:  # distant lights and the world: Strength as is
        return float(strength)
    strength *= (np.float32(1.0), length, length * length)[FALLOFF.index(output)]
    if smooth > 0.0:
        squared = length * length
        strength *= squared / (smooth + squared)
    return float(strength)


@pytest.mark.parametrize("smooth", [0.0, 0.5, 4.0])
def test_outputs_are_cycles_formula(smooth):
    lengths = np.array([0.0, 0.3, 1.0, 2.5, 17.0, BACKGROUND_LENGTH])
    for strength in (0.0, 1.5, 100.0):
        path = RayPath(np.ones(len(lengths), bool), camera_bounces(len(lengths)), lengths)
        got = falloff(np.full(len(lengths), strength), np.full(len(lengths), smooth), path, len(lengths))
        for output, values in zip(FALLOFF, got):
            expected = [_cycles(strength, smooth, length, output) for length in lengths]
            assert np.allclose(values, expected, rtol=1e-6, atol=0.0), (output, strength)


def test_smooth_changes_every_output_and_quadratic_is_strength_without_it():
    path = RayPath(np.ones(2, bool), camera_bounces(2), np.array([0.5, 3.0]))
    quadratic, linear, constant = falloff(2.0, 0.0, path, 2)
    assert np.array_equal(quadratic, [2.0, 2.0]) and np.allclose(linear, [1.0, 6.0]) and np.allclose(constant,
                                                                                                   [0.5, 18.0])
    soft = falloff(2.0, 1.0, path, 2)
    for sharp, smoothed in zip((quadratic, linear, constant), soft):
        assert np.allclose(smoothed, sharp * np.array([0.25 / 1.25, 9.0 / 10.0]))


def test_without_a_path_the_length_is_the_estimates():
    quadratic, linear, constant = falloff(3.0, 0.0, None, 2)
    assert np.allclose(linear, 3.0 * ESTIMATE_LENGTH) and np.allclose(constant, 3.0 * ESTIMATE_LENGTH ** 2)


def _program(strength, smooth, outputs):
    """Light Falloff's ``outputs`` (one per channel) for constant Strength and Smooth, and the colour."""
    prog = Program()
    args = [(prog.add("const", value=np.asarray(v, float)), 0) for v in (strength, smooth)]
    node = prog.add("light_falloff", args)
    return prog, (prog.add("combine", [(node, FALLOFF.index(o)) for o in outputs]), 0)


def _pixel(scene, samples=1):
    passes, _ = render(scene, samples=samples, passes=("Combined",), max_depth=4)
    return passes["Combined"][..., :3].reshape(-1, 3).mean(axis=0)


def _emitter(prog, colour) -> Material:
    return Material("glow", [Closure("EMISSION", emission=(1.0, 1.0, 1.0), inputs={"emission": colour})],
                    program=prog)


@pytest.mark.parametrize("smooth", [0.0, 2.0])
def test_an_emitter_seen_by_the_camera_falls_off_over_the_hit_distance(smooth):
    prog, colour = _program(2.0, smooth, FALLOFF)
    scene = SceneData(camera=ortho_camera(translation(z=HEIGHT)), meshes=[plane(4.0)],
                      instances=[Instance(0, np.eye(4))], materials=[_emitter(prog, colour)])
    d = HEIGHT - CLIP
    expected = [_cycles(2.0, smooth, d, o) for o in FALLOFF]
    assert np.allclose(_pixel(scene), expected, rtol=1e-5)


def _lit_floor(emitter: Material) -> SceneData:
    """A grey floor under the camera lit by a small square 1 above it and 0.5 aside (facing down),
    which the camera does not see."""
    down = translation(x=0.5, z=1.0) @ np.diag([1.0, -1.0, -1.0, 1.0])
    return SceneData(camera=ortho_camera(translation(z=HEIGHT)), meshes=[plane(4.0), plane(0.2, material=1)],
                     instances=[Instance(0, np.eye(4)), Instance(1, down)],
                     materials=[Material("floor", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))]), emitter])


def test_a_light_sampled_emitter_falls_off_over_the_sample_distance():
    """Linear is Strength times Light Path's Ray Length wherever DRT shades (the same render), and
    a floor lit by it gets what a constant emitter of Strength times its distance gives it."""
    prog, colour = _program(3.0, 0.0, ("Linear",) * 3)
    linear = _pixel(_lit_floor(_emitter(prog, colour)), samples=64)
    prog = Program()
    length = prog.add("light_path"), OUTPUTS.index("Ray Length")
    strength = prog.add("const", value=np.asarray(3.0)), 0
    times = prog.add("math", [length, strength, strength], operation="MULTIPLY"), 0
    by_light_path = _pixel(_lit_floor(_emitter(prog, (prog.add("combine", [times] * 3), 0))), samples=64)
    assert np.array_equal(linear, by_light_path)
    distance = np.hypot(0.5, 1.0)
    constant = Material("glow", [Closure("EMISSION", emission=np.full(3, 3.0 * distance))])
    assert linear == pytest.approx(_pixel(_lit_floor(constant), samples=64), rel=0.03)
    assert linear[0] > 0.01


def test_the_world_passes_strength_through():
    """At the world (Ray Length FLT_MAX) every output is Strength, as measured with Blender 5.0's
    Cycles (a Background of strength Linear 0.25 rendered at a quarter of strength 1's)."""
    prog, colour = _program(0.25, 1.0, FALLOFF)
    scene = SceneData(camera=ortho_camera(translation(z=HEIGHT)), meshes=[plane(2.0)],
                      instances=[Instance(0, translation(x=100.0))],
                      materials=[Material("off", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])],
                      world=World(program=prog, color=colour))
    assert np.allclose(_pixel(scene), 0.25)
