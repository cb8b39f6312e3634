"""Displacement, Camera Data, Wireframe and Tangent (core.shading.geometrynodes) against closed forms."""
import numpy as np

from drt_engine.core.scene import Closure, Material, Program
from drt_engine.core.shading import geometrynodes as gn
from drt_engine.core.shading.surface import MaterialShading

N = 4


def scaled(s, turn=0.0):
    """(N, 4, 4) object transforms: a uniform scale ``s`` after a turn about z."""
    m = np.eye(4)
    c, t = np.cos(turn), np.sin(turn)
    m[:3, :3] = s * np.array([[c, -t, 0.0], [t, c, 0.0], [0.0, 0.0, 1.0]])
    return np.broadcast_to(m, (N, 4, 4))


def test_displacement_in_object_space_scales_with_the_object():
    normal = np.tile([0.0, 0.0, 1.0], (N, 1))
    height, mid, scale = np.full(N, 0.9), np.full(N, 0.5), np.full(N, 0.25)
    world = gn.displacement("WORLD", height, mid, scale, normal, scaled(3.0))
    own = gn.displacement("OBJECT", height, mid, scale, normal, scaled(3.0, 0.7))
    assert np.allclose(world, [0.0, 0.0, 0.1]) and np.allclose(own, [0.0, 0.0, 0.3])


def test_vector_displacement_tangent_space_frame():
    """x along the tangent, y along the normal, z along normal x tangent (times the sign), in object
    space, then carried to the world."""
    normal = np.tile([0.0, 0.0, 1.0], (N, 1))
    tangent = np.tile([1.0, 0.0, 0.0], (N, 1))
    v = np.tile([0.7, 0.6, 0.9], (N, 1))
    out = gn.vector_displacement("TANGENT", v, np.full(N, 0.5), np.full(N, 2.0), normal, tangent, np.ones(N),
                                 scaled(2.0, np.pi / 2))
    # object space: 0.4 along x, 0.2 along z (the normal), 0.8 along y (z x x); then turned to (-0.8, 0.4, 0.2), doubled
    assert np.allclose(out, [-1.6, 0.8, 0.4])
    obj = gn.vector_displacement("OBJECT", v, np.zeros(N), np.ones(N), normal, None, None, scaled(2.0))
    assert np.allclose(obj, 2.0 * v) and np.allclose(gn.vector_displacement("WORLD", v, np.zeros(N), np.ones(N), normal,
                                                                            None, None, scaled(2.0)), v)


def test_camera_data_is_the_point_in_camera_space():
    cam = np.eye(4)
    cam[:3, 3] = (1.0, 2.0, -3.0)  # z looks forward: the point 4 m ahead and 3 m aside
    pos = np.tile([4.0, 2.0, 1.0], (N, 1))
    view, depth, distance = gn.camera_data(pos, cam)
    assert np.allclose(view, [0.6, 0.0, 0.8]) and np.allclose(depth, 4.0) and np.allclose(distance, 5.0)


def test_wireframe_is_one_within_half_the_size_of_an_edge():
    corners = np.broadcast_to(np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]), (3, 3, 3))
    # 0.04 and 0.06 from the edge along x, 0.028 from the diagonal
    pos = np.array([[0.5, 0.04, 0.0], [0.5, 0.06, 0.0], [0.97, 0.99, 0.0]])
    assert np.array_equal(gn.wireframe(pos, corners, np.full(3, 0.1)), [1.0, 0.0, 1.0])
    assert np.array_equal(gn.wireframe(pos, corners, np.full(3, 2.0), np.full(3, 0.05)), [1.0, 0.0, 1.0])


def test_tangents_are_perpendicular_to_the_normal():
    generated = np.tile([0.8, 0.5, 0.3], (N, 1))
    assert np.allclose(gn.radial_tangent("Z", generated), [0.0, 0.3, 0.0])
    assert np.allclose(gn.radial_tangent("X", generated), [0.0, 0.2, 0.0])
    normal = np.tile([0.0, 0.6, 0.8], (N, 1))
    t = gn.surface_tangent(np.tile([1.0, 1.0, 0.0], (N, 1)), normal, scaled(1.0))
    assert np.allclose(np.einsum("ij,ij->i", t, normal), 0.0) and np.allclose(np.linalg.norm(t, axis=1), 1.0)


def test_pixel_size_wireframe_in_an_emission_is_named_in_a_warning():
    """DRT's emission is evaluated without the pixel's footprint: named, as a view-dependent input."""
    def shading(pixel_size):
        prog = Program()
        size = prog.add("const", value=np.asarray(2.0))
        fac = prog.add("wireframe", [(size, 0)], pixel_size=pixel_size)
        col = prog.add("convert", [(fac, 0)], kind="float_to_vector")
        material = Material("m", [Closure("EMISSION", inputs={"emission": (col, 0)})], program=prog)
        return MaterialShading(material, [], [])
    warned = shading(True).warnings
    assert len(warned) == 1 and "Wireframe in pixels" in warned[0] and not shading(False).warnings
