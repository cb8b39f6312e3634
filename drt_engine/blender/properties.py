"""DRT's settings in Blender: ``scene.drt`` and ``view_layer.drt``, and their plain-data mirror.

Only settings Blender does not already have live here. Resolution, border, film
transparency, filter width and motion blur are read from ``scene.render`` so DRT and
Cycles share one set of knobs.
"""
import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
)

from ..core.settings import (
    CRYPTOMATTE_PASSES,
    NOISY_IMAGE,
    PASSES,
    RenderSettings,
    cryptomatte_passes,
    lightgroup_pass,
    pass_channels,
)
from .oidn import oidn_library

BLENDER_PASS_TOGGLES = {
    "Depth": "use_pass_z",
    "Normal": "use_pass_normal",
    "Position": "use_pass_position",
    "DiffCol": "use_pass_diffuse_color",
    "GlossCol": "use_pass_glossy_color",
    "DiffDir": "use_pass_diffuse_direct",
    "DiffInd": "use_pass_diffuse_indirect",
    "GlossDir": "use_pass_glossy_direct",
    "GlossInd": "use_pass_glossy_indirect",
    "TransDir": "use_pass_transmission_direct",
    "TransInd": "use_pass_transmission_indirect",
    "TransCol": "use_pass_transmission_color",
    "Emit": "use_pass_emit",
    "Env": "use_pass_environment",
    "Mist": "use_pass_mist",
    "IndexOB": "use_pass_object_index",
    "IndexMA": "use_pass_material_index",
    "Vector": "use_pass_vector",
    "CryptoObject": "use_pass_cryptomatte_object",
    "CryptoMaterial": "use_pass_cryptomatte_material",
    "CryptoAsset": "use_pass_cryptomatte_asset",
}
"""Passes Blender has its own view-layer toggle for (the compositor knows them by these names)."""

DRT_PASS_TOGGLES = {
    "Sample Count": "use_pass_sample_count",
    "Noise": "use_pass_noise",
    "Denoising Albedo": "use_pass_denoising_data",
    "Denoising Normal": "use_pass_denoising_data",
}
"""DRT's own passes, toggled by ``view_layer.drt.<property>``."""

CYCLES_PASS_TOGGLES = {"Shadow Catcher": "use_pass_shadow_catcher"}
"""Passes whose toggle Cycles' add-on puts on the view layer (``view_layer.cycles``), as Cycles reads
it; off when that add-on is not there."""

RESULT_NAMES_5 = {"IndexOB": "Object Index", "IndexMA": "Material Index"}
"""Passes Blender 5.0+ names otherwise in its render result (the view-layer toggles create them so)."""


def result_pass_name(name: str) -> str:
    """The name of pass ``name`` in this Blender's render result and compositor."""
    return RESULT_NAMES_5.get(name, name) if bpy.app.version >= (5, 0, 0) else name


_PASS_TYPES = {"rgba": "COLOR", "RGBA": "COLOR", "RGB": "COLOR", "XYZ": "VECTOR", "XYZW": "VECTOR", "Z": "VALUE", "X": "VALUE"}


def pass_enabled(view_layer, name: str) -> bool:
    """Whether the view layer asks for pass ``name`` (Combined always)."""
    if name == "Combined":
        return True
    if name in BLENDER_PASS_TOGGLES:
        return bool(getattr(view_layer, BLENDER_PASS_TOGGLES[name], False))
    if name in CYCLES_PASS_TOGGLES:
        return bool(getattr(getattr(view_layer, "cycles", None), CYCLES_PASS_TOGGLES[name], False))
    return bool(getattr(view_layer.drt, DRT_PASS_TOGGLES[name]))


def enabled_passes(view_layer) -> tuple[str, ...]:
    """The passes to render and write for this view layer, in ``PASSES`` order."""
    return tuple(name for name in PASSES if pass_enabled(view_layer, name))


def view_layer_aovs(view_layer) -> tuple[tuple[str, str], ...]:
    """The view layer's shader AOVs, (name, "COLOR" or "VALUE"): passes of their names, as Cycles
    registers them; an AOV Blender marks not valid (its name empty, repeated or a pass's) is none."""
    return tuple((aov.name, aov.type) for aov in getattr(view_layer, "aovs", ()) if aov.is_valid)


