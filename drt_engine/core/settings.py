"""Render settings the core reads: the plain-data mirror of ``scene.drt``."""
from __future__ import annotations

from dataclasses import dataclass, field

from .errors import SettingsError

SAMPLING_PATTERNS = ("GRID", "JITTERED", "SOBOL")
FILTER_TYPES = ("BOX", "GAUSSIAN", "BLACKMAN_HARRIS")
ADAPTIVE_MODES = ("NOISE", "CONTRAST")
SHADOW_ESTIMATORS = ("MONTE_CARLO", "RATIO")
"""How the diffuse direct light of lights with a closed form is estimated (core.integrator.ratio)."""

PASSES = (
    "Combined",  # RGBA
    "Depth",  # Z: distance along the view axis, as Blender's Depth pass
    "Normal",  # world-space shading normal
    "Position",  # world-space hit position
    "DiffCol",  # diffuse albedo of the first hit
    "GlossCol",  # glossy albedo of the first hit
    "Emit",  # emission seen directly
    "Env",  # environment seen directly
    "Sample Count",  # samples taken per pixel
    "Noise",  # standard error of the Combined estimate per pixel
    "Denoising Albedo",  # Cycles' albedo of the first diffuse-like hit, for the Denoise node (core.film.denoising)
    "Denoising Normal",  # its normal in Cycles' camera space
    "Mist",  # Cycles' mist: 0 near, 1 far and for the background, by the world's mist settings
    "IndexOB",  # the first sample's object pass index, unfiltered (Cycles' Object Index)
    "IndexMA",  # the first sample's material pass index, unfiltered (Cycles' Material Index)
    "DiffDir",  # Cycles' light passes (core.integrator.lightpasses): light by the first hit's diffuse lobes,
    "DiffInd",  # direct (light samples at the first hit, emission its bounce ray finds) and indirect
    "GlossDir",  # (what later vertices bring), each read out divided by its colour pass
    "GlossInd",
    "TransDir",
    "TransInd",
    "TransCol",  # transmission albedo of the first hit
    "Vector",  # Cycles' motion vectors in pixels: to the previous frame's position, from the next's (core.film.vector)
    "CryptoObject",  # Cryptomatte of the objects' names, written as CryptoObject00, 01, ... (core.film.cryptomatte)
    "CryptoMaterial",  # of the materials' names
    "CryptoAsset",  # of the objects' top-level parents' names
    "Shadow Catcher",  # Cycles' Shadow Catcher pass: the catchers' light with the other objects over without them
)
PASS_CHANNELS = {
    "Combined": "RGBA",
    "Depth": "Z",
    "Normal": "XYZ",
    "Position": "XYZ",
    "DiffCol": "RGB",
    "GlossCol": "RGB",
    "Emit": "RGB",
    "Env": "RGB",
    "Sample Count": "X",
    "Noise": "RGB",
    "Denoising Albedo": "RGB",
    "Denoising Normal": "XYZ",
    "Mist": "Z",
    "IndexOB": "X",
    "IndexMA": "X",
    "DiffDir": "RGB",
    "DiffInd": "RGB",
    "GlossDir": "RGB",
    "GlossInd": "RGB",
    "TransDir": "RGB",
    "TransInd": "RGB",
    "TransCol": "RGB",
    "Vector": "XYZW",
    "Noisy Image": "RGBA",
    "Shadow Catcher": "RGB",  # read from the sums below (core.film.shadow_catcher)
    "Shadow Catcher Paths": "RGB",
    "Shadow Catcher Matte": "RGBA",
    "Shadow Catcher Sample Count": "X",
    "Shadow Catcher Background": "RGB",
}
FIRST_SAMPLE_PASSES = ("IndexOB", "IndexMA")
"""Passes that hold their pixel's first sample (sample id 0, replicate 0) as it is, not a filtered
mean: an index is an identity, which averaging across an edge would turn into another one (Cycles
writes these at sample 0 only, core.film.film)."""
LIGHT_PASSES = {"DiffDir": "DiffCol", "DiffInd": "DiffCol", "GlossDir": "GlossCol", "GlossInd": "GlossCol",
                "TransDir": "TransCol", "TransInd": "TransCol"}
