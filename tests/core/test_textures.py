"""Image textures on surfaces: exact texels, colour spaces, footprint filtering, normals."""
import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, Program, SceneData, TextureImage
from drt_engine.core.settings import RenderSettings
from drt_engine.core.shading.textures import MAGENTA, Texture, srgb_to_linear
from tests.support.scenes import look_at, uv_sphere
from tests.support.textured_scenes import (constant_world_scene, diffuse_textured, image_program, ortho_top, uv_plane,
                             write_image)

RES = 16
TEXELS = 4  # image is TEXELS x TEXELS, each texel RES / TEXELS pixels wide


def render(scene, samples=4, seed=0, **kw):
    result = Renderer(scene, RenderSettings(samples=samples, seed=seed, threads=1, **kw)).render()
    return result.passes["Combined"][..., :3].astype(np.float64), result


def srgb_encode(linear):
    """The inverse transfer (the Standard view transform)."""
    c = np.clip(linear, 0, 1)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)


@pytest.fixture(scope="module")
def texel_bytes():
    rng = np.random.default_rng(7)
    return rng.integers(0, 256, (TEXELS, TEXELS, 3), dtype=np.uint8)  # top row first, as in the file


def textured_plane_render(path_or_pixels, colorspace, interpolation="Closest"):
    image = (TextureImage("img", path=path_or_pixels, colorspace=colorspace) if isinstance(path_or_pixels, str)
             else TextureImage("img", pixels=path_or_pixels, colorspace=colorspace))
    prog, ref = image_program(interpolation=interpolation)
    scene = constant_world_scene(uv_plane(), diffuse_textured(prog, ref), ortho_top(RES), images=[image])
    return render(scene)[0]