def view_layer_lightgroups(view_layer) -> tuple[str, ...]:
    """The view layer's light groups' names (Cycles writes a pass ``Combined_<name>`` for each)."""
    return tuple(group.name for group in getattr(view_layer, "lightgroups", ()))


def lightgroup_of(idblock, groups: dict) -> int:
    """The index among the view layer's light groups ``groups`` (name -> index) of the object's or
    world's light group, -1 for none or a name the view layer has no group of (as Cycles)."""
    return groups.get(getattr(idblock, "lightgroup", "") or "", -1) if idblock is not None else -1


def denoising_active(scene) -> bool:
    """Whether final renders of ``scene`` are denoised: asked for, and this Blender has OIDN."""
    return bool(scene.drt.use_denoising) and oidn_library() is not None


def registered_passes(scene, view_layer) -> tuple[str, ...]:
    """The passes a render of this view layer writes: the enabled ones (a Cryptomatte pass as its rank
    passes), and Noisy Image when denoising."""
    extra = (NOISY_IMAGE,) if scene is not None and denoising_active(scene) else ()
    levels = view_layer.pass_cryptomatte_depth
    written = tuple(rank for name in enabled_passes(view_layer)
                    for rank in (cryptomatte_passes(name, levels) if name in CRYPTOMATTE_PASSES else (name,)))
    return written + tuple(name for name, _ in view_layer_aovs(view_layer)) + _lightgroup_passes(view_layer) + extra


def _lightgroup_passes(view_layer) -> tuple[str, ...]:
    return tuple(dict.fromkeys(lightgroup_pass(name) for name in view_layer_lightgroups(view_layer)))


def pass_layout(name: str, aovs=()) -> tuple[int, str, str]:
    """(channel count, channel ids, Blender pass type) for ``RenderEngine.register_pass`` (``aovs``:
    the view layer's shader AOVs)."""
    chan_id = pass_channels(name, aovs)
    return len(chan_id), chan_id, _PASS_TYPES[chan_id]


VECTOR_BACKGROUND_FROM = (5, 1, 0)
"""The first Blender whose Cycles writes the Vector pass at camera rays that reach the background
(film_write_data_passes_background: 5.2's kernel has it, 5.0's does not). 5.1's is not at hand: it is
taken to be 5.2's, the first release after the 5.0 whose sources were read."""


def settings_from_scene(scene, view_layer) -> RenderSettings:
    """The core's RenderSettings for one view layer of ``scene``."""
    drt = scene.drt
    return RenderSettings(
        samples=drt.samples,
        seed=drt.seed,
        sampling_pattern=drt.sampling_pattern,
        max_depth=drt.max_depth,
        diffuse_bounces=drt.diffuse_bounces,
        glossy_bounces=drt.glossy_bounces,
        transmission_bounces=drt.transmission_bounces,
        min_light_bounces=drt.min_light_bounces,
        min_transparent_bounces=drt.min_transparent_bounces,
        max_transparent_bounces=drt.max_transparent_bounces,
        sample_clamp_direct=drt.sample_clamp_direct,
        sample_clamp_indirect=drt.sample_clamp_indirect,
        filter_glossy=drt.filter_glossy,
        threads=drt.threads,
        filter_type=drt.filter_type,
        filter_size=scene.render.filter_size,
        passes=enabled_passes(view_layer) + _lightgroup_passes(view_layer),
        aovs=view_layer_aovs(view_layer),
        use_adaptive_sampling=drt.use_adaptive_sampling,
        adaptive_threshold=drt.adaptive_threshold,
        adaptive_min_samples=drt.adaptive_min_samples,
        adaptive_mode=drt.adaptive_mode,
        shadow_estimator=drt.shadow_estimator,
        time_limit=drt.time_limit,
        target_error=drt.target_error,
        sample_start=drt.sample_offset,
        sample_end=drt.sample_offset + drt.sample_count if drt.sample_count else 0,
        pass_alpha_threshold=view_layer.pass_alpha_threshold,
        cryptomatte_levels=view_layer.pass_cryptomatte_depth,
        weighted_denoising_normal=bpy.app.version >= (5, 2, 0),
        vector_background=bpy.app.version >= VECTOR_BACKGROUND_FROM,
        use_denoising=drt.use_denoising,
        denoising_prefilter=drt.denoising_prefilter,
        denoising_quality=drt.denoising_quality,
    )