"""Cycles' light passes and the colour pass each is read out divided by (Cycles' divide_even_color):
a render of one also sums its colour (``read_over``), as Cycles allocates it."""


def read_over(passes) -> tuple[str, ...]:
    """The colour passes the light passes among ``passes`` are divided by that ``passes`` lacks: a
    render traces and sums them (core.render.render) but returns only what was asked, as Cycles
    allocates them for itself and hands Blender only the enabled passes."""
    passes = tuple(passes)
    return tuple(dict.fromkeys(LIGHT_PASSES[name] for name in passes
                               if name in LIGHT_PASSES and LIGHT_PASSES[name] not in passes))


CATCHER_SUMS = ("Shadow Catcher Paths", "Shadow Catcher Matte", "Shadow Catcher Sample Count",
                "Shadow Catcher Background")
"""The film sums a render with shadow catchers keeps beside Combined and Shadow Catcher and returns
as no pass, as Cycles allocates its matte, sample count and background passes for itself
(core.film.shadow_catcher)."""


WEIGHTED_PASSES = ("Vector",)
"""Passes whose sums carry one more channel, the count of samples that wrote them, and read as the
sum over it (Cycles' motion weight: a pixel's vector is the mean of its samples that hit a surface,
the background's samples count for nothing)."""
CRYPTOMATTE_PASSES = ("CryptoObject", "CryptoMaterial", "CryptoAsset")
"""Passes whose sums are (id, weight) slots, read out as ``cryptomatte_levels`` RGBA passes each of two
ranks (core.film.cryptomatte)."""
CRYPTOMATTE_CHANNELS = "rgba"
"""A Cryptomatte rank pass's channels, as Cycles registers them (id, weight, id, weight)."""


