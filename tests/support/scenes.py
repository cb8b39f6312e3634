"""Small scenes written by hand for core tests (no Blender)."""
import numpy as np

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Mesh, SceneData
from drt_engine.core.settings import RenderSettings


def translation(x=0.0, y=0.0, z=0.0):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def plane(size=10.0, z=0.0, material=0):
    h = size / 2
    v = np.array([[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]])
    return Mesh("plane", v, [[0, 1, 2], [0, 2, 3]], [material, material])


def top_camera(height=1.0, half_width=0.01, res=8):
    """Looks straight down at the origin from ``height``; sees a tiny patch of the plane."""
    m = translation(0, 0, height)
    return Camera(m[None], (-half_width, half_width, -half_width, half_width), (res, res))


def lit_plane_scene(light: Light, albedo=0.5, camera=None, world=None):
    mat = Material("white", [Closure("DIFFUSE", color=(albedo,) * 3)])
    scene = SceneData(camera=camera or top_camera(), meshes=[plane()], instances=[Instance(0, np.eye(4))],
                      materials=[mat], lights=[light])
    if world is not None:
        scene.world.radiance = np.asarray(world, float)
    return scene


def uv_sphere(radius=1.0, center=(0, 0, 0), segments=48, rings=24, material=0, smooth=True):
    th = np.linspace(0, np.pi, rings + 1)
    ph = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    n = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    v = n * radius + np.asarray(center, float)
    idx = np.arange((rings + 1) * segments).reshape(rings + 1, segments)
    a, b = idx[:-1], np.roll(idx[:-1], -1, axis=1)
    c, d = idx[1:], np.roll(idx[1:], -1, axis=1)
    tris = np.concatenate([np.stack([a, c, d], -1).reshape(-1, 3), np.stack([a, d, b], -1).reshape(-1, 3)])
    p0, p1, p2 = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    tris = tris[np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1) > 1e-12]
    normals = n[tris] if smooth else None
    return Mesh("sphere", v, tris, np.full(len(tris), material), corner_normals=normals)


def look_at(eye, target, up=(0, 0, 1)):
    eye, target, up = (np.asarray(x, float) for x in (eye, target, up))
    z = eye - target
    z /= np.linalg.norm(z)
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, eye
    return m


def cube(center, half, material):
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * half + center
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return Mesh("cube", corners, tris, [material] * len(tris))


def soft_shadow_scene(width=160):
    """The soft-shadow scene of issue 13 (a plane, a sphere and a cube under one rectangular area light) at ``width`` x 3/4 width pixels, and the settings it renders with (box filter 1.5).

    Most of its pixels are lit floor that converges fast; the error sits in the penumbrae, so
    bench/ shows with it whether adaptive sampling moves samples there with its default settings.
    """
    height = width * 3 // 4
    mats = [Material("floor", [Closure("DIFFUSE", color=(0.6, 0.6, 0.6))]),
            Material("sphere", [Closure("DIFFUSE", color=(0.7, 0.3, 0.2))]),
            Material("cube", [Closure("DIFFUSE", color=(0.2, 0.4, 0.7))])]
    meshes = [plane(20.0), uv_sphere(0.8, (-0.9, 0.0, 0.8), material=1), cube(np.array([1.1, 0.4, 0.6]), 0.6, 2)]
    half = 0.45
    camera = Camera(look_at((0.0, -6.0, 4.0), (0.0, 0.3, 0.4))[None], (-half, half, -half * height / width,
                                                                      half * height / width), (width, height))
    light_matrix = translation(0.5, -0.5, 4.0)
    light = Light("AREA", light_matrix, radiance=np.full(3, 15.0), shape="RECTANGLE", size_x=2.0, size_y=1.0)
    scene = SceneData(camera, meshes, [Instance(i, np.eye(4)) for i in range(len(meshes))], mats, [light])
    scene.world.radiance = np.full(3, 0.02)
    return scene, dict(max_depth=8, filter_type="BLACKMAN_HARRIS", filter_size=1.5, threads=0)


def defocused_checker_scene(width=64):
    """A checkerboard floor of light and dark diffuse tiles under a white world, seen far out of focus
    (thin lens: the plane in focus 2 m away, the floor about 5 m) at ``width`` x 3/4 width pixels, and
    the settings it renders with. Every pixel averages tiles of both shades through the lens, so its
    Denoising Albedo is as noisy as its colour and correlated with it: the depth-of-field case (the
    sample scene dof_row) where an estimate of the denoised error from halves that share their
    features reads far too low (core.render.denoise)."""
    tile, size = 0.25, 8.0
    k = int(round(size / tile))
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) * tile
    origins = [np.array([-size / 2 + i * tile, -size / 2 + j * tile, 0.0]) for i in range(k) for j in range(k)]
    vertices = np.concatenate([corners + o for o in origins])
    tris = [t for q in range(k * k) for t in ([4 * q, 4 * q + 1, 4 * q + 2], [4 * q, 4 * q + 2, 4 * q + 3])]
    shades = [(i + j) % 2 for i in range(k) for j in range(k) for _ in range(2)]
    mats = [Material("light", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8))]),
            Material("dark", [Closure("DIFFUSE", color=(0.2, 0.2, 0.2))])]
    height, half = width * 3 // 4, 0.45
    camera = Camera(look_at((0.0, -4.0, 3.0), (0.0, 0.0, 0.0))[None], (-half, half, -half * height / width,
                                                                       half * height / width), (width, height),
                    aperture_radius=0.15, focus_distance=2.0)
    scene = SceneData(camera, [Mesh("checker", vertices, tris, shades)], [Instance(0, np.eye(4))], mats, [])
    scene.world.radiance = np.full(3, 1.0)
    return scene, dict(max_depth=4, filter_type="BLACKMAN_HARRIS", filter_size=1.5, threads=0)


def render_passes(data, passes, **settings):
    """The passes of ``data`` rendered with 8 samples on one thread to depth 4, unless ``settings`` say
    otherwise."""
    s = RenderSettings(**{"samples": 8, "threads": 1, "max_depth": 4, "passes": passes, **settings})
    return Renderer(data, s).render().passes