def _update_render_passes(self, context):
    """Tell Blender the view layer's pass list changed so the compositor's sockets follow."""
    for view_layer in self.id_data.view_layers:
        if view_layer.drt.as_pointer() == self.as_pointer():
            view_layer.update_render_passes()


def _update_scene_passes(self, context):
    """Denoising adds or removes the Noisy Image pass of every view layer."""
    for view_layer in self.id_data.view_layers:
        view_layer.update_render_passes()


_PREFILTERS = (
    ("NONE", "None", "No prefiltering: the albedo and normal are taken as noise-free (sharpest "
     "where they are, e.g. without depth of field or motion blur)"),
    ("FAST", "Fast", "The denoiser allows for noise in the albedo and normal itself"),
    ("ACCURATE", "Accurate", "The albedo and normal are denoised first, each on its own, then "
     "guide the image's denoising (slowest, best detail)"),
)
"""Cycles' denoising prefilters, for final renders and the viewport alike."""
_QUALITIES = (
    ("HIGH", "High", "Best quality (for final frames)"),
    ("BALANCED", "Balanced", "Faster, somewhat lower quality"),
    ("FAST", "Fast", "Fastest, lowest quality (for previews)"),
)
"""OpenImageDenoise's quality modes, as Cycles names them."""


_DENOISING_OPTIONS = {
    "Prefilter": ("How the albedo and normal that guide the denoiser are cleaned", _PREFILTERS),
    "Quality": ("OpenImageDenoise's quality mode", _QUALITIES),
}


def _denoising_option(name: str, default: str, where: str = "") -> dict:
    """The arguments of a denoiser's Prefilter or Quality (final renders, or the viewport's
    ``where``), as Cycles' options: the scene's properties hold their defaults, nothing else."""
    what, items = _DENOISING_OPTIONS[name]
    return {"name": name, "description": f"{what}{where}, as Cycles' option", "default": default, "items": items}


def _bounces(name: str, description: str, default: int = 0, soft_max: int = 64) -> dict:
    """The arguments of a count of bounces, as the Light Paths panel shows them."""
    return {"name": name, "description": description, "default": default, "min": 0, "soft_max": soft_max,
            "max": 1024}