def cryptomatte_passes(name: str, levels: int) -> tuple[str, ...]:
    """The rank passes of Cryptomatte pass ``name`` at ``levels``: ``<name>00``, ``<name>01``, ...,
    one per two levels rounded up (at most 16 levels), as Cycles names them."""
    return tuple(f"{name}{i:02d}" for i in range((min(16, levels) + 1) // 2))


def pass_of(image: str) -> str:
    """The pass an image of the film belongs to: a Cryptomatte rank pass's own pass, else the image's name."""
    return image[:-2] if image[:-2] in CRYPTOMATTE_PASSES and image[-2:].isdigit() else image


AOV_CHANNELS = {"COLOR": "RGBA", "VALUE": "X"}
"""Channels of a shader AOV pass by its type, as Cycles registers them (a colour's alpha counts the
writes: 1 per sample whose camera path wrote the AOV)."""


LIGHTGROUP_PREFIX = "Combined_"
"""A light group's pass is ``Combined_<group>``, RGB, as Cycles names and registers it: the share of
Combined its emitters give (core.integrator.lightgroups)."""


def lightgroup_pass(group: str) -> str:
    """The pass of light group ``group``."""
    return LIGHTGROUP_PREFIX + group


def pass_channels(name: str, aovs=()) -> str:
    """The channel ids of pass ``name``: a built-in pass's, a light group's, or of one of the shader
    AOVs ``aovs`` ((name, type) pairs, ``RenderSettings.aovs``)."""
    if name in PASS_CHANNELS:
        return PASS_CHANNELS[name]
    if pass_of(name) in CRYPTOMATTE_PASSES:
        return CRYPTOMATTE_CHANNELS
    aov = dict(aovs).get(name)
    if aov is None and name.startswith(LIGHTGROUP_PREFIX):
        return "RGB"
    return AOV_CHANNELS[aov]


NOISY_IMAGE = "Noisy Image"
"""With denoising on, the Combined image as rendered, before OIDN (Cycles' pass of that name); not
one of ``PASSES``: the render adds it, no setting asks for it."""

DENOISING_PREFILTERS = ("NONE", "FAST", "ACCURATE")
"""Cycles' ``denoising_prefilter``: how the albedo and normal are cleaned (core.film.denoiser)."""
DENOISING_QUALITIES = ("HIGH", "BALANCED", "FAST")
"""Cycles' ``denoising_quality``."""


@dataclass
class RenderSettings:
    samples: int = 64
    seed: int = 0
    sampling_pattern: str = "SOBOL"
    max_depth: int = 8
    # Cycles' Diffuse bounces: how many diffuse reflections a path may take (0: direct light only
    # on diffuse surfaces, DRT's classic image; core.integrator.bounces)
    diffuse_bounces: int = 0
    # Cycles' Glossy and Transmission bounces: a path whose glossy (non-diffuse reflection) or
    # transmission depth passes them ends at its next hit, which adds only the emission it sees
    # (core.integrator.bounces.ended); at the default Total 8 a limit of 8 never binds
    glossy_bounces: int = 8
    transmission_bounces: int = 8
    # Cycles' Min Light Bounces and Min Transparent Bounces: Russian roulette ends paths after
    # them (only with diffuse bounces; core.integrator.continuation.roulette)
    min_light_bounces: int = 0
    min_transparent_bounces: int = 0
    # Cycles' Max Transparent Bounces: transparent surfaces a shadow ray goes through, counted on
    # from its path's own transparent bounces; one more blocks it (core.integrator.shadows)
    max_transparent_bounces: int = 8
    # Cycles' Clamp Direct and Clamp Indirect: each contribution of a sample before (direct) and
    # after (indirect) its path's first bounce kept within them (core.integrator.clamp); 0: off
    sample_clamp_direct: float = 0.0
    sample_clamp_indirect: float = 0.0
    # Cycles' Filter Glossy: after a path's blurry bounces its GGX reflection, glass and Principled Hair
    # lobes are made at least as rough as the least likely bounce allows (core.bsdf.blur); 0: off (Cycles' default is
    # 1, DRT's 0 keeps the image of paths that see highlights through rough bounces as it was)
    filter_glossy: float = 0.0
    threads: int = 0
    filter_type: str = "BLACKMAN_HARRIS"
    filter_size: float = 1.5
    passes: tuple[str, ...] = ("Combined",)
    # the view layer's shader AOVs, (name, "COLOR" or "VALUE") each: passes of those names, written
    # by the materials' AOV Output nodes (core.integrator.aovs); each name is also one of ``passes``
    aovs: tuple[tuple[str, str], ...] = ()
    use_adaptive_sampling: bool = False
    adaptive_threshold: float = 0.01
    adaptive_min_samples: int = 0
    adaptive_mode: str = "NOISE"
    shadow_estimator: str = "MONTE_CARLO"
    time_limit: float = 0.0
    target_error: float = 0.0
    sample_start: int = 0  # first sample id of this render's range (a farm part renders one range)
    sample_end: int = 0  # one past its last sample id; 0 = samples
    # the view layer's Alpha Threshold: a hit at least this opaque ends the index passes (IndexOB,
    # IndexMA) of its path; a more transparent one hands them on to the hit behind it (Cycles' rule)
    pass_alpha_threshold: float = 0.5
    # the view layer's Cryptomatte Levels: (id, weight) ranks kept per pixel, two per pass, for the
    # Cryptomatte passes among ``passes`` (core.film.cryptomatte)
    cryptomatte_levels: int = 6
    # Cycles from Blender 5.2 on scales Denoising Normal by the feature walk's mean throughput
    # (measured: seen in a mirror of tint t, |n| = mean(t)); 5.0 and older write unit normals
    weighted_denoising_normal: bool = False
    # Cycles from Blender 5.2 on writes the Vector pass at camera rays that reach the background
    # too (the camera's own turning, weight 1, core.geometry.motion_vectors); 5.0 and older leave
    # those samples out of the pass
    vector_background: bool = False
    # OpenImageDenoise over the finished Combined image (core.render.denoise), guided by the
    # Denoising Albedo and Normal (traced for it even when not asked for as passes)
    use_denoising: bool = False
    denoising_prefilter: str = "ACCURATE"
    denoising_quality: str = "HIGH"
    extra: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.sampling_pattern not in SAMPLING_PATTERNS:
            raise ValueError(f"unknown sampling pattern {self.sampling_pattern!r}")
        if self.filter_type not in FILTER_TYPES:
            raise ValueError(f"unknown filter type {self.filter_type!r}")
        if self.adaptive_mode not in ADAPTIVE_MODES:
            raise ValueError(f"unknown adaptive mode {self.adaptive_mode!r}")
        if self.shadow_estimator not in SHADOW_ESTIMATORS:
            raise SettingsError(f"unknown shadow estimator {self.shadow_estimator!r} "
                                f"(one of {', '.join(SHADOW_ESTIMATORS)})")
        if self.denoising_prefilter not in DENOISING_PREFILTERS:
            raise SettingsError(f"unknown denoising prefilter {self.denoising_prefilter!r} "
                                f"(one of {', '.join(DENOISING_PREFILTERS)})")
        if self.denoising_quality not in DENOISING_QUALITIES:
            raise SettingsError(f"unknown denoising quality {self.denoising_quality!r} "
                                f"(one of {', '.join(DENOISING_QUALITIES)})")
        for name in ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "min_light_bounces",
                     "min_transparent_bounces", "max_transparent_bounces"):
            if getattr(self, name) < 0:
                raise SettingsError(f"{name.replace('_', ' ')} must be 0 or more, not {getattr(self, name)}")
        for name in ("sample_clamp_direct", "sample_clamp_indirect", "filter_glossy"):
            if not getattr(self, name) >= 0:
                raise SettingsError(f"{name.replace('_', ' ')} must be 0 (off) or more, not {getattr(self, name)}")
        if self.samples < 1:
            raise ValueError("samples must be at least 1")
        self.aovs = tuple((str(name), str(kind)) for name, kind in self.aovs)
        self._check_aovs()
        unknown = {name for name in set(self.passes) - set(PASSES) - set(CATCHER_SUMS) - {name for name, _ in self.aovs}
                   if not name.startswith(LIGHTGROUP_PREFIX)}
        if unknown:
            raise ValueError(f"unknown passes {sorted(unknown)}")
        self.passes = tuple(self.passes) + tuple(name for name, _ in self.aovs if name not in self.passes)
        if "Combined" not in self.passes:
            self.passes = ("Combined",) + tuple(self.passes)
        start, end = self.sample_range()
        if not 0 <= start < end <= self.samples:
            raise SettingsError(f"sample range {start}:{end} is not inside the {self.samples} samples 0:{self.samples}")
        if self.partial and (self.use_adaptive_sampling or self.time_limit > 0 or self.target_error > 0):
            raise SettingsError("a sample range needs a fixed sample count: turn off adaptive sampling, "
                                "the time limit and the target error")

    def _check_aovs(self):
        names = [name for name, _ in self.aovs]
        for name, kind in self.aovs:
            if kind not in AOV_CHANNELS:
                raise SettingsError(f"AOV '{name}' has type {kind!r}, not one of {', '.join(AOV_CHANNELS)}")
            if not name or name in PASS_CHANNELS or names.count(name) > 1:
                raise SettingsError(f"AOV '{name}': an AOV needs a name of its own, not empty, another AOV's "
                                    "or a pass's")

    def sample_range(self) -> tuple[int, int]:
        """The sample ids this render traces, start to end - 1, of the full set of ``samples``."""
        return self.sample_start, self.sample_end or self.samples

    @property
    def partial(self) -> bool:
        """True when only part of the samples is traced (a part to merge with others)."""
        return self.sample_range() != (0, self.samples)
