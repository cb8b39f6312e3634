"""Shader program operations against Cycles' definitions of the nodes (svm_*.h)."""
import numpy as np

from drt_engine.core.scene import Program
from drt_engine.core.shading.nodes import DirectionContext, Evaluator, hsv_to_rgb, rgb_to_hsv

N = 5


def run(build):
    """Evaluate the output a ``build(program, const)`` returns over N identical points."""
    prog = Program()

    def const(v):
        return prog.add("const", value=np.asarray(v, float)), 0

    ref = build(prog, const)
    return Evaluator(prog, DirectionContext(np.tile([0.0, 0.0, 1.0], (N, 1))), [])(ref)[0]


def math(op, a, b=0.0, c=0.0, clamp=False):
    return run(lambda p, k: (p.add("math", [k(a), k(b), k(c)], operation=op, clamp=clamp), 0))


def mix(blend, fac, a, b):
    return run(lambda p, k: (p.add("mix", [k(fac), k(a), k(b)], data_type="RGBA", blend=blend), 0))


def test_math_follows_cycles_safe_definitions():
    assert math("DIVIDE", 1.0, 0.0) == 0.0
    assert math("POWER", -2.0, 0.5) == 0.0 and math("POWER", -2.0, 3.0) == -8.0
    assert math("MODULO", -3.0, 2.0) == -1.0 and math("FLOORED_MODULO", -3.0, 2.0) == 1.0
    assert math("PINGPONG", 3.0, 2.0) == 1.0 and math("WRAP", 5.5, 2.0, 0.0) == 1.5
    assert math("ADD", 0.8, 0.7, clamp=True) == 1.0
    assert math("COMPARE", 0.3, 0.35, 0.1) == 1.0 and math("SQRT", -1.0) == 0.0


def test_mix_blend_modes():
    a, b = np.array([0.2, 0.6, 0.9]), np.array([0.5, 0.3, 0.9])
    assert np.allclose(mix("LIGHTEN", 1.0, a, b), np.maximum(a, b))
    assert np.allclose(mix("DARKEN", 0.5, a, b), a + 0.5 * (np.minimum(a, b) - a))
    assert np.allclose(mix("MULTIPLY", 0.5, a, b), a * (0.5 + 0.5 * b))
    assert np.allclose(mix("SCREEN", 1.0, a, b), 1 - (1 - a) * (1 - b))
    assert np.allclose(mix("MIX", 2.0, a, b), b)  # the factor is clamped
    assert np.allclose(mix("OVERLAY", 1.0, a, b), np.where(a < 0.5, 2 * a * b, 1 - 2 * (1 - a) * (1 - b)))


def test_color_ramp_and_checker():
    def ramp(fac, interpolation):
        return run(lambda p, k: (p.add("ramp", [k(fac)], positions=[0.2, 0.6],
                                       colors=[[0, 0, 0, 1], [1, 0.5, 0, 1]], interpolation=interpolation), 0))
    assert np.allclose(ramp(0.4, "LINEAR"), [0.5, 0.25, 0])
    assert np.allclose(ramp(0.1, "LINEAR"), 0) and np.allclose(ramp(0.9, "LINEAR"), [1, 0.5, 0])
    assert np.allclose(ramp(0.3, "EASE"), [0.15625, 0.078125, 0]) and np.allclose(ramp(0.5, "CONSTANT"), 0)

    def checker(p3):
        return run(lambda p, k: (p.add("checker", [k(p3), k([1, 1, 1]), k([0, 0, 0]), k(2.0)]), 1))
    assert checker([0.1, 0.1, 0.1]) == 0.0 and checker([0.6, 0.1, 0.1]) == 1.0 and checker([0.6, 0.6, 0.1]) == 0.0


def test_colour_conversions():
    c = np.random.default_rng(2).random((50, 3))
    assert np.allclose(hsv_to_rgb(rgb_to_hsv(c)), c)
    same = run(lambda p, k: (p.add("hsv", [k(0.5), k(1.0), k(1.0), k(1.0), k([0.3, 0.6, 0.2])]), 0))
    assert np.allclose(same, [0.3, 0.6, 0.2])
    assert np.allclose(run(lambda p, k: (p.add("invert", [k(1.0), k([0.3, 0.6, 0.2])]), 0)), [0.7, 0.4, 0.8])
    assert np.allclose(run(lambda p, k: (p.add("gamma", [k([0.25, 0.5, 1.0]), k(2.0)]), 0)), [0.0625, 0.25, 1])


def test_mapping_texture_inverts_point():
    loc, rot, scale = [0.3, -1.0, 2.0], [0.4, -0.2, 1.1], [2.0, 0.5, 3.0]

    def build(p, k):
        point = p.add("mapping", [k([0.2, 0.7, -0.4]), k(loc), k(rot), k(scale)], type="POINT")
        return p.add("mapping", [(point, 0), k(loc), k(rot), k(scale)], type="TEXTURE"), 0
    assert np.allclose(run(build), [0.2, 0.7, -0.4])
