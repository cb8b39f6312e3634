"""SceneData: the plain-data contract between the Blender export and the tracer.

Everything here is NumPy arrays and small dataclasses, nothing of Blender. A scene
written by hand in a test is as good as one exported from Blender. Units follow
Blender and Cycles; the export converts Blender's light units into the radiometric
quantities documented on each field, so the core never needs Blender's conventions.

Coordinates: right-handed, Z up, metres (scene units at unit scale 1), float64.
Matrices are 4x4 float64 mapping object space to world space (column vectors).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _vec3(value) -> np.ndarray:
    return np.asarray(value, dtype=np.float64).reshape(3)


@dataclass
class Closure:
    """One shader closure with its mixing weight.

    ``kind`` is one of ``CLOSURE_KINDS``. Fields a kind does not use are ignored.
    Principled follows Cycles' layering: coat over (metal | glass | specular over diffuse).
    """

    kind: str
    weight: np.ndarray = field(default_factory=lambda: np.ones(3))
    color: np.ndarray = field(default_factory=lambda: np.full(3, 0.8))
    roughness: float = 0.5
    metallic: float = 0.0
    ior: float = 1.5
    specular_ior_level: float = 0.5
    specular_tint: np.ndarray = field(default_factory=lambda: np.ones(3))
    transmission: float = 0.0
    coat_weight: float = 0.0
    coat_roughness: float = 0.03
    coat_ior: float = 1.5
    coat_tint: np.ndarray = field(default_factory=lambda: np.ones(3))
    sheen_weight: float = 0.0
    """Principled's Sheen Weight: a microfiber sheen layered over the coat and the rest (as Cycles)."""
    sheen_roughness: float = 0.5
    sheen_tint: np.ndarray = field(default_factory=lambda: np.ones(3))
    diffuse_roughness: float = 0.0
    """DIFFUSE's and Principled's diffuse: Lambert, or from 1e-5 up Oren-Nayar of this sigma (Cycles')."""
    emission: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Emitted radiance, W/(m² sr) per channel: emission colour times strength."""
    multiscatter: bool = True
    """GGX lobes get Cycles' multiple-scattering energy compensation ("Multiscatter GGX")."""
    anisotropy: float = 0.0
    """The node's own anisotropy: Principled's Anisotropic (0 to 1, also the Metallic BSDF's), or
    GLOSSY's Anisotropy (-1 to 1); each maps to alpha_x, alpha_y as Cycles' svm_node_closure_bsdf
    (core.bsdf.shader.anisotropic_alphas), along the hits' tangent (input "tangent")."""
    anisotropic_rotation: float = 0.0
    """Turns of the tangent about the normal."""
    toon_size: float = 0.5
    """DIFFUSE_TOON / GLOSSY_TOON: the Toon BSDF's Size, the cone of full intensity (0 to 1: 0 to 90 degrees)."""
    toon_smooth: float = 0.0
    """The Toon BSDF's Smooth, the angle past Size over which the intensity falls to 0 (0 to 1: 0 to 90 degrees)."""
    thin_film_thickness: float = 0.0
    """PRINCIPLED: thickness (nm) of a thin film over the specular layer, glass and (with
    ``thin_film_metal``) metal, as Cycles' fresnel_iridescence (core.bsdf.thin_film); up to 0.1, none."""
    thin_film_ior: float = 1.33
    """The thin film's IOR."""
    thin_film_metal: bool = True
    """The film covers the metal lobe too (Cycles 5.0 on; 4.x leaves metal bare)."""
    hair_roughness_v: float = 1.0
    """HAIR_*: the Hair BSDF's RoughnessV (across the strand; ``roughness`` is RoughnessU)."""
    hair_offset: float = 0.0
    """HAIR_*: the Hair BSDF's Offset; PRINCIPLED_HAIR: its Offset (the scales' tilt), radians."""
    hair_model: str = "CHIANG"
    """PRINCIPLED_HAIR: "CHIANG" or "HUANG"."""
    hair_parametrization: str = "COLOR"
    """PRINCIPLED_HAIR: "COLOR" (``color`` as reflectance), "MELANIN" or "ABSORPTION"."""
    melanin: float = 0.8
    melanin_redness: float = 1.0
    hair_tint: np.ndarray = field(default_factory=lambda: np.ones(3))
    absorption: np.ndarray = field(default_factory=lambda: np.array([0.245531, 0.52, 1.365]))
    radial_roughness: float = 0.3
    hair_coat: float = 0.0
    random_color: float = 0.0
    random_roughness: float = 0.0
    hair_random: float = 0.0
    """PRINCIPLED_HAIR: the node's Random (a mesh has no per-strand random, so Cycles reads the socket)."""
    aspect_ratio: float = 0.85
    hair_gains: np.ndarray = field(default_factory=lambda: np.ones(3))
    """PRINCIPLED_HAIR, Huang: the Reflection, Transmission and Secondary Reflection gains."""
    inputs: dict = field(default_factory=dict)
    """Inputs that vary over the surface: field name ("weight", "color", "roughness",
    "metallic", "ior", "transmission", "emission", "normal", "coat_normal", ...) -> output ``(node, socket)``
    of the material's ``program``; they replace the constant field per hit."""

    def __post_init__(self):
        if self.kind not in CLOSURE_KINDS:
            raise ValueError(f"unknown closure kind {self.kind!r}")
        for name in ("weight", "color", "specular_tint", "coat_tint", "sheen_tint", "emission", "hair_tint",
                     "absorption", "hair_gains"):
            setattr(self, name, _vec3(getattr(self, name)))


