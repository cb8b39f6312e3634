"""Shader program operations against Cycles' definitions of the nodes (svm_*.h)."""
import numpy as np

from drt_engine.core.scene import Program
from drt_engine.core.shading.nodes import DirectionContext, Evaluator, euler_matrix, hsv_to_rgb, rgb_to_hsv

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


class FacingContext(DirectionContext):
    """Hits seen along +z with the shading normal +z, front- or backfacing, one object matrix."""

    def __init__(self, n, back=False, matrix=None):
        super().__init__(np.tile([0.0, 0.0, 1.0], (n, 1)))
        self.back = back
        self.matrix = matrix

    def backfacing(self):
        return np.full(self.n, self.back)

    def object_matrix(self):
        return None if self.matrix is None else np.broadcast_to(self.matrix, (self.n, 4, 4))


def run_in(ctx, build):
    prog = Program()
    ref = build(prog, lambda v: (prog.add("const", value=np.asarray(v, float)), 0))
    return Evaluator(prog, ctx, [])(ref)[0]


def tilted(theta):
    """A normal at angle theta from the incoming direction (+z)."""
    return [np.sin(theta), 0.0, np.cos(theta)]


def fresnel(ior, theta, back=False):
    return run_in(FacingContext(N, back), lambda p, k: (p.add("fresnel", [k(ior), k(tilted(theta))]), 0))


def exact_fresnel(n, theta):
    """Unpolarised dielectric Fresnel reflectance from Snell's law (relative IOR n)."""
    ci = np.cos(theta)
    st = np.sin(theta) / n
    if st >= 1:
        return 1.0
    ct = np.sqrt(1 - st * st)
    rs = (ci - n * ct) / (ci + n * ct)
    rp = (n * ci - ct) / (n * ci + ct)
    return 0.5 * (rs * rs + rp * rp)


def test_fresnel_is_the_dielectric_reflectance_backfacing_inverted():
    for ior in (1.33, 1.45, 2.4):
        assert np.allclose(fresnel(ior, 0.0), ((ior - 1) / (ior + 1)) ** 2)
        assert np.allclose(fresnel(ior, 0.7), exact_fresnel(ior, 0.7))
        assert np.allclose(fresnel(ior, 0.7, back=True), exact_fresnel(1 / ior, 0.7))
    assert np.allclose(fresnel(1.45, np.pi / 2), 1.0)  # grazing
    assert np.allclose(fresnel(1.5, 1.0, back=True), 1.0)  # total internal reflection inside
    # the unlinked normal is the shading normal: normal incidence here
    plain = run_in(FacingContext(N), lambda p, k: (p.add("fresnel", [k(1.5)]), 0))
    assert np.allclose(plain, 0.04)


def test_layer_weight_fresnel_and_facing():
    def layer(blend, theta, out, back=False):
        return run_in(FacingContext(N, back), lambda p, k: (p.add("layer_weight", [k(blend), k(tilted(theta))]), out))
    assert np.allclose(layer(0.5, 0.6, 1), 1 - np.cos(0.6))
    assert np.allclose(layer(0.25, 0.6, 1), 1 - np.cos(0.6) ** 0.5)
    assert np.allclose(layer(0.75, 0.6, 1), 1 - np.cos(0.6) ** 2)
    assert np.allclose(layer(0.3, 0.6, 0), exact_fresnel(1 / 0.7, 0.6))  # IOR 1 / (1 - blend)
    assert np.allclose(layer(0.3, 0.6, 0, back=True), exact_fresnel(0.7, 0.6))


