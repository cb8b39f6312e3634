"""Ray visibility of objects and lights, as Cycles': an object hidden from a kind of ray is passed
by it (Embree instance masks), a light hidden from a kind of ray neither lights that kind's BSDF
parts nor is seen by its rays, and a light with Cast Shadow off is never shadowed."""
import numpy as np
import pytest

from drt_engine.core.geometry import embree
from drt_engine.core.geometry.visibility import CAMERA, DIFFUSE, GLOSSY, SHADOW, TRANSMIT
from drt_engine.core.render.prepared import PreparedScene
from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, Mesh, SceneData
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import translation
from tests.support.textured_scenes import ortho_top, uv_plane

RES = 8
CENTRE = slice(3, 5)


def square(half, z, material):
    v = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], float)
    return Mesh("square", v, [[0, 1, 2], [0, 2, 3]], [material, material])


def render(scene, samples=16):
    result = Renderer(scene, RenderSettings(samples=samples, seed=0, threads=1)).render()
    return result.passes["Combined"][..., :3].astype(np.float64)


def test_embree_skips_instances_whose_mask_the_ray_does_not_share():
    """The measurement the masks rest on: embreex's libembree4 honours ray masks on instances."""
    tri = embree.TriangleScene(np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], float), [[0, 1, 2]])
    top = embree.InstanceScene()
    top.add(tri, np.eye(4), mask=DIFFUSE | SHADOW)
    top.commit()
    ray = dict(origins=[[0.0, 0.0, -5.0]], directions=[[0.0, 0.0, 1.0]])
    hit = {mask: embree.intersect(top, **ray, mask=mask)["geomID"][0] for mask in (-1, CAMERA, DIFFUSE, GLOSSY,
                                                                                   TRANSMIT, SHADOW)}
    assert hit == {-1: 0, CAMERA: -1, DIFFUSE: 0, GLOSSY: -1, TRANSMIT: -1, SHADOW: 0}
    assert not embree.occluded(top, **ray, mask=GLOSSY)[0] and embree.occluded(top, **ray, mask=SHADOW)[0]


def occluded_scene(light_shadow=True, **occluder):
    """A grey floor lit by a point light above, a grey square between them over the image's centre."""
    grey = Material("grey", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])
    light = Light("POINT", translation(0, 0, 3), intensity=np.full(3, 20.0), cast_shadow=light_shadow)
    return SceneData(camera=ortho_top(RES, half=1.0, height=2.0), meshes=[uv_plane(half=2.0), square(0.45, 0.5, 0)],
                     instances=[Instance(0, np.eye(4)), Instance(1, np.eye(4), **occluder)], materials=[grey],
                     lights=[light])


def test_object_hidden_from_camera_still_casts_its_shadow():
    seen = render(occluded_scene())
    hidden = render(occluded_scene(visible_camera=False))
    open_floor = render(occluded_scene(visible_camera=False, visible_shadow=False))
    assert np.array_equal(hidden[0, 0], seen[0, 0])
    assert seen[CENTRE, CENTRE].min() > 0  # the square's lit top
    assert np.all(hidden[CENTRE, CENTRE] == 0)  # the floor in its shadow
    assert open_floor[CENTRE, CENTRE].min() > 0.5 * open_floor.max()


def test_object_hidden_from_shadow_rays_casts_no_shadow():
    without = render(SceneData(**{**occluded_scene().__dict__, "instances": occluded_scene().instances[:1]}))
    shadowless = render(occluded_scene(visible_shadow=False))
    assert np.array_equal(shadowless[0, 0], without[0, 0])
    assert np.allclose(shadowless[CENTRE, CENTRE], render(occluded_scene())[CENTRE, CENTRE])  # seen by the camera
    hidden = render(occluded_scene(visible_shadow=False, visible_camera=False))
    assert np.allclose(hidden, without)


def test_light_with_cast_shadow_off_is_never_shadowed():
    lit = render(occluded_scene(visible_shadow=False, visible_camera=False))
    assert np.allclose(render(occluded_scene(light_shadow=False, visible_camera=False)), lit)
    assert np.all(render(occluded_scene(visible_camera=False))[CENTRE, CENTRE] == 0)


def mirror_scene(**glow):
    """A mirror floor under an emissive square between it and the camera."""
    mirror = Material("mirror", [Closure("GLOSSY", color=(1, 1, 1), roughness=0.0)])
    glowing = Material("glow", [Closure("EMISSION", emission=(1.0, 1.0, 1.0))])
    return SceneData(camera=ortho_top(RES, half=1.0, height=2.0), meshes=[uv_plane(half=2.0), square(0.45, 0.5, 1)],
                     instances=[Instance(0, np.eye(4)), Instance(1, np.eye(4), **glow)], materials=[mirror, glowing])


