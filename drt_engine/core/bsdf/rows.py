"""Batch loops over a wave's arrays: each runs one scalar function of ``mixture``, ``passes`` or
``tables`` per ray, reading ray i's per-hit row ``hp[prow[i]]``; ``shader.MaterialShader`` calls them."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from .mixture import eval_lobes, sample_lobes, selection
from .passes import colours, denoising_albedos, transmission_colour, transparency
from .tables import lobe_scale, locate, ms_factor


@kernel
def selection_rows(lp, lt, hp, prow, mu, mu_o, out):
    for i in range(len(mu_o)):
        selection(lp, lt, hp, prow[i], mu, mu_o[i], out, i, False)


@kernel
def evaluate_rows(lp, lt, hp, prow, mu, wo, wi, above, inside, sel, f_diff, f_nd, pdf):
    for i in range(len(wo)):
        v = eval_lobes(lp, lt, hp, prow[i], mu, wo[i, 0], wo[i, 1], wo[i, 2], wi[i, 0], wi[i, 1], wi[i, 2],
                       above[i], inside[i], sel, i, False, 0, 0.0, 0.0, 1.0, 0, 0.0, 0.0, 1.0, -1)
        f_diff[i, 0], f_diff[i, 1], f_diff[i, 2] = v[0], v[1], v[2]
        f_nd[i, 0], f_nd[i, 1], f_nd[i, 2] = v[3], v[4], v[5]
        pdf[i] = v[6]


@kernel
def sample_rows(lp, lt, hp, prow, mu, wo, u_select, u2, inside, wi, weight, pdf, delta, valid, passthrough,
                n_sampled):
    sel = np.empty((1, n_sampled))
    for i in range(len(wo)):
        selection(lp, lt, hp, prow[i], mu, wo[i, 2], sel, 0, False)
        v = sample_lobes(lp, lt, hp, prow[i], mu, wo[i, 0], wo[i, 1], wo[i, 2], u_select[i], u2[i, 0], u2[i, 1],
                         inside[i], sel, 0, False, 0.0, 0.0, 1.0, 0, 0.0, 0.0, 1.0)
        wi[i, 0], wi[i, 1], wi[i, 2] = v[0], v[1], v[2]
        weight[i, 0], weight[i, 1], weight[i, 2] = v[3], v[4], v[5]
        pdf[i], delta[i], valid[i], passthrough[i] = v[6], v[7], v[8], v[9]


@kernel
def colours_rows(lp, lt, hp, prow, mu, mu_o, diff, gloss):
    for i in range(len(mu_o)):
        v = colours(lp, lt, hp, prow[i], mu, mu_o[i])
        diff[i, 0], diff[i, 1], diff[i, 2] = v[0], v[1], v[2]
        gloss[i, 0], gloss[i, 1], gloss[i, 2] = v[3], v[4], v[5]


@kernel
def transmission_rows(lp, lt, hp, prow, mu, mu_o, out):
    for i in range(len(mu_o)):
        out[i, 0], out[i, 1], out[i, 2] = transmission_colour(lp, lt, hp, prow[i], mu, mu_o[i])


@kernel
def denoising_rows(lp, lt, hp, prow, mu, mu_o, inside, diff, spec, take):
    for i in range(len(mu_o)):
        v = denoising_albedos(lp, lt, hp, prow[i], mu, mu_o[i], inside[i])
        diff[i, 0], diff[i, 1], diff[i, 2] = v[0], v[1], v[2]
        spec[i, 0], spec[i, 1], spec[i, 2] = v[3], v[4], v[5]
        take[i] = v[6]


@kernel
def transparency_rows(lp, lt, hp, prow, mu, mu_o, out):
    for i in range(len(mu_o)):
        out[i, 0], out[i, 1], out[i, 2] = transparency(lp, lt, hp, prow[i], mu, mu_o[i])


@kernel
def weights_rows(lp, lt, hp, prow, mu, mu_o, out):
    """(N, L, 3) weight of each lobe: scale times its multiple-scattering factor."""
    for i in range(len(mu_o)):
        j, t = locate(mu, mu_o[i])
        for l in range(lp.shape[0]):
            s0, s1, s2 = lobe_scale(lp, lt, hp, prow[i], j, t, l)
            ms = ms_factor(lp, lt, hp, prow[i], j, t, l)
            out[i, l, 0], out[i, l, 1], out[i, l, 2] = s0 * ms, s1 * ms, s2 * ms