CLOSURE_KINDS = (
    "PRINCIPLED",  # full Principled BSDF
    "DIFFUSE",  # Lambert (Oren-Nayar with ``diffuse_roughness``), colour = albedo
    "TRANSLUCENT",  # Lambert on the side opposite the normal, colour = albedo
    "SHEEN",  # Cycles' microfiber sheen (Zeltner et al. 2022) of ``roughness``, tinted by colour
    "GLOSSY",  # GGX reflection tinted by colour, no Fresnel (Blender's Glossy BSDF)
    "GLASS",  # smooth or rough dielectric, reflection + refraction tinted by colour
    "REFRACTION",  # refraction only, tinted by colour
    "EMISSION",  # emitted radiance ``emission``, two-sided
    "TRANSPARENT",  # straight through, tinted by colour
    "HOLDOUT",  # no light: where the camera sees it, that share of the pixel is transparent (Cycles' holdout)
    "DIFFUSE_TOON",  # Cycles' diffuse toon: a cone about the normal, colour = weight
    "GLOSSY_TOON",  # Cycles' glossy toon: a cone about the mirror direction, colour = weight
    "HAIR_REFLECTION",  # the Hair BSDF's Reflection component about the strand, colour = weight
    "HAIR_TRANSMISSION",  # its Transmission component
    "PRINCIPLED_HAIR",  # the Principled Hair BSDF (``hair_model``), colour through its parametrization
)


