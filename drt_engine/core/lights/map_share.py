"""How many of a world's light samples its map draws, the rest cosine-weighted about the shading
normal: chosen per world, since no one share suits every world.

The map's density follows the world's brightness over the whole sphere; a diffuse surface wants
brightness times its cosine over its own hemisphere. Measured on the irradiance of an upward
diffuse surface (20,000 samples of the one-sample mixture): under a Preetham sky with the sun at
the zenith the map alone had 62x the variance of cosine sampling and the old fixed share of 0.75
28x (half the map's directions lie under the surface, the rest crowd round the bright zenith);
under Blender 5's Multiple Scattering sky with its sun disc a share of 0.25 had 12x the variance
of 0.75 (the map's cone finds the sun); Blender's own studio-light HDRIs do best at 0.75 to 0.9
(sunset.exr at 0.5). So each world takes, of ``CANDIDATES``, the share whose mixture has the least
variance summed over diffuse surfaces facing the six axes (so the brightly lit ones weigh most),
estimated once from ``SAMPLES`` directions of each strategy, all of them weighed as draws of the
even mixture (the map's rare bright directions, a sun, count at their true weight).

That is the variance of one sample; DRT's stratified samples lower each strategy's differently
(a diffuse floor under the zenith sky, 16 x 16 pixels, pixel variance over four seeds at 1, 16 and
64 spp: share 0.1 0.030, 1.1e-3, 7.6e-5; 0.75 0.35, 2.0e-3, 2.2e-4; the map alone 0.70, 1.5e-3,
2.0e-5), so the choice is a good share, not always the best one.
"""
from __future__ import annotations

import numpy as np

from ..base.colour import LUMINANCE

CANDIDATES = np.array([0.1, 0.25, 0.5, 0.75, 0.9])
"""Map shares to choose from: each strategy keeps at least a tenth of the samples."""
SAMPLES = 4096
AXES = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
                 [0.0, -1.0, 0.0]])


def _cosine_directions(u: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Cosine-weighted directions about the unit ``axis`` (one of AXES) for 2D samples u."""
    r, phi = np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
    t0 = np.roll(axis, 1)  # perpendicular to an axis vector
    t1 = np.cross(axis, t0)
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1.0 - u[:, 0], 0.0))], axis=1)
    return local @ np.stack([t0, t1, axis])


def calibrated_share(env) -> float:
    """The map share for ``env`` (lights.environment.Environment): the candidate of least summed
    variance, for the same world the same share (fixed seed)."""
    rng = np.random.default_rng(0)
    map_dirs, _ = env.sample(rng.random((SAMPLES, 2)))
    map_lum = env.radiance(map_dirs) @ LUMINANCE
    variance = np.zeros(len(CANDIDATES))
    for axis in AXES:
        cos_dirs = _cosine_directions(rng.random((SAMPLES, 2)), axis)
        dirs = np.concatenate([map_dirs, cos_dirs])
        cos = np.maximum(dirs @ axis, 0.0)
        f = np.concatenate([map_lum, env.radiance(cos_dirs) @ LUMINANCE]) * cos
        p_map, p_cos = env.pdf(dirs), cos / np.pi
        q = 0.5 * (p_map + p_cos)  # the density all 2 x SAMPLES directions were drawn from
        lit = f > 0
        if not lit.any():
            continue
        f, p_map, p_cos, q = f[lit], p_map[lit], p_cos[lit], q[lit]
        total = (f / q).sum() / len(dirs)
        for i, share in enumerate(CANDIDATES):
            variance[i] += (f * f / ((share * p_map + (1.0 - share) * p_cos) * q)).sum() / len(dirs) - total * total
    return float(CANDIDATES[np.argmin(variance)])