def test_brightness_contrast_blackbody_wavelength():
    c = np.array([0.2, 0.5, 0.9])
    out = run(lambda p, k: (p.add("brightness", [k(c), k(0.1), k(0.4)]), 0))
    assert np.allclose(out, np.maximum(1.4 * c + 0.1 - 0.2, 0))
    assert np.allclose(run(lambda p, k: (p.add("brightness", [k(c), k(-0.5), k(0.0)]), 0)), [0, 0, 0.4])

    def blackbody(t):
        return run(lambda p, k: (p.add("blackbody", [k(t)]), 0))
    white = blackbody(6500.0)
    assert white.max() / white.min() < 1.07  # D65's temperature: near white
    warm = blackbody(2000.0)
    assert warm[0] > warm[1] > warm[2] >= 0  # a candle: red, some green, little blue
    cold = blackbody(15000.0)
    assert cold[2] > cold[1] > cold[0]

    def wavelength(nm):
        return run(lambda p, k: (p.add("wavelength", [k(nm)]), 0))
    assert np.argmax(wavelength(550.0)) == 1 and np.argmax(wavelength(450.0)) == 2
    assert np.argmax(wavelength(650.0)) == 0
    assert np.allclose(wavelength(800.0), 0) and np.all(wavelength(550.0) <= 1)


def test_hsl_and_hsv_blends():
    from drt_engine.core.shading.colornodes import hsl_to_rgb, rgb_to_hsl
    c = np.random.default_rng(3).random((50, 3))
    assert np.allclose(hsl_to_rgb(rgb_to_hsl(c)), c)
    assert np.allclose(rgb_to_hsl(np.array([[1.0, 0.0, 0.0], [0.5, 0.5, 0.5]])), [[0, 1, 0.5], [0, 0, 0.5]])
    sep = run(lambda p, k: (p.add("separate", [k([0.0, 0.0, 1.0])], mode="HSL"), 0))
    assert np.allclose(sep, 2 / 3)
    comb = run(lambda p, k: (p.add("combine", [k(1 / 3), k(1.0), k(0.5)], mode="HSL"), 0))
    assert np.allclose(comb, [0, 1, 0])
    a, b = np.array([0.8, 0.2, 0.2]), np.array([0.1, 0.3, 0.9])
    assert np.allclose(mix("VALUE", 1.0, a, b), a / a.max() * b.max())  # a's hue and saturation, b's value
    assert np.allclose(mix("HUE", 0.7, a, [0.4, 0.4, 0.4]), a)  # a grey b has no hue to give
    hue = hsv_to_rgb(np.array([[rgb_to_hsv(b[None])[0, 0], *rgb_to_hsv(a[None])[0, 1:]]]))[0]
    assert np.allclose(mix("HUE", 0.5, a, b), a + 0.5 * (hue - a))
    assert np.allclose(mix("COLOR", 1.0, a, b), hsv_to_rgb(np.array([[*rgb_to_hsv(b[None])[0, :2], 0.8]]))[0])
    sat = hsv_to_rgb(np.array([[0.0, 0.5 * 0.75 + 0.5 * 8 / 9, 0.8]]))[0]
    assert np.allclose(mix("SATURATION", 0.5, a, b), sat)
    assert np.allclose(mix("SATURATION", 1.0, [0.3, 0.3, 0.3], b), 0.3)


def test_curves_and_baked_ramp_tables():
    ramp = np.linspace(0, 1, 257)[:, None] * [1.0, 0.5, 0.25]
    out = run(lambda p, k: (p.add("curves", [k(1.0), k([0.3, 0.6, 1.5])], table=ramp, min=0.0, max=1.0,
                                  extrapolate=True), 0))
    assert np.allclose(out, [0.3, 0.3, 0.375])  # each channel its own column, the blue one extrapolated
    out = run(lambda p, k: (p.add("curves", [k(0.5), k([0.3, 0.6, 1.5])], table=ramp, min=0.0, max=1.0,
                                  extrapolate=False), 0))
    assert np.allclose(out, 0.5 * np.array([0.3, 0.6, 1.5]) + 0.5 * np.array([0.3, 0.3, 0.25]))
    squares = np.linspace(-1, 1, 257) ** 2
    val = run(lambda p, k: (p.add("float_curve", [k(1.0), k(0.5)], table=squares, min=-1.0, max=1.0,
                                  extrapolate=False), 0))
    assert np.allclose(val, 0.25, atol=1e-4)
    steps = np.repeat(np.eye(4)[:2], [128, 129], axis=0)
    col = run(lambda p, k: (p.add("ramp", [k(0.2)], interpolation="TABLE", table=steps, interpolate=False), 0))
    assert np.allclose(col, [1, 0, 0])


