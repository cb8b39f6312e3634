"""A triangle's material, source, world corners and normal resolved through its instance equal the
flattened tables they replaced, and the geometry's memory grows with instances, not their triangles."""
import numpy as np

from drt_engine.core.geometry.accel import Geometry
from drt_engine.core.scene import Camera, Closure, Instance, Material, SceneData
from tests.support.scenes import look_at, translation, uv_sphere


def _two_material_sphere():
    sphere = uv_sphere(1.0, segments=12, rings=6)
    sphere.material_indices = (np.arange(len(sphere.triangles)) % 2).astype(np.int32)
    return sphere


def _scene(meshes, instances):
    cam = Camera(look_at((0, -8, 3), (0, 0, 0))[None], (-0.5, 0.5, -0.5, 0.5), (8, 8))
    mats = [Material(name, [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))]) for name in ("a", "b")]
    return SceneData(cam, meshes, instances, mats, [])


def _placements():
    rotate = look_at((0, 0, 0), (1, 2, 0.5)) @ np.diag([0.5, 2.0, 1.0, 1.0])
    moving = np.stack([translation(0, 0, 0), translation(0, 2, 0)])
    return [translation(1, 2, 3), np.diag([-1.0, 1, 1, 1]) @ translation(4, 0, 0), rotate, moving]


def test_triangle_queries_match_the_flattened_instances():
    sphere, box = _two_material_sphere(), uv_sphere(0.3, segments=6, rings=3, material=1)
    instances = [Instance(0, m) for m in _placements()] + [Instance(1, translation(-3, 0, 0))]
    geo = Geometry(_scene([sphere, box], instances), np.zeros(3))
    want_material, want_source, want_corners, want_normals = [], [], [], []
    for k, inst in enumerate(instances):
        mesh = (sphere, box)[inst.mesh]
        m = inst.matrices[len(inst.matrices) // 2] if len(inst.matrices) % 2 else inst.matrices.mean(axis=0)
        p = mesh.vertices[mesh.triangles] @ m[:3, :3].T + m[:3, 3]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) * np.sign(np.linalg.det(m[:3, :3]))
        kept = np.flatnonzero(np.linalg.norm(np.cross(mesh.vertices[mesh.triangles[:, 1]] - mesh.vertices[mesh.triangles[:, 0]],
                                                      mesh.vertices[mesh.triangles[:, 2]] - mesh.vertices[mesh.triangles[:, 0]]),
                                             axis=1) > 0)
        want_material.append(mesh.material_indices[kept])
        want_source.append(np.stack([np.full(len(kept), k), kept], axis=1))
        want_corners.append(p[kept])
        want_normals.append(n[kept] / np.linalg.norm(n[kept], axis=1)[:, None])
    prim = np.arange(geo.triangle_count)
    assert geo.triangle_count == sum(len(m) for m in want_material)
    assert np.array_equal(geo.material_of(prim), np.concatenate(want_material))
    assert np.array_equal(geo.source_of(prim), np.concatenate(want_source))
    corners = geo.world_corners(prim)
    assert np.allclose(corners, np.concatenate(want_corners), rtol=0, atol=1e-12)
    normals, area = geo.world_normals(prim)
    assert np.allclose(normals, np.concatenate(want_normals), rtol=0, atol=1e-9)
    assert np.allclose(area, 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                                  axis=1), rtol=1e-12)
    assert np.array_equal(geo.triangles_with([1]), prim[geo.material_of(prim) == 1])
    assert np.array_equal(geo.materials_used(), [0, 1])


def _geometry_bytes(count, mesh):
    """Bytes of the NumPy arrays a Geometry of ``count`` instances of ``mesh`` keeps (its Embree
    scenes aside)."""
    side = int(np.ceil(np.sqrt(count)))
    instances = [Instance(0, translation(3 * (i % side), 3 * (i // side), 0)) for i in range(count)]
    geo = Geometry(_scene([mesh], instances), np.zeros(3))
    arrays = [a for a in list(vars(geo).values()) + list(geo.tables) if isinstance(a, np.ndarray)]
    return sum(a.nbytes for a in arrays)


def test_memory_grows_with_instances_not_their_triangles():
    mesh = uv_sphere(1.0, segments=96, rings=48)  # 9,024 triangles
    small, large = _geometry_bytes(10, mesh), _geometry_bytes(410, mesh)
    per_instance = (large - small) / 400
    assert per_instance < 1024, f"{per_instance:.0f} bytes per instance of {len(mesh.triangles)} triangles"
