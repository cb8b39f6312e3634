"""DRT's own binding of Embree's C API (core/geometry/embree.py) against embreex, which calls the same
library: the RTCRayHit layout, closest hits and occlusion, tnear/tfar, instances, motion time steps,
the error callback, the rule that finds the library in each wheel, and kernels loaded from the disk
cache in a fresh process."""
import ctypes
import gc
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from drt_engine.core.errors import DRTError
from drt_engine.core.geometry import embree
from tests.support.scenes import uv_sphere

ROOT = Path(__file__).resolve().parents[2]


def _sphere():
    mesh = uv_sphere(radius=1.0, segments=64, rings=32)
    return mesh.vertices.astype(np.float32), mesh.triangles.astype(np.int32)


def _random_triangles(rng, count=2000):
    centers = rng.uniform(-1, 1, (count, 1, 3))
    vertices = (centers + rng.normal(0, 0.08, (count, 3, 3))).reshape(-1, 3).astype(np.float32)
    return vertices, np.arange(3 * count, dtype=np.int32).reshape(-1, 3)


def _random_rays(rng, count):
    """Incoherent rays from a shell of radius 3 towards random points inside the unit cube."""
    origins = rng.normal(size=(count, 3))
    origins *= 3 / np.linalg.norm(origins, axis=1, keepdims=True)
    directions = rng.uniform(-1, 1, (count, 3)) - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return origins.astype(np.float32), directions.astype(np.float32)


def _embreex(vertices, triangles):
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, vertices, triangles)
    return scene


@pytest.mark.parametrize("mesh", ["sphere", "random triangles"])
def test_closest_hits_equal_embreex(mesh):
    rng = np.random.default_rng(1)
    vertices, triangles = _sphere() if mesh == "sphere" else _random_triangles(rng)
    origins, directions = _random_rays(rng, 20000)
    theirs = _embreex(vertices, triangles).run(origins, directions, output=1)
    with embree.TriangleScene(vertices, triangles) as scene:
        ours = embree.intersect(scene, origins, directions)
    hit = theirs["geomID"] >= 0
    assert 0.2 < hit.mean() < 0.99  # both hits and misses are tested
    np.testing.assert_array_equal(ours["primID"], theirs["primID"])
    np.testing.assert_array_equal(ours["geomID"], theirs["geomID"])
    assert (ours["instID"] == -1).all()
    np.testing.assert_array_equal(ours["t"][hit], theirs["tfar"][hit])  # bit for bit: both scenes are robust
    assert np.isinf(ours["t"][~hit]).all()
    np.testing.assert_array_equal(ours["uv"][hit, 0], theirs["u"][hit])
    np.testing.assert_array_equal(ours["uv"][hit, 1], theirs["v"][hit])
    np.testing.assert_array_equal(ours["Ng"][hit], theirs["Ng"][hit])

def test_occlusion_equals_embreex():
    rng = np.random.default_rng(2)
    vertices, triangles = _random_triangles(rng)
    origins, directions = _random_rays(rng, 20000)
    theirs = _embreex(vertices, triangles).run(origins, directions, query="OCCLUDED")
    with embree.TriangleScene(vertices, triangles) as scene:
        ours = embree.occluded(scene, origins, directions)
    assert 0.2 < ours.mean() < 0.99
    np.testing.assert_array_equal(ours, theirs >= 0)


def test_tnear_and_tfar_bound_the_ray():
    """Rays through the centre of a unit sphere from distance 3 cross it at t = 2 and t = 4."""
    vertices, triangles = _sphere()
    rng = np.random.default_rng(3)
    origins, _ = _random_rays(rng, 1000)
    directions = -origins / 3
    with embree.TriangleScene(vertices, triangles) as scene:
        near = embree.intersect(scene, origins, directions)
        far = embree.intersect(scene, origins, directions, tnear=3.0)
        short = embree.intersect(scene, origins, directions, tfar=1.9)
        blocked = embree.occluded(scene, origins, directions, tfar=np.where(np.arange(1000) % 2, 2.1, 1.9))
    sagitta = 1 - np.cos(np.pi / 64) ** 2  # the facets lie inside the sphere by at most this
    assert ((2 <= near["t"]) & (near["t"] <= 2 + sagitta)).all()
    assert ((4 - sagitta <= far["t"]) & (far["t"] <= 4)).all()
    assert (short["geomID"] == -1).all() and np.isinf(short["t"]).all()
    np.testing.assert_array_equal(blocked, np.arange(1000) % 2 == 1)