def test_vector_rotate_normal_and_map_range_vector():
    def rotate(kind, v, angle=0.0, rotation=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), center=(0.0, 0.0, 0.0),
               invert=False):
        return run(lambda p, k: (p.add("vector_rotate", [k(v), k(center), k(axis), k(angle), k(rotation)],
                                       type=kind, invert=invert), 0))
    assert np.allclose(rotate("Z_AXIS", [1, 0, 0], np.pi / 2), [0, 1, 0])
    assert np.allclose(rotate("Z_AXIS", [1, 0, 0], np.pi / 2, invert=True), [0, -1, 0])
    assert np.allclose(rotate("X_AXIS", [0, 1, 0], np.pi / 2), [0, 0, 1])
    assert np.allclose(rotate("AXIS_ANGLE", [2, 0, 0], np.pi, axis=[0, 0, 3], center=[1, 0, 0]), [0, 0, 0])
    assert np.allclose(rotate("AXIS_ANGLE", [0.3, 0.2, 0.1], 1.0, axis=[0, 0, 0]), [0.3, 0.2, 0.1])
    euler = (0.4, -0.9, 1.3)
    there = rotate("EULER_XYZ", [0.3, 0.2, 0.1], rotation=euler, center=[1, 2, 3])
    assert np.allclose(rotate("EULER_XYZ", there, rotation=euler, center=[1, 2, 3], invert=True), [0.3, 0.2, 0.1])
    assert np.allclose(there - [1, 2, 3], euler_matrix(np.array([euler]))[0] @ (np.array([0.3, 0.2, 0.1]) - [1, 2, 3]))

    dot = run(lambda p, k: (p.add("normal", [k([0.0, 3.0, 4.0])], direction=[0.0, 0.0, 2.0]), 1))
    assert np.allclose(dot, 0.8)

    def map_range(kind, v, clamp=True):
        return run(lambda p, k: (p.add("map_range_vector", [k(v), k([0, 0, 1]), k([1, 2, 1]), k([0, 10, 0]),
                                                            k([1, 0, 1]), k([4, 4, 0])], type=kind, clamp=clamp), 0))
    assert np.allclose(map_range("LINEAR", [0.5, 3.0, 7.0]), [0.5, 0.0, 0.0])  # clamped; From Min = Max gives 0
    assert np.allclose(map_range("LINEAR", [0.5, 3.0, 7.0], clamp=False), [0.5, -5.0, 0.0])
    assert np.allclose(map_range("STEPPED", [0.3, 1.0, 7.0]), [0.25, 5.0, 0.0])  # floor(0.5 * 5) / 4 of the way
    assert np.allclose(map_range("SMOOTHSTEP", [0.25, 3.0, 0.5]), [0.15625, 0.0, 0.0])
    assert np.allclose(math_map_range(0.7, 0.5, 0.5, 0.2, 0.9), 0.2)  # float: 0 when From Min = From Max, clamped


def math_map_range(v, a, b, c, d):
    return run(lambda p, k: (p.add("map_range", [k(v), k(a), k(b), k(c), k(d), k(4.0)], type="LINEAR", clamp=True), 0))