@dataclass
class Material:
    """A weighted sum of closures (Mix and Add Shader flattened by the export).

    Principled alpha is expressed as a mix with a TRANSPARENT closure.
    """

    name: str
    closures: list[Closure]
    program: Program | None = None
    """The shader nodes feeding the closures' varying ``inputs``."""
    displacement: tuple | None = None
    """The shading normal bumped by the output's Displacement socket (Cycles' "Bump Only"): an
    output ``(node, socket)`` of ``program``, evaluated before the closures' inputs, which then
    see it as the hit's normal."""
    pass_index: int = 0
    """The material's pass index (Material Index pass)."""
    aovs: list = field(default_factory=list)
    """What its AOV Output nodes write into the render's shader AOVs (core.integrator.aovs): (AOV
    name, value), the value RGB (3,) for a colour AOV, a float for a value AOV, or an output
    ``(node, socket)`` of ``program``."""
    transparent_shadow: bool = True
    """Shadow rays may pass it where it is transparent (Blender's Transparent Shadows, read by
    Cycles): off, its surfaces block them."""
    bump_shadowing: str = "GGX"
    """How a bumped normal shadows the light the smooth normal sees at grazing angles
    (core.bsdf.bump_shadowing): "GGX" as Cycles 5, "CHIANG" as Cycles 4.2."""
    bump_correction: bool = True
    """Its Bump Map Correction (Cycles' material setting): off, no smoothing at the terminator."""

    @property
    def emission(self) -> np.ndarray:
        """Total emitted radiance of the material where it is constant (varying emission
        and weights count with their constant fallback)."""
        total = np.zeros(3)
        for c in self.closures:
            if c.kind in ("EMISSION", "PRINCIPLED"):
                total += c.weight * c.emission
        return total


@dataclass
class ProgramNode:
    """One operation of a shader program: ``op`` (the cases of core.shading.nodes.Evaluator._run), its inputs as
    ``(node, output)`` references to earlier nodes, and constant parameters."""

    op: str
    inputs: tuple = ()
    params: dict = field(default_factory=dict)


@dataclass
class Program:
    """Shader nodes compiled to a list in evaluation order (inputs refer to earlier nodes)."""

    nodes: list[ProgramNode] = field(default_factory=list)

    def add(self, op: str, inputs=(), **params) -> int:
        self.nodes.append(ProgramNode(op, tuple(inputs), params))
        return len(self.nodes) - 1


@dataclass
class TextureImage:
    """An image for texture lookups: a file OpenImageIO reads, or pixels (H, W, C) bottom row
    first. ``colorspace``: "sRGB" (linearised on load) or "Non-Color" (used as is; also
    right for linear float images)."""

    name: str
    path: str | None = None
    pixels: np.ndarray | None = None
    colorspace: str = "sRGB"


DEFAULT_MATERIAL = Material("Default", [Closure("PRINCIPLED", color=(0.8, 0.8, 0.8))])
"""Blender's default surface for objects without a material."""


@dataclass
class Mesh:
    """A triangle mesh in its object space.

    ``corner_normals`` (T, 3, 3) hold the shading normal of each triangle corner in
    object space (smooth, flat or custom split normals alike); ``None`` means flat.
    ``material_indices`` (T,) index ``SceneData.materials``. ``uvs`` (T, 3, 2) or None.
    ``motion_vertices`` (S, V, 3): object-space vertices at S evenly spaced shutter times
    for a mesh that deforms (same topology throughout), else None. ``motion_pass_vertices``
    (2, V, 3): for the Vector pass, its object-space vertices at the previous and the next frame
    when they move (None: they stand still, or the pass is off).
    ``attributes``: per-corner data by name, (T, 3, 2) for UV maps, (T, 3, 4) for colour
    attributes, (T, 3, 1 to 4) for other attributes (a float, a 2D or 3D vector, a colour, a
    quaternion); ``uvs`` is the default (active render) UV map and ``colors`` the default
    colour attribute. ``texspace`` (location, size) maps object space to generated
    coordinates ((p - location + size) / (2 size)); None: the vertices' bounds.
    """

    name: str
    vertices: np.ndarray
    triangles: np.ndarray
    material_indices: np.ndarray
    corner_normals: np.ndarray | None = None
    uvs: np.ndarray | None = None
    motion_vertices: np.ndarray | None = None
    motion_pass_vertices: np.ndarray | None = None
    attributes: dict = field(default_factory=dict)
    colors: np.ndarray | None = None
    texspace: tuple | None = None

    def __post_init__(self):
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        if self.motion_vertices is not None:
            self.motion_vertices = np.asarray(self.motion_vertices, dtype=np.float64).reshape(-1, len(self.vertices), 3)
        if self.motion_pass_vertices is not None:
            self.motion_pass_vertices = np.asarray(self.motion_pass_vertices, np.float64).reshape(
                2, len(self.vertices), 3)
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.int32).reshape(-1, 3)
        self.material_indices = np.ascontiguousarray(self.material_indices, dtype=np.int32).reshape(-1)
        if self.material_indices.size == 1 and len(self.triangles) != 1:
            self.material_indices = np.full(len(self.triangles), self.material_indices[0], np.int32)
        if len(self.material_indices) != len(self.triangles):
            raise ValueError(f"mesh {self.name!r}: one material index per triangle expected")
        if self.corner_normals is not None:
            self.corner_normals = np.asarray(self.corner_normals, dtype=np.float32).reshape(-1, 3, 3)
        if self.uvs is not None:
            self.uvs = np.asarray(self.uvs, dtype=np.float32).reshape(-1, 3, 2)
        if self.colors is not None:
            self.colors = np.asarray(self.colors, dtype=np.float32).reshape(-1, 3, 4)
        self.attributes = {k: np.asarray(v, dtype=np.float32).reshape(len(self.triangles), 3, -1)
                           for k, v in self.attributes.items()}