def test_bad_triangles_are_refused_before_embree_reads_them():
    with pytest.raises(DRTError, match="vertex 3 of 3"):
        embree.TriangleScene(np.zeros((3, 3)), [[0, 1, 3]])


def test_rayhit_scratch_is_16_byte_aligned():
    for _ in range(64):
        floats, ints = embree.new_rayhit()
        assert floats.ctypes.data % 16 == 0 and ints.ctypes.data == floats.ctypes.data and floats.nbytes == 96


def _transform(angle, scale, offset):
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    m[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) * scale
    m[:3, 3] = offset
    return m


def test_instances_hit_like_the_mesh_transformed_by_hand():
    vertices, triangles = _sphere()
    transforms = [_transform(0.3, 1.0, (-1.2, 0, 0)), _transform(1.1, 0.7, (1.0, 0.4, 0.2))]
    world = [(np.c_[vertices, np.ones(len(vertices))] @ m.T)[:, :3] for m in transforms]
    rng = np.random.default_rng(4)
    origins, directions = _random_rays(rng, 20000)
    origins *= 1.5
    with embree.TriangleScene(vertices, triangles) as mesh, embree.InstanceScene() as top, \
            embree.TriangleScene(np.concatenate(world), np.concatenate([triangles, triangles + len(vertices)])) as flat:
        assert [top.add(mesh, m) for m in transforms] == [0, 1]
        top.commit()
        ours = embree.intersect(top, origins, directions)
        by_hand = embree.intersect(flat, origins, directions)
        shadow = embree.occluded(top, origins, directions)
    hit = by_hand["geomID"] >= 0
    assert 0.2 < hit.mean() < 0.9
    np.testing.assert_array_equal(ours["geomID"] >= 0, hit)
    np.testing.assert_array_equal(shadow, hit)
    inst = by_hand["primID"][hit] // len(triangles)
    np.testing.assert_array_equal(ours["instID"][hit], inst)
    np.testing.assert_array_equal(ours["geomID"][hit], 0)  # the mesh's own geometry in its own scene
    np.testing.assert_array_equal(ours["primID"][hit], by_hand["primID"][hit] % len(triangles))
    np.testing.assert_allclose(ours["t"][hit], by_hand["t"][hit], rtol=1e-5)
    # Ng comes back in the mesh's object space: the untransformed triangle's normal
    p = vertices[triangles[ours["primID"][hit]]]
    object_ng = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    np.testing.assert_allclose(ours["Ng"][hit], object_ng, rtol=1e-4, atol=1e-7)


def test_moving_an_instance_moves_its_hits_once_the_top_level_is_committed():
    vertices, triangles = _sphere()
    origins, directions = np.array([[5.0, 0, 3]]), np.array([[0.0, 0, -1]])
    with embree.TriangleScene(vertices, triangles) as mesh, embree.InstanceScene() as top:
        top.add(mesh, np.eye(4))
        top.commit()
        assert embree.intersect(top, origins, directions)["instID"][0] == -1
        top.move(0, _transform(0, 1, (5, 0, 0)))
        top.commit()
        np.testing.assert_allclose(embree.intersect(top, origins, directions)["t"], 2.0, atol=2e-3)


@pytest.mark.parametrize("time", [0.0, 0.25, 0.5, 1.0])
def test_motion_time_steps_interpolate(time):
    """Rigid motion as instance transforms and deformation as vertex steps: a unit square moving
    from z = 0 to z = 1 is met at z = time by a ray at that time."""
    square = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    quads = np.array([[0, 1, 2], [0, 2, 3]])
    lifted = square + np.float32([0, 0, 1])
    origins, directions = np.array([[0.1, 0.2, 3.0]]), np.array([[0.0, 0, -1]])
    with embree.TriangleScene(square, quads) as flat, embree.InstanceScene() as rigid, \
            embree.TriangleScene(np.stack([square, lifted]), quads) as deforming:
        rigid.add(flat, [np.eye(4), _transform(0, 1, (0, 0, 1))])
        rigid.commit()
        for scene in (rigid, deforming):
            np.testing.assert_allclose(embree.intersect(scene, origins, directions, time=time)["t"], 3 - time,
                                       atol=1e-5)


