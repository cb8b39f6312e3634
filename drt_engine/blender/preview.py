"""Material and light previews (thumbnails, the Preview panel): few samples and short chains.

Blender renders them through the engine's ``render`` with ``is_preview`` set; final.py runs
them with these settings and keeps their prepared scene under PREVIEW_LAYER.
"""
import dataclasses

PREVIEW_SAMPLES = 8
PREVIEW_MAX_DEPTH = 4
"""8 samples, not 16: the 128-pixel preview of a Cornell box material took 2.4 s at 16 (its
relMSE against 256 samples 3.6e-4, 8.9e-4 at 8), bench/preview_times.py."""

PREVIEW_LAYER = "<material preview>"
"""The ``persistent`` slot of previews: Blender renders a material's icon, then its large
preview, of the same preview scene, so the second reuses the first's prepared scene."""


def preview_settings(settings):
    """Settings for a material or light preview: small and fast, Combined only, not denoised."""
    return dataclasses.replace(settings, samples=min(settings.samples, PREVIEW_SAMPLES),
                               max_depth=min(settings.max_depth, PREVIEW_MAX_DEPTH), passes=("Combined",), aovs=(),
                               sample_start=0, sample_end=0, use_denoising=False)
