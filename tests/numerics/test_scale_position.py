"""Scale and position: the same scene at scale 1e-4, 1 and 1e4, and moved 1e5 and 1e7 from the origin.

Radiance does not change with scale when every length scales and light powers scale by s²
(area lights keep their radiance, point lights' intensity goes with s²). The tracer
re-centres geometry on the camera in float64 before handing float32 to Embree and
rebuilds hit points in float64, so position does not matter either. With the same seed
every render draws the same random numbers: images may differ only where float error
moves a silhouette across a sample.
"""
import numpy as np
import pytest

from tests.support.core_cases import Camera, Closure, Instance, Light, Material, SceneData, World, render
from tests.support.scenes import look_at, plane, translation, uv_sphere


def scene(s=1.0, offset=0.0):
    o = np.array([offset, -0.5 * offset, 0.25 * offset])
    at = lambda *p: tuple(np.asarray(p, float) * s + o)  # noqa: E731
    cam = Camera(look_at(at(0, -5, 2), at(0, 0, 0.5))[None], (-0.35, 0.35, -0.35, 0.35), (24, 24),
                 clip_start=0.01 * s, clip_end=100 * s)
    mats = [Material("floor", [Closure("DIFFUSE", color=(0.6, 0.6, 0.6))]),
            Material("glass", [Closure("GLASS", roughness=0.1, ior=1.45)]),
            Material("metal", [Closure("PRINCIPLED", color=(0.9, 0.7, 0.3), metallic=1, roughness=0.3)])]
    meshes = [plane(20), uv_sphere(0.5, (-0.6, 0, 0.5), material=1, segments=24, rings=12),
              uv_sphere(0.5, (0.6, 0, 0.5), material=2, segments=24, rings=12)]
    place = np.diag([s, s, s, 1.0])
    place[:3, 3] = o
    lights = [Light("AREA", look_at(at(1, -2, 3), at(0, 0, 0)), radiance=np.full(3, 10.0), size_x=s, size_y=s),
              Light("POINT", translation(*at(-2, -1, 2)), intensity=np.full(3, 5.0 * s * s), radius=0.1 * s)]
    return SceneData(cam, meshes, [Instance(i, place) for i in range(3)], mats, lights, World(np.full(3, 0.05)))


@pytest.fixture(scope="module")
def reference():
    passes, _ = render(scene(), samples=4)
    return passes["Combined"][..., :3]


def differing_fraction(image, ref):
    """Share of pixels whose RGB differs from the reference by more than 1% of its mean."""
    return float((np.abs(image - ref).max(axis=2) > 0.01 * ref.mean()).mean())


@pytest.mark.parametrize("s", [1e-4, 1e4])
def test_same_image_at_every_scale(s, reference):
    passes, _ = render(scene(s=s), samples=4, determinism=False)
    image = passes["Combined"][..., :3]
    assert abs(image.mean() / reference.mean() - 1) < 1e-4
    assert differing_fraction(image, reference) <= 0.005


@pytest.mark.parametrize("offset", [1e5, 1e7])
@pytest.mark.parametrize("s", [1e-4, 1.0])
def test_same_image_far_from_the_origin(offset, s, reference):
    passes, _ = render(scene(s=s, offset=offset), samples=4, determinism=False)
    image = passes["Combined"][..., :3]
    assert abs(image.mean() / reference.mean() - 1) < 1e-4
    assert differing_fraction(image, reference) <= 0.005
    position = passes["Position"]
    assert np.abs(position[..., 0]).max() > 0.5 * offset  # positions are world positions, in float32


@pytest.mark.parametrize("offset", [1e5, 1e7])
def test_same_image_far_from_the_origin_through_blender(drt, tmp_path, offset):
    """A sphere on a floor under a point and an area light, the camera 6 m away; every location
    shifted by ``offset`` (integers, exact in Blender's float32 matrices): the same image."""
    import bpy

    from tests.support import blender_scenes as bs

    def build(o):
        scene = bs.new_scene(24, 24, 8)
        scene.camera.location = (o, o - 6.0, 2.0)
        scene.camera.rotation_euler = (1.35, 0.0, 0.0)
        bs.add_plane(scene, "Floor", half=10.0, location=(o, o, 0), mat=bs.material("DIFFUSE"))
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(o, o, 1.0), segments=24, ring_count=12)
        bpy.context.active_object.data.shade_smooth()
        bs.add_light(scene, "POINT", (o - 2.0, o - 2.0, 3.0), energy=500.0, shadow_soft_size=0.25)
        bs.add_light(scene, "AREA", (o + 2.0, o - 1.0, 4.0), rotation=(0.3, 0.4, 0.0), energy=300.0, size=1.0)
        return scene

    near = bs.render(build(0.0), tmp_path, "origin")["Combined"][..., :3]
    far = bs.render(build(offset), tmp_path, "far")["Combined"][..., :3]
    assert abs(far.mean() / near.mean() - 1) < 1e-3
    assert differing_fraction(far, near) <= 0.005