@pytest.mark.parametrize("time", [0.25, 0.5, 0.8])
@pytest.mark.parametrize("mirror", [False, True])
def test_a_spinning_instance_turns_by_slerp_and_keeps_its_size(time, mirror):
    """A wall 2 from the z axis turning a quarter turn about it (scaled by 1.5 along z, mirrored in
    z or not, moving up by 1) is met at distance 2 along the direction it faces at ``time``: the
    rotation is slerped and the stretch and translation lerped, as geometry/motion.py does.
    Interpolated matrices would put it at 2 cos(45 deg) halfway."""
    wall = np.array([[2, -1, -1], [2, 1, -1], [2, 1, 1], [2, -1, 1]], np.float32)
    quads = np.array([[0, 1, 2], [0, 2, 3]])
    steps = np.array([_transform(angle, 1.0, (0, 0, lift)) for angle, lift in ((0, 0), (np.pi / 2, 1))])
    steps[:, 2, 2] = -1.5 if mirror else 1.5
    angle = time * np.pi / 2
    direction = np.array([[np.cos(angle), np.sin(angle), 0.0]])
    with embree.TriangleScene(wall, quads) as mesh, embree.InstanceScene() as top:
        top.add(mesh, steps)
        top.commit()
        hit = embree.intersect(top, [[0, 0, time]], direction, time=time)
    assert hit["instID"][0] == 0
    np.testing.assert_allclose(hit["t"], 2.0, rtol=1e-5)


def test_moving_instances_start_and_end_at_their_given_matrices():
    """The quaternion decomposition Embree gets for a moving instance rebuilds each step's matrix,
    shear and mirror included: at ray times 0 and 1 hits equal those of a still instance."""
    rng = np.random.default_rng(5)
    steps = np.tile(np.eye(4), (2, 1, 1))
    steps[:, :3, :] = rng.uniform(-0.6, 0.6, (2, 3, 4)) + np.eye(3, 4)
    steps[1, :, 0] *= -1  # the end mirrored
    vertices, triangles = _sphere()
    origins, directions = _random_rays(rng, 5000)
    with embree.TriangleScene(vertices, triangles) as mesh, embree.InstanceScene() as moving:
        moving.add(mesh, steps)
        moving.commit()
        for time, matrix in zip((0.0, 1.0), steps):
            with embree.InstanceScene() as still:
                still.add(mesh, matrix)
                still.commit()
                expected = embree.intersect(still, origins, directions)
            got = embree.intersect(moving, origins, directions, time=time)
            hit = expected["geomID"] >= 0
            assert 0.2 < hit.mean() < 0.9
            assert (got["primID"] != expected["primID"]).mean() < 1e-3  # rounding near edges only
            np.testing.assert_allclose(got["t"][hit], expected["t"][hit], rtol=1e-4)


@pytest.mark.parametrize("moving", [False, True])
def test_a_pivot_places_vertices_given_relative_to_it(moving):
    """A mesh handed to Embree relative to a point of its own (the pivot) and instanced with that
    pivot hits where the mesh given as it is does, under the same transform(s): a still one, or a
    turn, stretch and shift over the shutter (the pivot turns about the object's origin)."""
    vertices, triangles = _sphere()
    pivot = np.array([0.5, -0.3, 0.2])
    steps = np.array([_transform(0.0, 1.0, (0, 0, 0)), _transform(0.8, 1.3, (0.2, 0.1, -0.1))])
    steps[1, 2, 2] = 0.7
    transforms = steps if moving else steps[1]
    rng = np.random.default_rng(6)
    origins, directions = _random_rays(rng, 5000)
    time = rng.random(5000)
    with embree.TriangleScene(vertices + pivot.astype(np.float32), triangles) as whole, \
            embree.TriangleScene(vertices, triangles) as centred, embree.InstanceScene() as plain, \
            embree.InstanceScene() as pivoted:
        plain.add(whole, transforms)
        pivoted.add(centred, transforms, pivot)
        plain.commit()
        pivoted.commit()
        expected = embree.intersect(plain, origins, directions, time=time)
        got = embree.intersect(pivoted, origins, directions, time=time)
    hit = expected["geomID"] >= 0
    assert 0.2 < hit.mean() < 0.9
    assert (got["primID"] != expected["primID"]).mean() < 1e-3  # rounding near edges only
    both = hit & (got["primID"] == expected["primID"])
    np.testing.assert_allclose(got["t"][both], expected["t"][both], rtol=1e-4)


def test_mesh_scene_builds_are_counted():
    vertices, triangles = _sphere()
    before = embree.TriangleScene.builds
    with embree.TriangleScene(vertices, triangles) as mesh, embree.InstanceScene() as top:
        top.add(mesh, np.eye(4))
        top.add(mesh, _transform(0.3, 1.0, (2, 0, 0)))
        top.commit()
    assert embree.TriangleScene.builds - before == 1