class DRTSceneSettings(bpy.types.PropertyGroup):
    samples: IntProperty(
        name="Samples",
        description="Samples per pixel. Each sample traces one camera ray and its whole "
        "specular and glossy ray tree; noise falls as one over the square root of this",
        default=64,
        min=1,
        soft_max=4096,
    )
    preview_samples: IntProperty(
        name="Viewport",
        description="Samples per pixel the viewport's Rendered shading accumulates at full resolution "
        "(after its coarse 1/8, 1/4 and 1/2 resolution images). Fewer than Cycles' 1024 by default: "
        "a distribution ray tracer's image settles sooner than a path tracer's, and each full-resolution "
        "sample of the viewport costs as much as a final render's",
        default=256,
        min=1,
        soft_max=4096,
    )
    seed: IntProperty(
        name="Seed",
        description="Seed of every random number. The same settings and seed give the "
        "same image, bit for bit; change it to get independent noise",
        default=0,
        min=0,
    )
    sampling_pattern: EnumProperty(
        name="Pattern",
        description="How sample positions are chosen in the pixel, lens, shutter time and "
        "light dimensions",
        items=(
            ("GRID", "Grid", "Regular n×n supersampling, averaged down (aliases on fine detail)"),
            ("JITTERED", "Jittered", "n×n strata with one random sample in each"),
            ("SOBOL", "Sobol", "Owen-scrambled Sobol sequence, decorrelated per pixel and "
             "per dimension; converges fastest"),
        ),
        default="SOBOL",
    )
    max_depth: IntProperty(**_bounces(
        "Max Depth", "Longest chain of reflections and refractions followed from the camera (Cycles' Total "
        "bounces, transparent ones included)", default=8))
    diffuse_bounces: IntProperty(**_bounces(
        "Diffuse", "Diffuse reflections a path may take (Cycles' Diffuse bounces); 0: diffuse surfaces take "
        "direct light only, the classic distribution ray traced image", soft_max=32))
    glossy_bounces: IntProperty(**_bounces(
        "Glossy", "Glossy and mirror reflections a path may take (Cycles' Glossy bounces); the ray of one more "
        "still sees what it hits", default=8, soft_max=32))
    transmission_bounces: IntProperty(**_bounces(
        "Transmission", "Refractions and diffuse transmissions a path may take (Cycles' Transmission bounces); "
        "the ray of one more still sees what it hits", default=8, soft_max=32))
    min_light_bounces: IntProperty(**_bounces(
        "Min Light Bounces", "Bounces before Russian roulette may end a path (Cycles' Min Light Bounces); "
        "only paths with diffuse bounces are ended so"))
    min_transparent_bounces: IntProperty(**_bounces(
        "Min Transparent Bounces", "Transparent bounces before Russian roulette may end a path (Cycles' Min "
        "Transparent Bounces); only with diffuse bounces"))
    max_transparent_bounces: IntProperty(**_bounces(
        "Transparent", "Transparent surfaces a shadow ray may pass through, counted on from its path's "
        "transparent bounces; one more blocks it (Cycles' Max Transparent Bounces)", default=8))
    sample_clamp_direct: FloatProperty(
        name="Clamp Direct",
        description="Largest value (as the mean of its RGB) one sample's light may add before the path's first "
        "bounce: the camera's emission and world and the lights at its first hits (Cycles' Clamp Direct); "
        "tames fireflies at the cost of bias, 0 turns it off",
        default=0.0,
        min=0.0,
        soft_max=100.0,
    )
    sample_clamp_indirect: FloatProperty(
        name="Clamp Indirect",
        description="Largest value (as the mean of its RGB) one sample's light may add after the path's first "
        "bounce (Cycles' Clamp Indirect); tames fireflies at the cost of bias, 0 turns it off",
        default=0.0,
        min=0.0,
        soft_max=100.0,
    )
    filter_glossy: FloatProperty(
        name="Filter Glossy",
        description="Blur glossy, glass and Principled Hair surfaces seen after blurry bounces, as much as the least likely "
        "bounce of the path allows (Cycles' Filter Glossy): less noise in caustics at the cost of accuracy; "
        "0 turns it off (DRT's default; Cycles' is 1)",
        default=0.0,
        min=0.0,
        max=10.0,
    )
    shadow_estimator: EnumProperty(
        name="Shadow Estimator",
        description="How the diffuse direct light of area, sphere and sun lights is estimated",
        items=(
            ("MONTE_CARLO", "Monte Carlo", "Each shadow ray's light sample counts on its own (unbiased; "
             "noisy wherever a light is partly or wholly in view)"),
            ("RATIO", "Ratio", "The light's exact unoccluded light times the fraction of it the pixel's "
             "shadow rays let through (Heitz et al. 2018): exact where a light is wholly in view or "
             "hidden, noisy only in penumbrae, with a bias there that vanishes as samples grow; "
             "lights with no closed form stay Monte Carlo (the render plan names them)"),
        ),
        default=RenderSettings.shadow_estimator,
    )
    threads: IntProperty(
        name="Threads",
        description="Threads tracing rays; 0 uses all processor cores. The image does not "
        "depend on it",
        default=0,
        min=0,
        max=1024,
    )
    filter_type: EnumProperty(
        name="Filter",
        description="Pixel reconstruction filter; its width is the render's Filter Size",
        items=(
            ("BOX", "Box", "Every sample in the filter square counts equally (sharpest, aliases)"),
            ("GAUSSIAN", "Gaussian", "Gaussian falloff (soft)"),
            ("BLACKMAN_HARRIS", "Blackman-Harris", "Blackman-Harris window, as Cycles "
             "(sharp with little ringing)"),
        ),
        default="BLACKMAN_HARRIS",
    )
    use_adaptive_sampling: BoolProperty(
        name="Adaptive Sampling",
        description="After the minimum samples, stop sampling pixels that need no more and "
        "spend the samples where the image is still noisy",
        default=False,
    )
    adaptive_mode: EnumProperty(
        name="Mode",
        description="How a pixel is judged to need more samples",
        items=(
            ("NOISE", "Noise", "Until the estimated error of the pixel's mean is under the noise "
             "threshold, with Cycles' measure and threshold; the pixels still sampling share each "
             "round in proportion to their error"),
            ("CONTRAST", "Contrast", "While the samples in the pixel's 3x3 neighbourhood differ in "
             "contrast beyond Mitchell's (1987) thresholds (the noise threshold is not used)"),
        ),
        default="NOISE",
    )
    adaptive_threshold: FloatProperty(
        name="Noise Threshold",
        description="Noise level at which a pixel stops receiving samples, as Cycles' Noise "
        "Threshold (its standard error relative to its brightness); 0 chooses it from the "
        "samples, max(0.001, 1/samples)",
        default=0.01,
        min=0.0,
        soft_min=0.001,
        max=1.0,
        precision=4,
    )
    adaptive_min_samples: IntProperty(
        name="Min Samples",
        description="Samples every pixel takes before the first test; 0 chooses it for DRT's "
        "sharing of samples: min(16, samples / 8), at least 4",
        default=0,
        min=0,
    )
    time_limit: FloatProperty(
        name="Time Limit",
        description="Stop the render after this many seconds with the image so far; "
        "0 means no limit",
        default=0.0,
        min=0.0,
        subtype="TIME_ABSOLUTE",
        unit="TIME_ABSOLUTE",
    )
    target_error: FloatProperty(
        name="Target Error",
        description="Stop the render once the estimated relative mean squared error of "
        "the image (relMSE) falls below this, of the denoised image when Denoise is on; 0 means no target",
        default=0.0,
        min=0.0,
        soft_max=0.1,
        precision=4,
    )
    use_denoising: BoolProperty(
        name="Denoise",
        description="Denoise final renders with the OpenImageDenoise library Blender ships, guided by "
        "DRT's Denoising Albedo and Normal, as Cycles does; the image as rendered is kept as the Noisy "
        "Image pass, and the render's report gives the denoised image's estimated error beside the noisy "
        "one's. Unavailable in a Blender without OpenImageDenoise (Debian's, for one)",
        default=False,
        update=_update_scene_passes,
    )
    use_preview_denoising: BoolProperty(
        name="Denoise Viewport",
        description="Denoise the viewport's Rendered shading with OpenImageDenoise from the start sample on, "
        "on the viewport's worker thread",
        default=False,
    )
    preview_denoising_start_sample: IntProperty(
        name="Start Sample",
        description="Samples every pixel of the viewport has before its image is denoised",
        default=1,
        min=1,
    )
    preview_denoising_prefilter: EnumProperty(**_denoising_option("Prefilter", "FAST", " in the viewport"))
    preview_denoising_quality: EnumProperty(**_denoising_option("Quality", "BALANCED", " in the viewport"))
    denoising_prefilter: EnumProperty(**_denoising_option("Prefilter", "ACCURATE"))
    denoising_quality: EnumProperty(**_denoising_option("Quality", "HIGH"))

    sample_offset: IntProperty(
        name="Sample Offset",
        description="First sample id to render, for a render farm: each job renders its own range "
        "of the samples and writes a part file beside the output, and `python -m drt_engine merge` "
        "adds the parts into the image of all the samples",
        default=0,
        min=0,
    )
    sample_count: IntProperty(
        name="Sample Count",
        description="Samples to render from the offset, for a render farm; 0 means up to Samples",
        default=0,
        min=0,
    )


class DRTViewLayerSettings(bpy.types.PropertyGroup):
    use_pass_sample_count: BoolProperty(
        name="Sample Count",
        description="Write the number of samples each pixel took",
        default=False,
        update=_update_render_passes,
    )
    use_pass_noise: BoolProperty(
        name="Noise",
        description="Write each pixel's standard error of the Combined estimate",
        default=False,
        update=_update_render_passes,
    )
    use_pass_denoising_data: BoolProperty(
        name="Denoising Data",
        description="Write the Denoising Albedo and Denoising Normal passes, as Cycles does, for the "
        "compositor's Denoise node (Image, Albedo and Normal inputs)",
        default=False,
        update=_update_render_passes,
    )


classes = (DRTSceneSettings, DRTViewLayerSettings)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.drt = PointerProperty(type=DRTSceneSettings, name="DRT", description="DRT render settings")
    bpy.types.ViewLayer.drt = PointerProperty(type=DRTViewLayerSettings, name="DRT", description="DRT pass settings")


def unregister():
    del bpy.types.ViewLayer.drt
    del bpy.types.Scene.drt
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
