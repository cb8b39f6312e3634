"""Degenerate input: zero-area and sliver triangles, duplicates, NaN/Inf vertices, coincident
faces, meshes without faces, 10^6 triangles in one object, 10^4 objects."""
import numpy as np
import pytest

from drt_engine.core.scene import Mesh

from tests.support.core_cases import Camera, Closure, Instance, Light, Material, SceneData, World, diffuse, render
from tests.support.scenes import look_at, plane, translation, uv_sphere


def lit(meshes, instances=None, res=16, materials=None):
    """Meshes under a sun, seen from above by a camera that frames the unit square."""
    cam = Camera(translation(0, 0, 3)[None], (-0.2, 0.2, -0.2, 0.2), (res, res))
    sun = Light("SUN", look_at((0.3, 0.2, 1), (0, 0, 0)), irradiance=np.full(3, 2.0))
    instances = instances or [Instance(i, np.eye(4)) for i in range(len(meshes))]
    return SceneData(cam, meshes, instances, materials or [diffuse(0.5)], [sun], World(np.full(3, 0.1)))


def sliver_quad(n=64, ratio=1e6):
    """The square [-1, 1]² as a fan of slivers from one corner plus zero-area triangles: strips of
    width 2/n split into a 1:ratio sliver pair each, every third triangle doubled as a degenerate one."""
    x = np.linspace(-1, 1, n + 1)
    top = np.stack([x, np.ones_like(x), np.zeros_like(x)], 1)
    bottom = np.stack([x, -np.ones_like(x), np.zeros_like(x)], 1)
    v = np.concatenate([bottom, top])
    tris = []
    for i in range(n):
        tris += [[i, i + 1, n + 1 + i + 1], [i, n + 1 + i + 1, n + 1 + i]]
    # slivers: a point 1/ratio of the strip width off the strip's diagonal
    k = len(v)
    mid = 0.5 * (v[[t[0] for t in tris[::2]]] + v[[t[2] for t in tris[::2]]])
    v = np.concatenate([v, mid + [2.0 / n / ratio, 0, 0]])
    slivers = [[tris[2 * i][0], tris[2 * i][2], k + i] for i in range(n)]
    zero = [[t[0], t[0], t[1]] for t in tris[::3]] + [[t[0], t[1], t[1]] for t in tris[1::3]]
    return Mesh("slivers", v, tris + slivers + zero, 0)


def test_sliver_and_zero_area_triangles_render_like_the_plain_square():
    plain, _ = render(lit([plane(2.0)]))
    slivers, result = render(lit([sliver_quad()]))
    assert np.array_equal(plain["Combined"], slivers["Combined"]) or \
        np.abs(plain["Combined"] - slivers["Combined"]).max() < 1e-5
    assert result.stats["triangles"] == 128 + 64  # zero-area triangles are left out, slivers kept


def test_duplicate_vertices_and_faces_render_like_the_originals():
    base = plane(2.0)
    dup_v = np.concatenate([base.vertices, base.vertices])  # every vertex twice, faces use both copies
    dup = Mesh("dup", dup_v, np.concatenate([base.triangles, base.triangles + 4, base.triangles]), 0)
    a, _ = render(lit([base]))
    b, _ = render(lit([dup]))
    assert np.abs(a["Combined"] - b["Combined"]).max() < 1e-6


@pytest.mark.filterwarnings("error")  # DRT's one warning, and no RuntimeWarning from NumPy on stderr
def test_nan_and_inf_vertices_are_dropped_with_one_warning():
    base = plane(2.0)
    v = np.concatenate([base.vertices, [[np.nan, 0, 0], [np.inf, 1, 1], [0, -np.inf, 0]]])
    tris = np.concatenate([base.triangles, [[0, 4, 1], [5, 6, 2], [4, 5, 6], [1, 2, 6]]])
    passes, result = render(lit([Mesh("bad", v, tris, 0)]))
    clean, _ = render(lit([base]))
    assert np.array_equal(passes["Combined"], clean["Combined"])
    warnings = [w for w in result.warnings if "NaN" in w]
    assert len(warnings) == 1 and warnings[0].startswith("4 triangles")


def test_coincident_faces_render_deterministically():
    """Two coincident squares, red and green: whichever Embree reports, the same on every run and thread count."""
    mats = [Material("red", [Closure("DIFFUSE", color=(0.8, 0, 0))]),
            Material("green", [Closure("DIFFUSE", color=(0, 0.8, 0))])]
    render(lit([plane(2.0, material=0), plane(2.0, material=1)], materials=mats))  # asserts bit-identical


def test_mesh_without_faces_and_scene_without_geometry():
    empty = Mesh("points", np.random.default_rng(0).normal(size=(10, 3)), np.zeros((0, 3)), [])
    passes, _ = render(lit([empty, plane(2.0)]))
    assert passes["Combined"][..., 0].min() > 0
    nothing, _ = render(lit([empty]))
    assert np.allclose(nothing["Combined"][..., :3], 0.1)  # the world


def test_one_object_of_a_million_triangles():
    sphere = uv_sphere(1.0, segments=1000, rings=501)
    assert len(sphere.triangles) >= 1_000_000
    cam = Camera(look_at((0, -3, 0), (0, 0, 0))[None], (-0.4, 0.4, -0.4, 0.4), (8, 8))
    sun = Light("SUN", look_at((0, -1, 0), (0, 0, 0)), irradiance=np.full(3, np.pi))
    scene = SceneData(cam, [sphere], [Instance(0, np.eye(4))], [diffuse(1.0)], [sun])
    passes, result = render(scene, samples=1, determinism=False, passes=("Combined", "Normal"))
    centre = passes["Combined"][3:5, 3:5, 0]
    assert np.allclose(centre, np.abs(passes["Normal"][3:5, 3:5, 1]), atol=2e-3)  # Lambert: cos to the sun


def test_ten_thousand_objects_render_like_one_merged_mesh():
    """10^4 small spheres as objects give the image of the same triangles merged into one mesh.

    Before the fix the scene took 8 s to prepare: each object's vertex offset was a sum over
    all objects before it (quadratic in the number of objects)."""
    ball = uv_sphere(0.02, segments=6, rings=3)
    grid = np.stack(np.meshgrid(np.arange(100), np.arange(100), indexing="ij"), -1).reshape(-1, 2) * 0.05 - 2.5
    cam = Camera(translation(0, 0, 10)[None], (-0.3, 0.3, -0.3, 0.3), (16, 16))
    sun = Light("SUN", look_at((0.2, 0.1, 1), (0, 0, 0)), irradiance=np.full(3, 1.0))
    objects = SceneData(cam, [ball], [Instance(0, translation(x, y, 0)) for x, y in grid], [diffuse(0.5)], [sun])
    offsets = np.concatenate([grid, np.zeros((len(grid), 1))], 1)
    merged = Mesh("merged", (ball.vertices[None] + offsets[:, None]).reshape(-1, 3),
                  (ball.triangles[None] + len(ball.vertices) * np.arange(len(grid))[:, None, None]).reshape(-1, 3),
                  0, corner_normals=np.tile(ball.corner_normals, (len(grid), 1, 1)))
    one = SceneData(cam, [merged], [Instance(0, np.eye(4))], [diffuse(0.5)], [sun])
    a, result = render(objects, samples=2, determinism=False)
    b, _ = render(one, samples=2, determinism=False)
    assert result.stats["triangles"] == 10_000 * len(ball.triangles)
    assert np.abs(a["Combined"] - b["Combined"]).max() < 1e-5
    assert a["Combined"][..., 0].mean() > 0.01