def interior(img):
    """One pixel per texel, at the texel's centre (two pixels from each edge, beyond the filter)."""
    k = RES // TEXELS
    return img[k // 2::k, k // 2::k]


def test_textured_plane_reproduces_image_pixels(tmp_path, texel_bytes):
    """A diffuse plane under a uniform white world reflects its albedo exactly: the rendered
    texel centres, through the sRGB view transform, are the file's 8-bit values within 1/255."""
    path = write_image(tmp_path / "texels.png", texel_bytes)
    img = textured_plane_render(path, "sRGB")
    expected_linear = srgb_to_linear(texel_bytes[::-1] / 255.0)  # rendered rows count from the bottom
    got = interior(img)
    assert np.abs(got - expected_linear).max() < 1e-6
    assert np.abs(srgb_encode(got) * 255.0 - texel_bytes[::-1]).max() <= 1.0


def test_srgb_and_non_color_differ_by_the_transfer_function(tmp_path, texel_bytes):
    path = write_image(tmp_path / "texels.png", texel_bytes)
    srgb = interior(textured_plane_render(path, "sRGB"))
    data = interior(textured_plane_render(path, "Non-Color"))
    assert np.abs(data - texel_bytes[::-1] / 255.0).max() < 1e-6
    assert np.abs(srgb - srgb_to_linear(data)).max() < 1e-6
    assert np.abs(srgb - data).max() > 0.1


def test_missing_image_is_magenta_with_one_warning(tmp_path):
    img = textured_plane_render(str(tmp_path / "nowhere.png"), "sRGB")
    assert np.allclose(img[2:-2, 2:-2], MAGENTA[:3], atol=1e-6)  # the border also sees the world
    prog, ref = image_program()
    scene = constant_world_scene(uv_plane(), diffuse_textured(prog, ref), ortho_top(RES),
                                 images=[TextureImage("lost", path=str(tmp_path / "nowhere.png"))])
    _, result = render(scene, samples=1)
    assert sum("lost" in w for w in result.warnings) == 1


def test_extension_modes():
    pixels = np.array([[[0.0, 0, 0, 1], [1.0, 1, 1, 1]]], np.float32)  # 2 x 1, black then white
    tex = Texture(TextureImage("t", pixels=pixels, colorspace="Non-Color"))
    uv = np.array([[1.25, 0.5], [-0.25, 0.5]])
    rep = tex.lookup(uv, None, "REPEAT", "Closest")[:, 0]
    ext = tex.lookup(uv, None, "EXTEND", "Closest")[:, 0]
    clip = tex.lookup(uv, None, "CLIP", "Closest")
    mirror = tex.lookup(uv, None, "MIRROR", "Closest")[:, 0]
    assert list(rep) == [0.0, 1.0] and list(ext) == [1.0, 0.0] and list(mirror) == [1.0, 0.0]
    assert np.all(clip == 0.0)


def _bilinear_in_numpy(tex, level, uv, extension):
    """The bilinear lookup as NumPy computes it, over all points at once: the compiled kernels'
    yardstick (their texel indices too)."""
    def index(i, n):
        if extension == "REPEAT":
            return np.mod(i, n)
        if extension == "MIRROR":
            period = np.mod(i, 2 * n)
            return np.where(period < n, period, 2 * n - 1 - period)
        return np.clip(i, 0, n - 1)

    img = tex.levels[level]
    h, w = img.shape[:2]
    x, y = uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    with np.errstate(invalid="ignore"):
        x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    xa, xb, ya, yb = index(x0, w), index(x0 + 1, w), index(y0, h), index(y0 + 1, h)
    top = img[ya, xa] * (1 - fx) + img[ya, xb] * fx
    bottom = img[yb, xa] * (1 - fx) + img[yb, xb] * fx
    return top * (1 - fy) + bottom * fy


@pytest.mark.parametrize("extension", ["REPEAT", "EXTEND", "CLIP", "MIRROR"])
def test_bilinear_lookups_are_numpys_bit_for_bit_and_stay_inside_the_image(extension):
    """The compiled bilinear taps give NumPy's values exactly, across the image's edges and at
    coordinates no sane uv has (NaN, inf, past int64's range: a texel read, never memory past the
    image), on an odd-sized image and on its mip levels."""
    rng = np.random.default_rng(2)
    tex = Texture(TextureImage("t", pixels=rng.random((37, 53, 4)).astype(np.float32), colorspace="Non-Color"))
    uv = rng.random((4000, 2)) * 5 - 2
    uv[:8] = [[np.nan, 0.5], [0.5, np.inf], [-np.inf, 0.1], [1e300, 0.5], [-1e300, 0.3], [0.5, 1e19],
              [0.3, -5e18], [1.0, 1.0]]
    for level in range(len(tex.levels)):
        ours = tex._bilinear(level, uv, extension)
        with np.errstate(invalid="ignore"):
            assert np.array_equal(ours, _bilinear_in_numpy(tex, level, uv, extension), equal_nan=True), level
        assert np.isfinite(ours[3:]).all() and np.isnan(ours[:3]).all()


def checker_pixels(n=256, square=2):
    i = np.arange(n) // square
    c = ((i[:, None] + i[None, :]) % 2).astype(np.float32)
    return np.repeat(c[:, :, None], 4, axis=2) * np.array([1, 1, 1, 0], np.float32) + np.array([0, 0, 0, 1])


def horizon_error(interpolation, seed):
    """RMS error against the checker's mean (0.5) over the far half of a receding textured plane."""
    image = TextureImage("checker", pixels=checker_pixels(), colorspace="Non-Color")
    prog, ref = image_program(interpolation=interpolation)
    mesh = uv_plane(half=200.0, uv_scale=200.0)
    cam_m = look_at((0, 0, 0.5), (0, 60, 0))
    camera = Camera(cam_m[None], (-0.5, 0.5, -0.25, 0.25), (48, 24))
    scene = constant_world_scene(mesh, diffuse_textured(prog, ref), camera, images=[image])
    img, _ = render(scene, samples=8, seed=seed)
    far = img[6:11].mean(axis=2)  # rows below the horizon (row 12): hundreds of squares per pixel
    return np.sqrt(np.mean((far - 0.5) ** 2))


def test_footprint_filtering_converges_far_checker_to_its_mean():
    """At equal samples the filtered lookups' far region is within half the unfiltered error."""
    filtered = np.mean([horizon_error("Linear", s) for s in (0, 1)])
    unfiltered = np.mean([horizon_error("Closest", s) for s in (0, 1)])
    assert unfiltered > 0.05  # the region aliases without filtering
    assert filtered < 0.5 * unfiltered, (filtered, unfiltered)


def lit_sphere(material, samples=16):
    sphere = uv_sphere(radius=1.0, segments=32, rings=16)
    tris = sphere.triangles
    p = sphere.vertices[tris]
    uv = np.stack([np.arctan2(p[..., 1], p[..., 0]) / (2 * np.pi) + 0.5, p[..., 2] * 0.5 + 0.5], axis=-1)
    sphere.uvs = uv.astype(np.float32)
    camera = Camera(look_at((0, -4, 1), (0, 0, 0))[None], (-0.4, 0.4, -0.4, 0.4), (16, 16))
    sun = Light("SUN", look_at((1, -1, 2), (0, 0, 0)), irradiance=np.full(3, 3.0), angle=0.1)
    scene = SceneData(camera=camera, meshes=[sphere], instances=[Instance(0, np.eye(4))], materials=[material],
                      lights=[sun], images=[TextureImage("flat", pixels=np.tile([0.5, 0.5, 1.0, 1.0], (4, 4, 1)),
                                                         colorspace="Non-Color")])
    return render(scene, samples=samples)[0]


def normal_program(kind):
    prog = Program()
    if kind == "normal_map":
        uv = prog.add("coord", name="uv")
        img = prog.add("image", [(uv, 0)], image=0)
        strength = prog.add("const", value=1.0)
        out = prog.add("normal_map", [(strength, 0), (img, 0)], map="")
    else:
        height = prog.add("const", value=0.3)
        one = prog.add("const", value=1.0)
        out = prog.add("bump", [(one, 0), (one, 0), (height, 0), None, (one, 0)])
    return prog, (out, 0)


@pytest.mark.parametrize("kind", ["normal_map", "bump"])
def test_flat_normal_map_and_constant_bump_change_nothing(kind):
    plain = lit_sphere(Material("plain", [Closure("PRINCIPLED", color=(0.6, 0.5, 0.4), roughness=0.4)]))
    prog, ref = normal_program(kind)
    bumped = Material("bumped", [Closure("PRINCIPLED", color=(0.6, 0.5, 0.4), roughness=0.4,
                                         inputs={"normal": ref})], prog)
    assert np.abs(lit_sphere(bumped) - plain).max() < 1e-9


def test_bump_slope_tilts_the_normal_by_its_gradient():
    """Height s * x (object X) tilts a plane's normal to (-s, 0, 1)/|.|: under a sun from straight
    above, a white diffuse plane's radiance drops from E/pi by the cosine 1/sqrt(1 + s^2)."""
    s = 0.75
    prog = Program()
    obj = prog.add("coord", name="object")
    x = prog.add("separate", [(obj, 0)], mode="RGB")
    slope = prog.add("const", value=s)
    zero = prog.add("const", value=0.0)
    height = prog.add("math", [(x, 0), (slope, 0), (zero, 0)], operation="MULTIPLY")
    one = prog.add("const", value=1.0)
    bump = prog.add("bump", [(one, 0), (one, 0), (height, 0), None, (one, 0)])
    mat = Material("slope", [Closure("DIFFUSE", color=(1, 1, 1), roughness=0.0, inputs={"normal": (bump, 0)})],
                   prog)
    scene = SceneData(camera=ortho_top(8, half=0.5), meshes=[uv_plane()], instances=[Instance(0, np.eye(4))],
                      materials=[mat], lights=[Light("SUN", np.eye(4), irradiance=np.full(3, 2.0))])
    img, _ = render(scene)
    assert np.allclose(img, 2.0 / np.pi / np.sqrt(1 + s * s), rtol=1e-6)


def emitter_scene(textured):
    """A floor under a 1 x 1 emitting square 1 m above it, seen from below the square's edge."""
    checker = checker_pixels(256, 2) * np.array([2, 2, 2, 1], np.float32)
    image = TextureImage("checker", pixels=checker, colorspace="Non-Color")
    prog, ref = image_program(interpolation="Closest")
    closure = Closure("EMISSION", color=(1, 1, 1), emission=(1.0, 1.0, 1.0), inputs={"emission": ref} if textured else {})
    emitter = Material("glow", [closure], prog if textured else None)
    floor = Material("floor", [Closure("DIFFUSE", color=(1, 1, 1), roughness=0.0)])
    lamp = uv_plane(half=0.5, z=1.0)
    lamp.material_indices[:] = 1
    lamp.triangles = lamp.triangles[:, ::-1].copy()  # face down
    lamp.uvs = lamp.uvs[:, ::-1].copy()
    ground = uv_plane(half=5.0)
    camera = Camera(look_at((0, -3, 0.5), (0, 0, 0.5))[None], (-0.5, 0.5, -0.5, 0.5), (24, 24))
    return SceneData(camera=camera, meshes=[ground, lamp], instances=[Instance(0, np.eye(4)), Instance(1, np.eye(4))],
                     materials=[floor, emitter], images=[image])


def test_textured_emission_lights_like_its_mean_and_is_seen_per_texel():
    """A fine 0/2 checker emitter lights the floor as a uniform emitter of its mean (1) does
    (light sampling evaluates the texture at the sampled point), and the camera sees its texels."""
    textured, _ = render(emitter_scene(True), samples=256)
    uniform, _ = render(emitter_scene(False), samples=256)
    floor = slice(0, 8)  # rows of floor below the lamp (measured: 2.9% apart at 64 samples, 0.7% at 256)
    assert abs(textured[floor].mean() / uniform[floor].mean() - 1) < 0.02
    prog, ref = image_program(interpolation="Closest")
    glow = Material("glow", [Closure("EMISSION", emission=(1, 1, 1), inputs={"emission": ref})], prog)
    image = TextureImage("noise", pixels=np.random.default_rng(1).random((TEXELS, TEXELS, 4)), colorspace="Non-Color")
    seen, _ = render(constant_world_scene(uv_plane(), glow, ortho_top(RES), radiance=0.0, images=[image]))
    assert np.abs(interior(seen) - image.pixels[..., :3]).max() < 1e-6


def test_cubic_is_cycles_b_spline():
    """Cubic (and Smart) read the image as Cycles' cubic B-spline: its weights, constants and
    linear ramps reproduced, a texel spread over its neighbours, and Clip fading out past the edge."""
    from drt_engine.core.shading.textures import bspline_weights
    w = bspline_weights(np.array([0.0, 0.3, 1.0]))
    assert np.allclose(w.sum(axis=1), 1) and np.allclose(w[0], [1 / 6, 2 / 3, 1 / 6, 0]) and np.allclose(w[2, 1:], w[0, :3])
    ramp = np.repeat(np.arange(8, dtype=np.float32)[None, :, None], 8, axis=0).repeat(4, axis=2)
    tex = Texture(TextureImage("ramp", pixels=ramp, colorspace="Non-Color"))
    uv = np.array([[0.4, 0.5], [0.55, 0.2]])
    assert np.allclose(tex.lookup(uv, None, "EXTEND", "Cubic")[:, 0], uv[:, 0] * 8 - 0.5)  # linear in, linear out
    spike = np.zeros((8, 8, 4), np.float32)
    spike[4, 4] = 1.0
    tex = Texture(TextureImage("spike", pixels=spike, colorspace="Non-Color"))
    centre = np.array([[4.5 / 8, 4.5 / 8]])
    assert np.isclose(tex.lookup(centre, None, "REPEAT", "Smart")[0, 0], (2 / 3) ** 2)
    assert np.isclose(tex.lookup(centre + [1 / 8, 0], None, "REPEAT", "Cubic")[0, 0], 2 / 3 / 6)
    edge = Texture(TextureImage("white", pixels=np.ones((8, 8, 4), np.float32), colorspace="Non-Color"))
    past = edge.lookup(np.array([[1.0 + 0.5 / 8, 0.5], [1.5, 0.5]]), None, "CLIP", "Cubic")[:, 0]
    assert np.allclose(past, [1 / 6, 0.0])  # half a texel past the edge: only the last column's 1/6 left