def test_vector_transform_object_space():
    m = np.eye(4)
    m[:3, :3] = euler_matrix(np.array([[0.3, 0.5, -0.2]]))[0] @ np.diag([2.0, 0.5, 1.0])
    m[:3, 3] = [1.0, -2.0, 0.5]
    ctx = FacingContext(N, matrix=m)

    def transform(kind, src, dst, v):
        return run_in(ctx, lambda p, k: (p.add("vector_transform", [k(v)], type=kind, **{"from": src, "to": dst}), 0))
    p = np.array([0.3, -0.4, 0.8])
    assert np.allclose(transform("POINT", "OBJECT", "WORLD", p), m[:3, :3] @ p + m[:3, 3])
    assert np.allclose(transform("POINT", "WORLD", "OBJECT", m[:3, :3] @ p + m[:3, 3]), p)
    assert np.allclose(transform("VECTOR", "OBJECT", "WORLD", p), m[:3, :3] @ p)
    # a normal stays perpendicular to the surface's tangents carried to the world
    tangent = np.cross(p, [0.0, 0.0, 1.0])
    n = transform("NORMAL", "OBJECT", "WORLD", p)
    assert np.isclose(np.linalg.norm(n), 1.0) and np.isclose(n @ (m[:3, :3] @ tangent), 0.0)
    assert np.allclose(transform("POINT", "OBJECT", "OBJECT", p), p)


def test_view_dependent_emission_is_named_in_a_warning():
    """DRT's emission sees no ray direction yet: a Fresnel feeding it is named, a colour feeding a
    diffuse closure is not."""
    from drt_engine.core.scene import Closure, Material
    from drt_engine.core.shading.surface import MaterialShading

    def shading(kind, name):
        prog = Program()
        ior = prog.add("const", value=np.asarray(1.5))
        fac = prog.add("fresnel", [(ior, 0)])
        col = prog.add("convert", [(fac, 0)], kind="float_to_vector")
        return MaterialShading(Material("m", [Closure(kind, inputs={name: (col, 0)})], program=prog), [], [])
    warned = shading("EMISSION", "emission").warnings
    assert len(warned) == 1 and "Fresnel" in warned[0]
    assert not shading("DIFFUSE", "color").warnings


def test_backfacing_output_is_the_side_seen():
    ctx = FacingContext(N, back=True)
    back = run_in(ctx, lambda p, k: (p.add("backfacing"), 0))
    assert back == 1.0 and run(lambda p, k: (p.add("backfacing"), 0)) == 0.0


def test_image_sphere_and_tube_projections():
    from drt_engine.core.shading.nodes import project
    points = np.array([[1.0, 0.5, 0.5], [0.5, 0.0, 0.5], [0.5, 1.0, 0.8], [0.5, 0.5, 1.0], [0.5, 0.5, 0.5]])
    # u once around z from -y (0) through +x (0.25) to +y (0.5); v from the bottom pole (0) up
    assert np.allclose(project("SPHERE", points), [[0.25, 0.5], [0.0, 0.5], [0.5, 1 - np.arccos(0.6 / np.hypot(1, 0.6)) / np.pi],
                                                   [0.0, 1.0], [0.0, 0.0]])
    assert np.allclose(project("TUBE", points), [[0.25, 0.5], [0.0, 0.5], [0.5, 0.8], [0.0, 0.0], [0.0, 0.0]])
    assert np.allclose(project("FLAT", points), points[:, :2])


def test_mirror_ball_is_the_ball_seen_from_minus_y():
    from drt_engine.core.shading.nodes import mirror_ball_uv
    d = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    # straight back to the viewer: the ball's centre; sideways: 45 degrees round it
    assert np.allclose(mirror_ball_uv(d), [[0.5, 0.5], [0.5 + 0.5 * np.sqrt(0.5), 0.5], [0.5, 0.5 + 0.5 * np.sqrt(0.5)]])


def vector_math(op, a, b, output=0):
    return run(lambda p, k: (p.add("vector_math", [k(a), k(b), k([0.0, 0.0, 0.0]), k(1.0)], operation=op), output))


def test_vector_math_dot_product_project_and_reflect():
    """The operations that take a dot product (they once failed on a name the function shadowed)."""
    a, b = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 2.0])
    assert np.allclose(vector_math("DOT_PRODUCT", a, b, 1), 6.0)
    assert np.allclose(vector_math("PROJECT", a, b), [0.0, 0.0, 3.0])
    assert np.allclose(vector_math("REFLECT", a, b), [1.0, 2.0, -3.0])
