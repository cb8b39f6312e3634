"""Paths continued through one non-diffuse lobe, for a shader's hits in one kernel call: the lobe
chosen by its albedo and sampled (core.bsdf.mixture), the new throughput, the direction in the
world, the check that it leaves through the side of the geometric surface the lobe says, the
next ray's origin pushed off the surface, and (when a shader program reads Light Path) the path's
ray kind and depths after the bounce."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..bsdf.mixture import sample_lobes, selection
from ..geometry.accel import spawn_point
from ..shading.lightpath import DEPTH, GLOSSY, GLOSSY_DEPTH, KIND, REFLECT, SINGULAR, TRANSMISSION_DEPTH, TRANSMIT
from ..shading.lightpath import TRANSPARENT_DEPTH


@kernel
def continue_paths(lp, lt, hp, prow, mu, n_sampled, frame, wo_l, inside, u_select, u2, throughput, pos, ng, scale,
                   bounces, go, origin, wi, weight, prev_pdf, passthrough, transmit, next_bounces):
    """Per hit j: ``go[j]`` whether its path goes on; where it does, the next ray's ``origin`` and
    world direction ``wi``, the path's new throughput ``weight``, the density that sampled the
    direction (``prev_pdf``, inf for a delta lobe), whether the transparent lobe was taken, whether
    the ray crosses the surface and, when ``bounces`` has rows (core.shading.lightpath's kind and
    depths of the paths), ``next_bounces``: as Cycles' path_state_next, a transparent lobe keeps
    the kind and counts a transparent bounce; any other sets reflection or transmission, glossy,
    and singular for a delta lobe, and counts a bounce and a glossy (reflected) or transmission
    one. Shader and hits as core.integrator.direct has them."""
    sel = np.empty((1, max(n_sampled, 1)))
    for j in range(len(wo_l)):
        selection(lp, lt, hp, prow[j], mu, wo_l[j, 2], sel, 0)
        s = sample_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], u_select[j], u2[j, 0], u2[j, 1],
                         inside[j], sel, 0)
        t0, t1, t2 = throughput[j, 0] * s[3], throughput[j, 1] * s[4], throughput[j, 2] * s[5]
        peak = np.maximum(np.maximum(t0, t1), t2)
        go[j] = False
        if not (s[8] and peak > 0):
            continue
        x, y, z = s[0], s[1], s[2]
        wx = x * frame[j, 0, 0] + y * frame[j, 1, 0] + z * frame[j, 2, 0]
        wy = x * frame[j, 0, 1] + y * frame[j, 1, 1] + z * frame[j, 2, 1]
        wz = x * frame[j, 0, 2] + y * frame[j, 1, 2] + z * frame[j, 2, 2]
        # a sampled direction on the wrong side of the geometric surface would leak light
        crosses = z < 0
        if (wx * ng[j, 0] + wy * ng[j, 1] + wz * ng[j, 2] < 0) != crosses:
            continue
        go[j] = True
        origin[j, 0], origin[j, 1], origin[j, 2] = spawn_point(pos[j, 0], pos[j, 1], pos[j, 2], ng[j, 0], ng[j, 1],
                                                               ng[j, 2], wx, wy, wz, scale[j])
        wi[j, 0], wi[j, 1], wi[j, 2] = wx, wy, wz
        weight[j, 0], weight[j, 1], weight[j, 2] = t0, t1, t2
        prev_pdf[j] = np.inf if s[7] else s[6]
        passthrough[j], transmit[j] = s[9], crosses
        if len(bounces):
            next_bounces[j] = bounces[j]
            if s[9]:
                next_bounces[j, TRANSPARENT_DEPTH] += 1
            else:
                next_bounces[j, KIND] = (TRANSMIT if crosses else REFLECT) | GLOSSY | (SINGULAR if s[7] else 0)
                next_bounces[j, DEPTH] += 1
                next_bounces[j, TRANSMISSION_DEPTH if crosses else GLOSSY_DEPTH] += 1