def test_object_hidden_from_camera_is_seen_in_a_mirror():
    seen, reflected = render(mirror_scene(), 4), render(mirror_scene(visible_camera=False), 4)
    assert np.allclose(seen[CENTRE, CENTRE], 1.0)
    assert reflected[CENTRE, CENTRE].min() > 0.9  # through it to the mirror, which shows it
    assert np.all(render(mirror_scene(visible_camera=False, visible_glossy=False), 4)[CENTRE, CENTRE] == 0)


def lit_from_above(closure, light=None, **glow):
    """A floor of ``closure`` lit by an area light (``light`` its settings) or, without one, by an
    emissive square (``glow`` its object's settings) hidden from the camera, which looks through it."""
    materials = [Material("floor", [closure]), Material("glow", [Closure("EMISSION", emission=(5.0, 5.0, 5.0))])]
    meshes, instances, lights = [uv_plane(half=2.0)], [Instance(0, np.eye(4))], []
    if light is None:
        meshes.append(square(0.5, 1.0, 1))
        instances.append(Instance(1, np.eye(4), visible_camera=False, **glow))
    else:
        lights.append(Light("AREA", translation(0, 0, 1.0), radiance=np.full(3, 5.0), size_x=1.0, size_y=1.0,
                            **light))
    return SceneData(camera=ortho_top(RES, half=0.5, height=2.0), meshes=meshes, instances=instances,
                     materials=materials, lights=lights)


DIFFUSE_FLOOR = Closure("DIFFUSE", color=(0.8, 0.8, 0.8))
GLOSSY_FLOOR = Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.5, multiscatter=False)


@pytest.mark.parametrize("emitter", ["light", "emissive object"])
def test_emitter_hidden_from_diffuse_rays_lights_glossy_parts_only(emitter):
    """By light sampling and by the rays a rough glossy floor reflects toward it alike: the glossy
    floor's image is the fully visible emitter's; the diffuse floor stays black."""
    def floor(closure, **visibility):
        return render(lit_from_above(closure, visibility) if emitter == "light"
                      else lit_from_above(closure, **visibility), 32)

    assert floor(DIFFUSE_FLOOR).min() > 0 and np.all(floor(DIFFUSE_FLOOR, visible_diffuse=False) == 0)
    full, partial = floor(GLOSSY_FLOOR), floor(GLOSSY_FLOOR, visible_diffuse=False)
    assert full.min() > 0 and np.allclose(partial, full)
    assert np.all(floor(GLOSSY_FLOOR, visible_glossy=False) == 0)



def test_shadow_rays_through_a_transparent_sheet_pass_an_object_hidden_from_them():
    """A transparent sheet under the occluder: the shadow rays it lets through (the transparent-shadow
    queue) pass the occluder hidden from shadow rays as the plain occlusion queries do."""
    def scene(occluder):
        s = occluded_scene(visible_camera=False, visible_shadow=False)
        s.materials.append(Material("sheet", [Closure("TRANSPARENT", color=(0.5, 0.5, 0.5))]))
        s.meshes.append(square(0.6, 0.3, 1))  # below the occluder: the queue meets it
        s.instances.append(Instance(2, np.eye(4), visible_camera=False))
        if not occluder:
            s.instances.pop(1)
        return s

    through = render(scene(occluder=True))
    assert through[CENTRE, CENTRE].min() > 0 and np.allclose(through, render(scene(occluder=False)))


def test_emissive_object_no_bsdf_ray_sees_is_no_light():
    """Left out of light sampling, as Cycles leaves it out of its light distribution: it lights nothing."""
    visibility = dict(visible_diffuse=False, visible_glossy=False, visible_transmission=False)
    assert len(PreparedScene(lit_from_above(DIFFUSE_FLOOR, visible_diffuse=False)).lights.emissive) == 2
    assert len(PreparedScene(lit_from_above(DIFFUSE_FLOOR, **visibility)).lights.emissive) == 0


@pytest.mark.parametrize("hidden, dark", [("visible_transmission", True), ("visible_glossy", False)])
def test_object_hidden_from_transmission_is_not_seen_through_glass(hidden, dark):
    """Rays refracted into a glass sheet are transmission rays: they pass a glowing square hidden
    from transmission (and see it when only glossy rays may not)."""
    glass = Material("glass", [Closure("REFRACTION", color=(1, 1, 1), roughness=0.0, ior=1.5)])
    glowing = Material("glow", [Closure("EMISSION", emission=(1.0, 1.0, 1.0))])
    scene = SceneData(camera=ortho_top(RES, half=1.0, height=2.0), meshes=[square(2.0, 1.0, 0), square(2.0, 0.0, 1)],
                      instances=[Instance(0, np.eye(4)), Instance(1, np.eye(4), **{hidden: False})],
                      materials=[glass, glowing])
    image = render(scene, 4)
    assert np.all(image == 0) if dark else image.min() > 0.4  # 1 / 1.5² of it, seen from inside the glass
