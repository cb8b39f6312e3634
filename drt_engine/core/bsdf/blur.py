"""Cycles' Filter Glossy (surface_shader_prepare_closures): after a path's blurry bounces, the
microfacet lobes at its later hits are made at least as rough as the bounce that was least
likely to take this path allows, so a sharp highlight seen through a diffuse bounce (a caustic)
is spread into a blur that sampling finds.

The path keeps the least density of its non-transparent bounces (Cycles' min_ray_pdf: the sampled
direction's pdf over the whole mixture, a delta lobe's infinite); with Filter Glossy f > 0,
blur_pdf = min_ray_pdf / f, and where it is below 1 every GGX reflection and glass lobe takes
alpha = max(alpha, sqrt(1 - blur_pdf) / 2) (Cycles' bsdf_microfacet_blur, on both alphas of an
anisotropic lobe; the blur roughness is an alpha, not squared). Principled Hair's roughnesses
are raised to the same value (core.bsdf.hair_lobes); toon, sheen, diffuse and Hair BSDF lobes
stay as they are, and, as in Cycles, the lobe's choice weight and multiple-scattering factor
stay those of its own roughness. A delta lobe blurred past ``DELTA_ALPHA`` becomes a rough one.

The per-hit least alpha lives in the lobe's ``H_BLUR`` (0: none, which leaves every alpha as it
was); the kernels below read a lobe's alphas and delta flag through it.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from .layout import GLASS, H_BLUR, P_ALPHA, P_ALPHA_T, P_ALPHA_X, P_ALPHA_Y, P_DELTA, P_ETA, P_KIND
from .microfacet import DELTA_ALPHA


def blur_roughness(min_pdf: np.ndarray, filter_glossy: float) -> np.ndarray:
    """Per path of least density ``min_pdf`` (inf: no blurry bounce yet), the alpha its
    microfacet lobes are raised to (0: none)."""
    if filter_glossy <= 0:
        return np.zeros(len(min_pdf))
    blur_pdf = min_pdf / filter_glossy  # Cycles keeps 1 / Filter Glossy
    with np.errstate(invalid="ignore"):
        return np.where(blur_pdf < 1.0, np.sqrt(np.maximum(1.0 - blur_pdf, 0.0)) * 0.5, 0.0)


@kernel(inline="always")
def alpha(lp, hp, r, l):
    """The lobe's (isotropic) alpha at hit row r."""
    return max(lp[l, P_ALPHA], hp[r, l, H_BLUR])


@kernel(inline="always")
def alphas_xy(lp, hp, r, l):
    """An anisotropic lobe's (alpha_x, alpha_y) at hit row r, each raised to the blur."""
    b = hp[r, l, H_BLUR]
    return max(lp[l, P_ALPHA_X], b), max(lp[l, P_ALPHA_Y], b)


@kernel(inline="always")
def alpha_t(lp, hp, r, l):
    """A glass lobe's spread of refracted directions at hit row r (its alpha scaled by the bend)."""
    return max(lp[l, P_ALPHA_T], hp[r, l, H_BLUR] * min(1.0, abs(lp[l, P_ETA] - 1.0)))


@kernel(inline="always")
def delta(lp, hp, r, l):
    """Whether the lobe is sampled as a delta distribution at hit row r: a delta lobe stays one
    unless the blur lifts its alpha (a glass's spread) to ``DELTA_ALPHA``."""
    if lp[l, P_DELTA] == 0.0:
        return False
    b = hp[r, l, H_BLUR]
    if b == 0.0:
        return True
    if int(lp[l, P_KIND]) == GLASS:
        return alpha_t(lp, hp, r, l) < DELTA_ALPHA
    return b < DELTA_ALPHA
