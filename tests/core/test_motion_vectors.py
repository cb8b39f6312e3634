"""The Vector pass against closed forms (core.geometry.motion_vectors, core.film.film): a point moved
between frames by its object or seen by a moving camera shifts by the projected distance in pixels,
(previous - now, now - next), x right and y up; in a render a pixel's vector is the mean over the
samples that hit a surface (Cycles' motion weight), and parts merge into the whole render's."""
import numpy as np
import pytest

from drt_engine.core.film import parts
from drt_engine.core.geometry.motion_vectors import MotionVectors
from drt_engine.core.render import merge
from drt_engine.core.scene import Camera, Instance, Mesh
from tests.core.test_mist_index import RES, render
from tests.core.test_mist_index import scene as quads
from tests.core.test_mist_index import settings as mist_settings
from tests.support.core_cases import rendered_part
from tests.support.scenes import translation

DEPTH = 5.0  # the point's distance in front of the perspective camera
PRE, POST = 0.5, 1.5  # the object's x at the previous and next frame, from 0 now


def perspective(motion_pass=None):
    """A camera at the origin looking down -z, window (-1, 1) x (-0.5, 0.5) on z = -1, 32 x 16 pixels:
    16 pixels per unit on that plane."""
    return Camera(np.eye(4)[None], (-1, 1, -0.5, 0.5), (32, 16), motion_pass=motion_pass)


def moving(pre=PRE, post=POST, y=0.0):
    return Instance(0, np.eye(4), motion_pass=np.stack([translation(pre, y), translation(post, -y)]))


POINT = np.array([[0.0, 0.0, -DEPTH]])


def test_object_motion_projects_into_pixels():
    v = MotionVectors(perspective(), [moving()]).vectors(POINT, np.array([0]))[0]
    scale = 16.0 / DEPTH
    assert np.allclose(v, [PRE * scale, 0.0, -POST * scale, 0.0], rtol=1e-12)


def test_y_is_up():
    v = MotionVectors(perspective(), [moving(0.0, 0.0, y=0.25)]).vectors(POINT, np.array([0]))[0]
    assert np.allclose(v, [0.0, 0.25 * 16 / DEPTH, 0.0, 0.25 * 16 / DEPTH], rtol=1e-12)


def test_a_moving_camera_sees_the_opposite_motion():
    """The camera moved by -x sees a still point as an object moved by +x sees it from a still camera."""
    cam = perspective(np.stack([translation(-PRE), translation(-POST)]))
    seen = MotionVectors(cam, [Instance(0, np.eye(4))]).vectors(POINT, np.array([0]))
    assert np.allclose(seen, MotionVectors(perspective(), [moving()]).vectors(POINT, np.array([0])), rtol=1e-12)


def test_nothing_moves_gives_exactly_zero():
    points = np.random.default_rng(1).normal(size=(64, 3)) - [0, 0, 5]
    assert np.all(MotionVectors(perspective(), [Instance(0, np.eye(4))]).vectors(points, np.zeros(64, int)) == 0)


TRI = np.array([[-1.0, -1.0, -DEPTH], [1.0, -1.0, -DEPTH], [0.0, 1.0, -DEPTH]])
SHIFT = np.array([[[0.1, 0, 0], [0.3, 0.2, 0], [0, 0, 0]], [[-0.4, 0, 0], [0, 0.5, 0], [0.2, 0, 0]]])
"""A triangle at DEPTH whose corners move differently at the previous and the next frame."""
WEIGHTS = np.array([0.2, 0.3, 0.5])


def _expected(pre, post):
    """The vector of a point moved by ``pre`` and ``post`` (world, at DEPTH) between the frames."""
    scale = 16.0 / DEPTH
    return [pre[0] * scale, pre[1] * scale, -post[0] * scale, -post[1] * scale]


def test_a_deforming_mesh_carries_its_points_with_its_vertices():
    """A point at barycentric (0.2, 0.3, 0.5) of a triangle whose corners move differently lands at
    the same place among the moved corners (the object moved too: its transform there applies)."""
    mesh = Mesh("tri", TRI, [[0, 1, 2]], [0], motion_pass_vertices=TRI + SHIFT)
    point = (WEIGHTS @ TRI)[None]
    v = MotionVectors(perspective(), [moving(0.25, 0.0)], [mesh]).vectors(point, np.array([0]), np.array([0]))[0]
    assert np.allclose(v, _expected(WEIGHTS @ SHIFT[0] + [0.25, 0, 0], WEIGHTS @ SHIFT[1]), rtol=1e-9)


def test_instances_of_one_deforming_mesh_carry_their_own_points():
    """Two instances of the deforming triangle, the second placed 0.3 up and moving its own way:
    each point is carried by the shared vertices and its own instance's placements."""
    mesh = Mesh("tri", TRI, [[0, 1, 2]], [0], motion_pass_vertices=TRI + SHIFT)
    up = Instance(0, translation(0.0, 0.3), motion_pass=np.stack([translation(-0.2, 0.3), translation(0.1, 0.3)]))
    points = np.stack([WEIGHTS @ TRI, WEIGHTS @ TRI + [0.0, 0.3, 0.0]])
    v = MotionVectors(perspective(), [moving(0.25, 0.0), up], [mesh]).vectors(points, np.array([0, 1]),
                                                                               np.array([0, 0]))
    assert np.allclose(v[0], _expected(WEIGHTS @ SHIFT[0] + [0.25, 0, 0], WEIGHTS @ SHIFT[1]), rtol=1e-9)
    assert np.allclose(v[1], _expected(WEIGHTS @ SHIFT[0] + [-0.2, 0, 0], WEIGHTS @ SHIFT[1] + [0.1, 0, 0]),
                       rtol=1e-9)


