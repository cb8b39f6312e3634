"""core.base.vectors: frames are orthonormal and right-handed, and carry vectors both ways."""
import numpy as np

from drt_engine.core.base.vectors import Frame, normalize


def _normals(rng, n=2000):
    v = normalize(rng.normal(size=(n, 3)))
    # the poles, where the branch of Duff et al.'s basis switches, and a near-pole normal
    return np.concatenate([v, [[0, 0, 1.0], [0, 0, -1.0], [1e-9, 0, -1.0]]])


def test_frame_is_orthonormal_and_right_handed():
    f = Frame.about(_normals(np.random.default_rng(1)))
    for a, b in ((f.t, f.b), (f.t, f.n), (f.b, f.n)):
        assert np.abs(np.einsum("ij,ij->i", a, b)).max() < 1e-12
    for a in (f.t, f.b):
        assert np.abs(np.linalg.norm(a, axis=1) - 1).max() < 1e-12
    assert np.abs(np.cross(f.t, f.b) - f.n).max() < 1e-12


def test_to_local_puts_the_normal_on_z_and_to_world_undoes_it():
    rng = np.random.default_rng(2)
    f = Frame.about(_normals(rng))
    assert np.abs(f.to_local(f.n) - [0, 0, 1]).max() < 1e-12
    v = rng.normal(size=f.n.shape)
    assert np.abs(f.to_world(f.to_local(v)) - v).max() < 1e-12


def test_rows_of_a_frame_are_the_frames_of_those_rows():
    f = Frame.about(_normals(np.random.default_rng(3)))
    rows = np.array([5, 0, 2001])
    g = f[rows]
    assert all(np.array_equal(getattr(g, k), getattr(f, k)[rows]) for k in "tbn")
