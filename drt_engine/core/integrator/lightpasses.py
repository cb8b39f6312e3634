"""Cycles' light passes: Diffuse, Glossy and Transmission, each Direct and Indirect, as its film
writes them (kernel/film/light_passes.h).

Every contribution to Combined after the camera's own first hit is split by the BSDF of that hit:
a light sample there by its evaluation toward the light (the diffuse lobes' share to Diffuse, the
other lobes' reflection to Glossy, the rest to Transmission, but a hair lobe's light by its closure,
as Cycles files it; Cycles' bsdf_eval_pass_*_weight), and
what the path finds after its first bounce by the shares of the bounce's direction (the ray's
pass weights, set once at that bounce and kept). Direct: the light samples at the first hit and the
emission (lights, emissive surfaces, the world, suns) its bounce ray finds, MIS-weighted; Indirect:
everything later. What the camera sees itself (Emit, Env) is in none of them. Each is written after
the clamp, as Combined; the film reads each out divided by its colour pass (core.film.film).

The wave carries ``split`` (paths, 6, 3: kind x direct / indirect, ``COLUMNS``), per path its
``weights`` (paths, 6, 3: diffuse, glossy and transmission share after the first bounce, of the whole
mixture for Indirect, then of the lobes the ray continued through for the emission it finds, Direct:
core.integrator.continuation.pass_shares) and ``bounces`` (its non-transparent bounces so far).
A render with none of these passes carries nothing of this.
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..bsdf.hair_lobes import has_hair
from ..bsdf.mixture import UNLIT_DIFFUSE, UNLIT_REFLECTION, UNLIT_TRANSMISSION, eval_lobes
from ..settings import LIGHT_PASSES

SHADOWS_LEFT_OUT = ("light passes: light that reaches a surface through transparent surfaces (transparent "
                    "shadows) is in Combined only")
RATIO_LEFT_OUT = "light passes: the Ratio shadow estimator's correction is in Combined only"
"""The warnings for what the light passes do not split yet (Emit + Env + the passes then fall short of Combined)."""

COLUMNS = ("DiffDir", "DiffInd", "GlossDir", "GlossInd", "TransDir", "TransInd")
"""The ``split`` columns: kind (diffuse, glossy, transmission) by direct (even) and indirect (odd)."""
NO_SPLIT = np.zeros((0, 6, 3))
NO_WEIGHTS = np.zeros((0, 6, 3))
NO_BOUNCES = np.zeros(0, np.int64)
"""The kernels' arrays when no light pass is asked for."""


def asked(passes) -> bool:
    """Whether any light pass is among ``passes``."""
    return any(name in LIGHT_PASSES for name in passes)


class WaveSplit:
    """The light passes' per-path arrays of one wave of ``n`` paths (see the module's docstring)."""

    def __init__(self, n: int):
        self.split = np.zeros((n, 6, 3))
        self.weights = np.zeros((n, 6, 3))
        self.bounces = np.zeros(n, np.int64)

    def arrays(self) -> tuple:
        """(split, weights, bounces), as the direct-light kernel takes them."""
        return self.split, self.weights, self.bounces

    def add_found(self, path: np.ndarray, e: np.ndarray):
        """Emission rays found (``e`` per row, clamped, MIS-weighted) on paths ``path``: by their
        bounce weights, Direct after one bounce (the continued lobes' shares), Indirect after more
        (the whole mixture's), nothing before any."""
        b = self.bounces[path]
        rows = np.flatnonzero(b >= 1)
        if len(rows) == 0:
            return
        p, e, indirect = path[rows], e[rows], (b[rows] > 1).astype(np.int64)
        w = self.weights[p[:, None], 3 * (1 - indirect)[:, None] + np.arange(3)]
        for kind in range(3):
            np.add.at(self.split, (p, 2 * kind + indirect), e * w[:, kind])

    def passes(self, aux: dict):
        """The asked light passes of ``aux`` filled from ``split``."""
        for column, name in enumerate(COLUMNS):
            if name in aux:
                aux[name][:] = self.split[:, column]


@kernel(inline="always")
def add_split(split, p, d0, d1, d2, g0, g1, g2, t0, t1, t2, indirect):
    """A contribution of path p, (d*) diffuse, (g*) glossy and (t*) transmission, into ``split``'s
    direct or ``indirect`` columns."""
    split[p, indirect, 0] += d0
    split[p, indirect, 1] += d1
    split[p, indirect, 2] += d2
    split[p, 2 + indirect, 0] += g0
    split[p, 2 + indirect, 1] += g1
    split[p, 2 + indirect, 2] += g2
    split[p, 4 + indirect, 0] += t0
    split[p, 4 + indirect, 1] += t1
    split[p, 4 + indirect, 2] += t2


@kernel(inline="always")
def add_weighted(split, weights, p, c0, c1, c2):
    """Contribution (c0, c1, c2) of path p after its first bounce, split by its weights, Indirect."""
    add_split(split, p, c0 * weights[p, 0, 0], c1 * weights[p, 0, 1], c2 * weights[p, 0, 2],
              c0 * weights[p, 1, 0], c1 * weights[p, 1, 1], c2 * weights[p, 1, 2],
              c0 * weights[p, 2, 0], c1 * weights[p, 2, 1], c2 * weights[p, 2, 2], 1)


@kernel(inline="always")
def share(part, total):
    """Cycles' safe_divide of one channel: a share of ``total``, 0 where it is 0."""
    return part / total if total != 0.0 else 0.0


@kernel
def eval_parts(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, diffuse, unlit, sx, sy, sz, model,
               dx, dy, dz, skip):
    """core.bsdf.mixture.eval_lobes with the parts ``unlit`` leaves out (and lobe ``skip``, -1: none): a
    call, not inlined, so the kernels that split contributions by lobe kind hold one more copy of the
    mixture, not one per use."""
    return eval_lobes(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, 0, diffuse, unlit, sx, sy, sz,
                      model, dx, dy, dz, skip)


@kernel(inline="always")
def other_parts(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, diffuse, unlit, sx, sy, sz, model,
                dx, dy, dz, skip):
    """(Glossy RGB, Transmission RGB): the non-diffuse lobes' BSDF times |cos| toward wi without the
    parts ``unlit`` leaves out, each its own evaluation. A lobe's light on wo's side (``above``) is
    glossy, through the surface transmission; a hair lobe's goes by its closure whatever the side
    (core.bsdf.mixture.eval_lobes), so the other side's part is evaluated where the mixture has hair."""
    near = unlit | UNLIT_DIFFUSE | (UNLIT_TRANSMISSION if above else UNLIT_REFLECTION)
    f = eval_parts(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, diffuse, near, sx, sy, sz,
                   model, dx, dy, dz, skip)
    o0 = o1 = o2 = 0.0
    if has_hair(lp):
        far = unlit | UNLIT_DIFFUSE | (UNLIT_REFLECTION if above else UNLIT_TRANSMISSION)
        o = eval_parts(lp, lt, hp, r, mu, wox, woy, woz, wix, wiy, wiz, above, inside, sel, diffuse, far, sx, sy, sz,
                       model, dx, dy, dz, skip)
        o0, o1, o2 = o[3], o[4], o[5]
    if above:
        return f[3], f[4], f[5], o0, o1, o2
    return o0, o1, o2, f[3], f[4], f[5]