def test_orthographic_scale():
    cam = Camera(np.eye(4)[None], (-2, 2, -1, 1), (32, 16), type="ORTHO")
    v = MotionVectors(cam, [moving()]).vectors(POINT * 3, np.array([0]))[0]
    assert np.allclose(v, [PRE * 8, 0.0, -POST * 8, 0.0], rtol=1e-12)  # 8 pixels per unit, any depth


def scene():
    """The index passes' quads (core test_mist_index) seen from above: quad B (under 0 < x < 0.5,
    8 pixels per unit) at x -0.25 the previous frame and +0.5 the next, quad A still."""
    data = quads()
    data.instances[1].motion_pass = np.stack([translation(-0.25), translation(0.5)])
    return data


B_VECTOR = (-2.0, 0.0, -4.0, 0.0)


def settings(**kw):
    return mist_settings(passes=("Combined", "Vector"), **kw)


@pytest.mark.parametrize("pattern", ["SOBOL", "GRID"])
def test_pixels_read_the_vector_of_their_hits(pattern):
    """With a wide Gaussian, pixels beside quad B's outer edge mix its samples with the background's:
    they still read B's vector (the background's samples weigh nothing), A's pixels 0, the background 0."""
    s = settings(pattern=pattern)
    s.filter_type, s.filter_size = "GAUSSIAN", 3.0
    v = render(scene(), s)[1].passes["Vector"]
    assert v.shape == (RES, RES, 4)
    b = np.all(np.isclose(v, B_VECTOR, atol=1e-9), axis=-1)
    zero = np.all(v == 0.0, axis=-1)
    assert np.all((b | zero)[:, RES // 2 + 2:])  # (beside A's edge B's and A's hits mix, both weighing 1)
    assert np.all(b[:, RES // 2 + 2:3 * RES // 4]) and np.all(zero[:, :RES // 2 - 2])
    assert zero[:, -1].all()
    if pattern == "SOBOL":  # past the edge: B's where its samples reach (8 grid samples stay closer)
        assert b[:, 3 * RES // 4:].any()


def test_an_unweighted_mean_would_be_diluted():
    """The same pixels read as a plain mean over all samples fall between B's vector and 0."""
    s = settings()
    s.filter_type, s.filter_size = "GAUSSIAN", 3.0
    renderer, _ = render(scene(), s)
    total = renderer.film.sums["Vector"]
    plain = total[:, :4] / renderer.film.count[:, None]
    assert np.any((plain[:, 0] < -0.01) & (plain[:, 0] > -1.99))


def test_no_work_when_off():
    renderer, result = render(scene(), mist_settings(passes=("Combined",)))
    assert "Vector" not in result.passes and renderer.integrator.motion_vectors is None


def test_parts_merge_into_the_whole_render(tmp_path):
    data = scene()

    def part(start, end):
        return rendered_part(data, settings(start=start, end=end))

    _, whole = part(0, 0)
    pieces = [part(a, b)[0] for a, b in ((3, 8), (0, 3))]
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    images = merge.merge_parts([parts.read(tmp_path / f"{i}.exr") for i in range(2)], ["A", "B"]).film.images()
    assert np.allclose(images["Vector"], whole.passes["Vector"], rtol=1e-6, atol=1e-12)



def turned(angle, z=0.0):
    """Camera-to-world: turned by ``angle`` about y, at height ``z``."""
    c, s = np.cos(angle), np.sin(angle)
    m = translation(0.0, 0.0, z)
    m[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    return m


def test_background_directions_as_cycles_projects_them():
    """A camera ray straight ahead, the camera turned by a at the previous frame: Cycles 5.2's
    camera_motion_vector_direction takes the world-to-raster projection without its translation and
    without dividing by depth, so x moves by 16 (sin a + cos a - 1) (the raster's origin at the
    window's corner, x = -1 on z = -1), y by 8 (cos a - 1) (its corner at y = -0.5)."""
    a = 0.1
    cam = perspective(np.stack([turned(a), np.eye(4)]))
    v = MotionVectors(cam, []).directions(np.array([[0.0, 0.0, -1.0]]))[0]
    assert np.allclose(v, [16 * (np.sin(a) + np.cos(a) - 1), 8 * (np.cos(a) - 1), 0.0, 0.0], rtol=1e-12)


def test_a_camera_that_only_moves_gives_the_background_zero():
    cam = perspective(np.stack([translation(-PRE), translation(-POST)]))
    dirs = np.random.default_rng(2).normal(size=(32, 3))
    assert np.all(MotionVectors(cam, []).directions(dirs) == 0.0)


@pytest.mark.parametrize("background", [False, True])
def test_the_background_writes_the_cameras_turning_only_when_asked(background):
    """The quads under an orthographic camera turned by -a and +a at the previous and next frame: with
    ``vector_background`` (Cycles 5.2) the background's pixels read the turning, 8 sin a pixels per
    half, else 0 (Cycles 5.0)."""
    a = 0.05
    data = quads()
    data.camera.motion_pass = np.stack([turned(-a, 10.0), turned(a, 10.0)])
    s = settings()
    s.vector_background = background
    v = render(data, s)[1].passes["Vector"][:, 3 * RES // 4 + 1:]
    expected = [-8 * np.sin(a), 0.0, -8 * np.sin(a), 0.0] if background else [0.0] * 4
    assert np.allclose(v, expected, rtol=1e-6, atol=1e-12)  # the film keeps float32