LIGHT_SETS_ALL = (1 << 64) - 1
"""An emitter's light-set membership when it lights every object (no light linking)."""


@dataclass
class Instance:
    """One placement of a mesh: ``mesh`` indexes ``SceneData.meshes``.

    ``matrices`` (S, 4, 4) are object-to-world transforms at S evenly spaced times over
    the shutter interval; S == 1 for an object that does not move.
    """

    mesh: int
    matrices: np.ndarray
    name: str = ""
    attributes: dict = field(default_factory=dict)
    """Object and Instancer attributes its materials read (Attribute node): key -> RGBA (4,)."""
    color: np.ndarray = field(default_factory=lambda: np.ones(4))
    """The object's colour and alpha (Object Info)."""
    pass_index: int = 0
    random: float = 0.0
    """Object Info's Random: Cycles' per-object (or per-instance) random number in [0, 1]."""
    holdout: bool = False
    """The whole object is a holdout where the camera sees it (Cycles' object holdout); other
    rays see it as it is."""
    shadow_catcher: bool = False
    """Cycles' Shadow Catcher: where the camera sees it, its path splits into one through the whole
    scene and one through the catchers alone (core.integrator.shadow_catcher)."""
    visible_camera: bool = True
    visible_shadow: bool = True
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    """Blender's ray visibility: the ray kinds that see the object (the others pass through it, and
    an emissive object lights only the BSDF parts of the kinds that see it, as in Cycles)."""
    lightgroup: int = -1
    """The light group its emission counts to (an index into ``SceneData.light_groups``; -1: none)."""
    asset: str = ""
    """The name of its object's top-level parent, Cryptomatte's asset (empty: the object has none, its own
    name)."""
    motion_pass: np.ndarray | None = None
    """For the Vector pass: object-to-world (2, 4, 4) at the previous and the next frame (None: it
    stands still there, or the pass is off)."""
    receiver_light_set: int = 0
    light_set_membership: int = LIGHT_SETS_ALL
    """Light linking (core.lights.linking): the receiver set the object is in (0: the default) and,
    for its emission, the sets it lights."""
    blocker_shadow_set: int = 0
    shadow_set_membership: int = LIGHT_SETS_ALL
    """Shadow linking, alike: the blocker set the object is in and, for its emission, the blocker
    sets that cast its shadows."""

    def __post_init__(self):
        self.color = np.asarray(self.color, dtype=np.float64).reshape(4)
        self.matrices = np.asarray(self.matrices, dtype=np.float64).reshape(-1, 4, 4)
        if self.motion_pass is not None:
            self.motion_pass = np.asarray(self.motion_pass, dtype=np.float64).reshape(2, 4, 4)

    @property
    def matrix(self) -> np.ndarray:
        """Transform at the shutter's centre step (the static transform)."""
        return self.matrices[len(self.matrices) // 2]


LIGHT_KINDS = ("POINT", "SPOT", "SUN", "AREA")
AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")


@dataclass
class Light:
    """A light in radiometric units (the export has applied Cycles' conversions).

    Orientation comes from ``matrix`` (light space to world, scale removed): lights
    shine along local -Z, area lights span local X (``size_x``) and Y (``size_y``).

    - POINT, SPOT: ``intensity`` is radiant intensity (W/sr) of the whole light;
      with ``radius`` > 0 it is a sphere (or, with ``soft_falloff``, a disk facing the
      shaded point, as Cycles does) of radiance intensity / (π radius²).
      SPOT adds ``spot_size`` (full cone angle, radians) and ``spot_blend``.
    - SUN: ``irradiance`` (W/m² on a facing surface), ``angle`` (full angular diameter).
    - AREA: ``radiance`` (W/(m² sr)), one-sided along -Z, with ``shape``, extents
      ``size_x`` and ``size_y`` along local X and Y in world units (both used for every
      shape, so a scaled square is a rectangle) and ``spread`` (radians, π = none).
    """

    kind: str
    matrix: np.ndarray
    intensity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    irradiance: np.ndarray = field(default_factory=lambda: np.zeros(3))
    radiance: np.ndarray = field(default_factory=lambda: np.zeros(3))
    radius: float = 0.0
    soft_falloff: bool = True
    spot_size: float = np.pi / 4
    spot_blend: float = 0.15
    angle: float = 0.0
    shape: str = "SQUARE"
    size_x: float = 1.0
    size_y: float = 1.0
    spread: float = np.pi
    visible_camera: bool = False
    """Seen by camera rays (Blender's ray visibility; off for lights by default)."""
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    """Which BSDF parts the light lights and which rays that left them see it (as the world's)."""
    cast_shadow: bool = True
    """Cycles' Cast Shadow: off, nothing blocks the light's shadow rays."""
    matrices: np.ndarray | None = None
    """(S, 4, 4) light-to-world transforms at S evenly spaced shutter times for a light
    that moves (scale removed, like ``matrix``), else None."""
    name: str = ""
    lightgroup: int = -1
    """The light group its light counts to (an index into ``SceneData.light_groups``; -1: none)."""
    light_set_membership: int = LIGHT_SETS_ALL
    """Light linking: the objects' receiver sets it lights (bit s: set s; core.lights.linking)."""
    shadow_set_membership: int = LIGHT_SETS_ALL
    """Shadow linking: the objects' blocker sets that cast its shadows."""
    program: Program | None = None
    emission: tuple | None = None
    """A node tree whose Emission colour or strength varies (an IES Texture, Light Falloff): the
    program's ``emission`` output (colour x strength, (N, 3)) scales the light's radiance at each
    sample and hit, in the coordinates Cycles gives a light's shader (core.lights.programs)."""
    object_scale: tuple = (1.0, 1.0, 1.0)
    """The lengths of the light object's axes, which ``matrix`` leaves out: its program's Normal and
    Object coordinates are in the object's space, scale included, as Cycles transforms them."""

    def __post_init__(self):
        if self.kind not in LIGHT_KINDS:
            raise ValueError(f"unknown light kind {self.kind!r}")
        if self.shape not in AREA_SHAPES:
            raise ValueError(f"unknown area light shape {self.shape!r}")
        self.matrix = np.asarray(self.matrix, dtype=np.float64).reshape(4, 4)
        if self.matrices is not None:
            self.matrices = np.asarray(self.matrices, dtype=np.float64).reshape(-1, 4, 4)
        for name in ("intensity", "irradiance", "radiance"):
            setattr(self, name, _vec3(getattr(self, name)))

    @property
    def position(self) -> np.ndarray:
        return self.matrix[:3, 3].copy()

    @property
    def direction(self) -> np.ndarray:
        """Unit vector the light shines along (local -Z in world space)."""
        d = -self.matrix[:3, 2]
        return d / np.linalg.norm(d)


@dataclass
class World:
    """The environment seen by rays that escape: ``radiance`` (colour times strength), or,
    with a ``program``, the radiance its output ``color`` gives per direction (the program's
    "generated" and "object" inputs are the world-space ray direction).

    Blender's world ray visibility: ``visible_camera`` (seen by camera rays),
    ``visible_diffuse`` (lights diffuse lobes), ``visible_glossy`` (lights and is seen by
    reflection), ``visible_transmission`` (lights and is seen through refraction)."""

    radiance: np.ndarray = field(default_factory=lambda: np.zeros(3))
    program: Program | None = None
    color: tuple | None = None
    visible_camera: bool = True
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    aovs: list = field(default_factory=list)
    """What its AOV Output nodes write where the camera sees it (core.integrator.aovs): (AOV name,
    constant), RGB (3,) for a colour AOV, a float for a value AOV."""
    mist_start: float = 0.0
    mist_depth: float = 100.0
    mist_falloff: float = 1.0
    """The world's mist settings as Cycles reads them: the Mist pass ramps from 0 at ``mist_start``
    to 1 at ``mist_start + mist_depth`` from the camera, raised to ``mist_falloff`` (quadratic 2,
    linear 1, inverse quadratic 0.5). The defaults are Cycles' film's, what it uses without a world."""
    lightgroup: int = -1
    """The light group its light counts to (an index into ``SceneData.light_groups``; -1: none)."""

    @property
    def visible_lighting(self) -> bool:
        return self.visible_diffuse or self.visible_glossy or self.visible_transmission

    def __post_init__(self):
        self.radiance = _vec3(self.radiance)


@dataclass
class Camera:
    """A pinhole, orthographic or panoramic camera looking along local -Z with Y up.

    ``frame`` = (left, right, bottom, top) of the image window in camera space on the
    plane z = -1 (perspective), in scene units (orthographic), or in the panorama's
    (u, v) coordinates, 0 to 1 over the unshifted image (panoramic); sensor fit, pixel
    aspect and shift are already folded into it. ``resolution`` is the full image in
    pixels after the resolution percentage; ``window`` = (x0, y0, x1, y1) is the pixel
    rectangle actually rendered (border render), rows counted from the bottom as in
    Blender. ``matrices`` (S, 4, 4) as for ``Instance``.
    """

    matrices: np.ndarray
    frame: tuple[float, float, float, float]
    resolution: tuple[int, int]
    type: str = "PERSP"
    clip_start: float = 0.1
    clip_end: float = 1000.0
    window: tuple[int, int, int, int] | None = None
    aperture_radius: float = 0.0
    focus_distance: float = 10.0
    """Distance of the plane in focus along the view axis (focus is planar, as in Cycles)."""
    blades: int = 0
    """Aperture polygon sides (0 or fewer than 3: a round aperture), rotated by ``blade_rotation``."""
    blade_rotation: float = 0.0
    aperture_ratio: float = 1.0
    """Anamorphic bokeh: the aperture's x extent is divided by this ratio."""
    panorama: str = "EQUIRECTANGULAR"
    """For type "PANO", one of ``PANORAMA_TYPES`` (Blender's ``panorama_type``)."""
    latitude: tuple[float, float] = (-np.pi / 2, np.pi / 2)
    """Equirectangular: latitudes (radians) at the bottom and top of the image."""
    longitude: tuple[float, float] = (-np.pi, np.pi)
    """Equirectangular: longitudes (radians) at the left and right of the image (0 ahead, positive to the right)."""
    fisheye_fov: float = np.pi
    """Fisheyes: the angle (radians) across the image circle."""
    fisheye_lens: float = 10.5
    """Fisheye equisolid: focal length, in the sensor's units (mm)."""
    sensor: tuple[float, float] = (36.0, 24.0)
    """Fisheye equisolid and lens polynomial: the sensor's width and height (mm) fitted to the image, as Cycles fits them."""
    fisheye_polynomial: tuple[float, float, float, float, float] = (0.0, 1.0, 0.0, 0.0, 0.0)
    """Fisheye lens polynomial: k0 to k4, the angle from the view axis (radians) of a sensor point at
    radius r (mm) being -(k0 + k1 r + k2 r^2 + k3 r^3 + k4 r^4)."""
    cylinder: tuple[float, float, float, float] = (-np.pi, np.pi, -1.0, 1.0)
    """Central cylindrical: longitudes (radians) at the image's left and right, heights on the unit
    cylinder (Blender's heights over its cylinder radius) at its bottom and top."""
    shutter_table: np.ndarray | None = None
    """Motion blur's shutter curve as Cycles' inverse-CDF table of shutter times (None: times uniform
    over the shutter, for a flat curve without a rolling shutter)."""
    rolling_shutter: float | None = None
    """Rolling shutter (rows read from the top down over the shutter): Cycles' rolling shutter
    duration, None when off."""
    motion_pass: np.ndarray | None = None
    """For the Vector pass: camera-to-world (2, 4, 4) at the previous and the next frame (None: it
    stands still there, or the pass is off)."""

    def __post_init__(self):
        self.matrices = np.asarray(self.matrices, dtype=np.float64).reshape(-1, 4, 4)
        if self.motion_pass is not None:
            self.motion_pass = np.asarray(self.motion_pass, dtype=np.float64).reshape(2, 4, 4)
        w, h = (int(v) for v in self.resolution)
        if w < 1 or h < 1:
            raise ValueError(f"camera resolution must be positive, got {w}x{h}")
        self.resolution = (w, h)
        if self.window is None:
            self.window = (0, 0, w, h)
        x0, y0, x1, y1 = (int(v) for v in self.window)
        if not (0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h):
            raise ValueError(f"render window {self.window} outside the image {w}x{h}")
        self.window = (x0, y0, x1, y1)
        if self.type not in ("PERSP", "ORTHO", "PANO"):
            raise ValueError(f"unknown camera type {self.type!r}")
        if self.type == "PANO" and self.panorama not in PANORAMA_TYPES:
            raise ValueError(f"unknown panorama type {self.panorama!r}")

    @property
    def matrix(self) -> np.ndarray:
        return self.matrices[len(self.matrices) // 2]

    @property
    def window_size(self) -> tuple[int, int]:
        x0, y0, x1, y1 = self.window
        return x1 - x0, y1 - y0


PANORAMA_TYPES = ("EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID", "MIRRORBALL",
                  "EQUIANGULAR_CUBEMAP_FACE", "FISHEYE_LENS_POLYNOMIAL", "CENTRAL_CYLINDRICAL")
"""Panoramic projections, as Cycles' kernel/camera/projection.h defines them."""


@dataclass
class SceneData:
    """Everything the tracer needs to render one image."""

    camera: Camera
    meshes: list[Mesh] = field(default_factory=list)
    instances: list[Instance] = field(default_factory=list)
    materials: list[Material] = field(default_factory=lambda: [DEFAULT_MATERIAL])
    lights: list[Light] = field(default_factory=list)
    world: World = field(default_factory=World)
    film_transparent: bool = False
    images: list[TextureImage] = field(default_factory=list)
    """Images the programs' "image" nodes index."""
    warnings: list[str] = field(default_factory=list)
    """Messages for the user gathered during export (unsupported nodes and the like)."""
    light_groups: list[str] = field(default_factory=list)
    """The view layer's light groups (Cycles'): each has a pass ``Combined_<name>`` of the light its
    emitters (lights, emissive objects, the world: their ``lightgroup``) give to Combined."""

    def triangle_count(self) -> int:
        return sum(len(self.meshes[i.mesh].triangles) for i in self.instances)