def test_error_callback_reports_and_the_device_keeps_working():
    """Instancing a closed scene passes Embree a NULL scene: the callback records Embree's message,
    the call raises it, and the device goes on tracing."""
    vertices, triangles = _sphere()
    closed = embree.TriangleScene(vertices, triangles)
    closed.close()
    with embree.InstanceScene() as top:
        with pytest.raises(embree.EmbreeError, match="^Embree failed placing an instance: invalid argument"):
            top.add(closed, np.eye(4))
        assert top.device.errors == []
        with embree.TriangleScene(vertices, triangles) as mesh:
            assert top.add(mesh, np.eye(4)) == 0
            top.commit()
            assert embree.intersect(top, [[0, 0, 3]], [[0, 0, -1]])["primID"][0] >= 0


def test_scenes_release_their_handle_on_close_and_on_collection():
    vertices, triangles = _sphere()
    with embree.TriangleScene(vertices, triangles) as scene:
        release = scene._release
    assert not release.alive and scene.handle == 0
    scene.close()  # twice is harmless
    scene = embree.TriangleScene(vertices, triangles)
    release = scene._release
    del scene
    gc.collect()
    assert not release.alive


def _wheel(tmp_path, files):
    for name in files:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(b"")
    return tmp_path / "embreex"


@pytest.mark.parametrize("files, expected", [
    (["embreex/__init__.py", "embreex.libs/libembree4-4aef3270.so.4", "embreex.libs/libtbb-dcf63f8c.so.12"],
     "embreex.libs/libembree4-4aef3270.so.4"),
    (["embreex/__init__.py", "embreex.libs/embree4.dll", "embreex.libs/tbb12.dll"], "embreex.libs/embree4.dll"),
    (["embreex/__init__.py", "embreex/.dylibs/libembree4.4.dylib", "embreex/.dylibs/libtbb.12.dylib"],
     "embreex/.dylibs/libembree4.4.dylib"),
])
def test_library_rule_finds_each_wheels_embree(tmp_path, files, expected):
    assert embree.library_path(_wheel(tmp_path, files)) == (tmp_path / expected).resolve()


def test_missing_library_is_a_one_line_error(tmp_path):
    with pytest.raises(DRTError) as error:
        embree.library_path(_wheel(tmp_path, ["embreex/__init__.py", "embreex.libs/libtbb.so.12"]))
    assert "Embree library missing" in str(error.value) and "\n" not in str(error.value)


def test_the_installed_library_is_the_copy_embreex_uses():
    """The kernels' rtcIntersect1 is the one in embreex's file, also in a process where Blender has
    mapped its own libembree4 (bpy imported by other tests of the suite, or inside Blender)."""
    import embreex
    from llvmlite import binding as llvm

    path = embree.library_path(Path(embreex.__file__).parent)
    assert path.name.startswith("libembree4") and path.is_file()
    address = llvm.address_of_symbol("drt_rtcIntersect1")
    assert address == ctypes.cast(embree._lib.rtcIntersect1, ctypes.c_void_p).value
    if sys.platform.startswith("linux"):
        holders = set()
        for line in Path("/proc/self/maps").read_text().splitlines():
            fields = line.split()
            low, high = (int(x, 16) for x in fields[0].split("-"))
            if low <= address < high:
                holders.add(fields[-1])
        assert holders == {str(path)}


_CACHED_RUN = """
import numpy as np
from drt_engine.core.geometry import embree
scene = embree.TriangleScene(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), [[0, 1, 2]])
hits = embree.intersect(scene, [[0.2, 0.3, 1.0]], [[0.0, 0.0, -1.0]])
blocked = embree.occluded(scene, [[0.2, 0.3, 1.0]], [[0.0, 0.0, -1.0]])
stats = [f.stats for f in (embree.intersect_batch, embree.occluded_batch)]
print(sum(sum(s.cache_hits.values()) for s in stats), sum(sum(s.cache_misses.values()) for s in stats),
      hits["t"][0], hits["primID"][0], blocked[0])
"""


def test_kernels_load_from_the_disk_cache_in_a_fresh_process(tmp_path):
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))  # keep the caller's (Blender's site-packages)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=path)

    def run():
        out = subprocess.run([sys.executable, "-c", textwrap.dedent(_CACHED_RUN)], env=env, cwd=ROOT,
                             capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr
        return out.stdout.split()

    first, second = run(), run()
    assert first[:2] == ["0", "2"]  # compiled
    assert second[:2] == ["2", "0"]  # loaded, and the call into Embree bound by name in this process
    assert first[2:] == second[2:] == ["1.0", "0", "True"]
