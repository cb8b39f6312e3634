"""Small textured scenes and images written in code for the texture and IBL tests."""
from dataclasses import replace

import numpy as np

from drt_engine.core.scene import Camera, Closure, Instance, Material, Mesh, Program, SceneData, TextureImage, World
from tests.support.scenes import translation


def write_image(path, pixels_top_first: np.ndarray):
    """Write an image file with OpenImageIO (uint8 input as 8-bit, float as float)."""
    import OpenImageIO as oiio

    px = np.ascontiguousarray(pixels_top_first)
    h, w, c = px.shape
    fmt = oiio.UINT8 if px.dtype == np.uint8 else oiio.FLOAT
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(w, h, c, fmt))
    out.write_image(px)
    out.close()
    return str(path)


def uv_plane(half=1.0, uv_scale=1.0, z=0.0):
    """Square plane in z = ``z`` with UV (0, 0) at (-half, -half) up to ``uv_scale`` at (half, half)."""
    v = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]])
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float) * uv_scale
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    return Mesh("plane", v, tris, [0, 0], uvs=uv[tris])


def ortho_top(res=16, half=1.0, height=1.0):
    return Camera(translation(0, 0, height)[None], (-half, half, -half, half), (res, res), type="ORTHO")


def image_program(image=0, interpolation="Linear", extension="REPEAT"):
    """Program whose node 1, output 0, is the image's colour at the UV coordinates."""
    prog = Program()
    uv = prog.add("coord", name="uv", map="")
    prog.add("image", [(uv, 0)], image=image, interpolation=interpolation, extension=extension)
    return prog, (1, 0)


def diffuse_textured(program, color_ref, name="textured", **inputs):
    closure = Closure("DIFFUSE", color=(0.8, 0.8, 0.8), roughness=0.0, inputs={"color": color_ref, **inputs})
    return Material(name, [closure], program)


def constant_world_scene(mesh, material, camera, radiance=1.0, images=()):
    """One mesh under a uniform world of the given radiance (which a diffuse surface reflects exactly)."""
    return SceneData(camera=camera, meshes=[mesh], instances=[Instance(0, np.eye(4))], materials=[material],
                     world=World(radiance=np.full(3, radiance)), images=list(images))


def with_image_world(scene: SceneData) -> SceneData:
    """``scene`` under an image world (a random 16x8 map), which lights.environment tabulates."""
    sky = TextureImage("sky", pixels=np.random.default_rng(5).random((8, 16, 4)) * 3, colorspace="Non-Color")
    return replace(scene, world=environment_world(image=0), images=[sky])


def environment_world(image=0, strength=1.0, rotation=None, interpolation="Linear"):
    """A world program: Environment Texture (optionally through a Mapping rotation) times strength."""
    prog = Program()
    d = prog.add("coord", name="generated")
    vec = (d, 0)
    if rotation is not None:
        zero = prog.add("const", value=np.zeros(3))
        rot = prog.add("const", value=np.asarray(rotation, float))
        one = prog.add("const", value=np.ones(3))
        vec = (prog.add("mapping", [vec, (zero, 0), (rot, 0), (one, 0)], type="POINT"), 0)
    env = prog.add("environment", [vec], image=image, interpolation=interpolation)
    s = prog.add("const", value=float(strength))
    out = prog.add("vector_math", [(env, 0), (env, 0), (env, 0), (s, 0)], operation="SCALE")
    return World(program=prog, color=(out, 0))
