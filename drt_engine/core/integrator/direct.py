"""Next-event estimation of one material's hits in one kernel call.

For every hit and every light strategy: the BSDF toward the light sample, the power heuristic
against BSDF sampling, the shadow ray's origin (Cycles' terminator rule) and the ray itself,
traced in place through Embree; the light that gets through goes straight into the wave's
radiance. No shadow-ray records, no per-strategy Python, no gather and scatter between stages.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.jit import kernel
from ..bsdf.bump_shadowing import smooth_local
from ..bsdf.mixture import UNLIT_DIFFUSE, UNLIT_REFLECTION, UNLIT_TRANSMISSION, eval_lobes, selection
from ..geometry import embree
from ..geometry.accel import blocked, lift, spawn_point
from ..lights.strategies import NO_MIS, NO_SHADOW, UNRESTRICTED
from .bounces import lobe_choice, lobe_choices
from .clamp import clamped, limit_at
from .lightpasses import add_split, add_weighted, eval_parts, other_parts
from .mis import power
from .shadows import OPEN, SEE_THROUGH, enqueue, first_surface

TERMINATOR_CUTOFF = 0.1
"""Cosine below which shadow rays leave from the smooth surface (Cycles' default shadow
terminator geometry offset)."""

NOT_TRACED, BLOCKED, VISIBLE = -1, 0, 1
"""What became of the shadow ray of a hit and strategy (``visibility``, for the ratio estimator)."""


@kernel(inline="always")
def _positive(r, g, b):
    """Some channel above zero and none NaN (what ``max3(v) > 0`` says of a row)."""
    if r != r or g != g or b != b:
        return False
    return r > 0 or g > 0 or b > 0


@kernel(inline="always")
def shadow_origin(px, py, pz, gx, gy, gz, wx, wy, wz, cos_shading, lx, ly, lz, scale):
    """Shadow-ray origin: on the side of the surface the shading normal puts w, lifted by (lx, ly,
    lz) toward the smooth surface near the terminator (Cycles' rule, faded in by the cosines) so
    that light the shading normal sees is not cut off by the flat facet."""
    cos_geo = gx * wx + gy * wy + gz * wz
    c = TERMINATOR_CUTOFF
    if cos_shading < c:
        amount = min(max(2.0 - (cos_geo + cos_shading) / c, 0.0), 1.0)
    else:
        amount = min(max(1.0 - cos_geo / c, 0.0), 1.0)
    if not cos_shading > 0:
        amount = 0.0
    side = 1.0 if cos_shading > 0 else -1.0
    return spawn_point(px + lx * amount, py + ly * amount, pz + lz * amount, gx, gy, gz, side * gx, side * gy,
                       side * gz, scale)


@kernel(inline="always")
def _aim(x, y, z):
    """Unit direction and length of (x, y, z)."""
    d = math.sqrt(x * x + y * y + z * z)
    inv = 1.0 / max(d, 1e-300)
    return x * inv, y * inv, z * inv, d


@kernel(inline="always")
def unlit_parts(restrict, k):
    """The BSDF parts strategy k does not light (mixture's ``UNLIT_*`` bits) from its ``restrict`` row."""
    if restrict[k, 0] == UNRESTRICTED:
        return 0
    return ((UNLIT_DIFFUSE if restrict[k, 0] == 0 else 0) | (UNLIT_REFLECTION if restrict[k, 1] == 0 else 0)
            | (UNLIT_TRANSMISSION if restrict[k, 2] == 0 else 0))


@kernel
def direct_light(lp, lt, hp, prow, mu, n_sampled, pos, ng, frame, smooth, dn, wo_l, inside, scale, throughput, path,
                 limit, bounces, diffuse_limit, continues, geo, prim, u, v, lifted, wi, dist, value, pdf, cycles_pdf, stop,
                 restrict,
                 exclude, group, masks, scene, center, shadow_mask, times, radiance, grouped, split, weights,
                 passed, f_diff, visibility, cuts, clear, allowed, qf, qi):
    """Adds every hit's unblocked direct light to ``radiance[path[j]]``, each strategy's clamped to
    ``limit[j]`` (core.integrator.clamp); returns the shadow rays traced and the rows queued.

    Shader: the packed lobes (lp, lt, hp, per-hit rows prow, mu; bsdf.layout). Hits: world
    position, geometric normal (facing the ray), shading frame (N, 3, 3: tangent, bitangent,
    normal rows), the smooth normal a bump replaced (empty: none, bsdf.bump_shadowing), the diffuse
    lobes' normal in that frame (bsdf.diffuse_normal), wo in that frame, inside, offset scale,
    throughput, path, the paths' depths and
    the diffuse bounces (the diffuse lobes paths continue through are weighed against sampling
    them, integrator.bounces; the others are light-sampled alone), whether any ray ``continues``
    from these hits (at the last depth none does: light sampling alone finds all their light,
    no share is left to rays that are never traced), and the triangle and
    barycentrics on the geometry tables ``geo``, for the terminator lift where ``lifted``
    (core.geometry.accel.lift).
    Light samples, strategy by hit: direction, distance, value (radiance / pdf), pdf, the pdf
    Cycles' light sampling has (``cycles_pdf``, lights.strategies), distance to stop short of an
    emitter that is geometry, the BSDF parts each strategy lights
    (``restrict``) and what each sample's light leaves out (``exclude``, lights.strategies: BSDF
    parts, and its shadow ray with NO_SHADOW; empty: nothing) and each sample's light group
    (``group``; empty: no light groups): what gets through is added to ``grouped[path[j], group]``
    as well (core.integrator.lightgroups; no group: -1), and to the light passes' ``split`` (empty: none;
    core.integrator.lightpasses): at a path's first hit (``passed[path[j]]``, its bounces, 0) by the
    diffuse lobes' and the other lobes' reflection's shares of the BSDF toward the sample, Direct; later
    by the path's ``weights``, Indirect. Shadow rays see the objects whose
    Embree mask shares a bit with ``shadow_mask``, or with each sample's ``masks`` row (shadow
    linking; empty: none), and a sample whose light is light sampling's alone (``NO_MIS`` in
    ``exclude``) takes its whole weight. ``times``: each hit's shutter time (empty when
    nothing moves).
    ``f_diff``, ``visibility`` and ``cuts`` (strategy by hit) are filled when they have rows (the
    ratio estimator reads them): the diffuse part toward each sample, what became of its ray and
    the clamp's factor on what got through.
    With transparent shadows (``clear``, per mesh triangle row: its material can be transparent;
    empty: none can, and shadow rays are occlusion queries), a ray stopped by such a surface is
    queued in (``qf``, ``qi``) with its contribution, if hit j's rays may pass ``allowed[j]`` > 0
    surfaces (core.integrator.shadows).

    A sample on the wrong side of the geometric surface for the lobes that light it (reflection
    below it, near a smooth rim, or transmission above it) takes the power heuristic against every
    lobe's density, diffuse ones included, at Cycles' light density, whatever DRT continues
    through: Cycles drops BSDF samples there (bsdf_diffuse_sample, bsdf_microfacet_sample) but
    weighs its light samples against them all the same, so there the light sample's MIS share is
    all the light Cycles finds. Unweighed, the rim of a smooth diffuse cylinder under a white world
    was 0.126 off Cycles in its worst block.
    """
    rayhit = embree.new_rayhit()
    scratch = np.empty((2, 3, 4))
    choices = lobe_choices(lp, n_sampled)
    sel_rim = np.empty((1, max(lp.shape[0], 1)))
    keep = f_diff.shape[1] > 0
    see_through = len(clear) > 0
    excluding = exclude.size > 0
    grouping = group.size > 0
    splitting = split.shape[0] > 0
    masking = masks.size > 0
    traced = queued = 0
    for j in range(len(pos)):
        first = splitting and passed[path[j]] == 0
        sel, diffuse_on = lobe_choice(lp, lt, hp, prow[j], mu, wo_l[j, 2], choices, bounces, j, diffuse_limit)
        time = times[j] if len(times) else 0.5
        sx, sy, sz, model = smooth_local(smooth, frame, j)
        hx = hy = hz = 0.0
        if lifted:
            hx, hy, hz = lift(geo, prim[j], u[j], v[j], time, scratch)
        s0 = s1 = s2 = 0.0
        rim_selected = False
        for k in range(wi.shape[0]):
            if keep:
                visibility[k, j] = NOT_TRACED
            v0, v1, v2 = value[k, j, 0], value[k, j, 1], value[k, j, 2]
            if not _positive(v0, v1, v2):
                continue
            wx, wy, wz = wi[k, j, 0], wi[k, j, 1], wi[k, j, 2]
            left_out = exclude[k, j] if excluding else 0
            lx = wx * frame[j, 0, 0] + wy * frame[j, 0, 1] + wz * frame[j, 0, 2]
            ly = wx * frame[j, 1, 0] + wy * frame[j, 1, 1] + wz * frame[j, 1, 2]
            lz = wx * frame[j, 2, 0] + wy * frame[j, 2, 1] + wz * frame[j, 2, 2]
            cd = lx * dn[j, 0] + ly * dn[j, 1] + lz * dn[j, 2]
            above = cd > 0  # the shading hemisphere decides, as in Cycles (of sd->N), not the facet
            f = eval_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], lx, ly, lz, above,
                           inside[j], sel, 0, diffuse_on, unlit_parts(restrict, k) | (left_out & ~(NO_SHADOW | NO_MIS)),
                           sx, sy, sz, model, dn[j, 0], dn[j, 1], dn[j, 2], -1)
            d0, d1, d2, n0, n1, n2 = f[0], f[1], f[2], f[3], f[4], f[5]
            if keep:
                f_diff[k, j, 0], f_diff[k, j, 1], f_diff[k, j, 2] = d0, d1, d2
            w = power(pdf[k, j], f[6]) if continues and not left_out & NO_MIS else 1.0
            wd = 1.0  # the diffuse lobes light-sampled alone take it all, but on the wrong side
            if (wx * ng[j, 0] + wy * ng[j, 1] + wz * ng[j, 2] < 0.0) == above and not left_out & NO_MIS:
                if not rim_selected:
                    selection(lp, lt, hp, prow[j], mu, wo_l[j, 2], sel_rim, 0, True)
                    rim_selected = True
                every = eval_lobes(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], lx, ly, lz, above,
                                   inside[j], sel_rim, 0, True, 0, sx, sy, sz, model,
                                   dn[j, 0], dn[j, 1], dn[j, 2], -1)
                w = wd = power(cycles_pdf[k, j], every[6])
            mask = masks[k, j] if masking else shadow_mask
            c0 = throughput[j, 0] * v0 * (d0 * wd + n0 * w)
            c1 = throughput[j, 1] * v1 * (d1 * wd + n1 * w)
            c2 = throughput[j, 2] * v2 * (d2 * wd + n2 * w)
            if not _positive(c0, c1, c2):
                continue
            e0 = e1 = e2 = h0 = h1 = h2 = t0 = t1 = t2 = 0.0  # diffuse, glossy, transmission, at a first hit
            if first:
                unlit = unlit_parts(restrict, k) | (left_out & ~(NO_SHADOW | NO_MIS))
                fd = eval_parts(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], lx, ly, lz, above,
                                inside[j], sel, diffuse_on, unlit | UNLIT_REFLECTION | UNLIT_TRANSMISSION, sx, sy, sz,
                                model, dn[j, 0], dn[j, 1], dn[j, 2], np.int64(-1))
                e0 = throughput[j, 0] * v0 * (fd[0] * wd + fd[3] * w)
                e1 = throughput[j, 1] * v1 * (fd[1] * wd + fd[4] * w)
                e2 = throughput[j, 2] * v2 * (fd[2] * wd + fd[5] * w)
                # the other lobes' glossy and transmission parts, each its own evaluation, exactly 0
                # where the BSDF has none
                fo = other_parts(lp, lt, hp, prow[j], mu, wo_l[j, 0], wo_l[j, 1], wo_l[j, 2], lx, ly, lz, above,
                                 inside[j], sel, diffuse_on, unlit, sx, sy, sz, model, dn[j, 0], dn[j, 1], dn[j, 2],
                                 np.int64(-1))
                h0, h1, h2 = throughput[j, 0] * v0 * fo[0] * w, throughput[j, 1] * v1 * fo[1] * w, \
                    throughput[j, 2] * v2 * fo[2] * w
                t0, t1, t2 = throughput[j, 0] * v0 * fo[3] * w, throughput[j, 1] * v1 * fo[4] * w, \
                    throughput[j, 2] * v2 * fo[5] * w
            ox, oy, oz = shadow_origin(pos[j, 0], pos[j, 1], pos[j, 2], ng[j, 0], ng[j, 1], ng[j, 2], wx, wy, wz, cd,
                                       hx, hy, hz, scale[j])
            tmax = math.inf
            if not math.isinf(dist[k, j]):
                # aimed at the sampled point from where the ray starts: the offset and the lift
                # moved the origin, and a ray parallel to wi meets a mesh light's surface short of
                # the point by offset / cosine (every grazing sample of an emissive panel was blocked)
                wx, wy, wz, d = _aim(pos[j, 0] + wx * dist[k, j] - ox, pos[j, 1] + wy * dist[k, j] - oy,
                                     pos[j, 2] + wz * dist[k, j] - oz)
                tmax = max(d * (1.0 - 1e-6) - stop[k, j], 0.0)
            if left_out & NO_SHADOW:
                hidden = False
            elif see_through:
                traced += 1
                what, hit, t, hu, hv = first_surface(scene, geo, clear, rayhit, scratch, ox, oy, oz, wx, wy, wz,
                                                     tmax, time, mask)
                hidden = what != OPEN
                if what == SEE_THROUGH and allowed[j] > 0:
                    enqueue(qf, qi, queued, c0, c1, c2, ox, oy, oz, wx, wy, wz, tmax, time, hu, hv, t, path[j], hit,
                            j, 0, allowed[j], group[k, j] if grouping else -1, mask)
                    queued += 1
            else:
                traced += 1
                hidden = blocked(scene, center, rayhit, ox, oy, oz, wx, wy, wz, tmax, time, mask)
            if keep:
                visibility[k, j] = BLOCKED if hidden else VISIBLE
            # area lights are not geometry: a nearer area light does not block (lights cast shadows
            # of each other's bodies in Cycles only when they are meshes, so it does not here)
            if not hidden:  # each strategy's light one contribution, clamped to its hit's ``limit``
                c0, c1, c2, cut = clamped(c0, c1, c2, limit_at(limit, j))
                if cuts.shape[1] > 0:  # the ratio estimator's N stays the share of Combined it is
                    cuts[k, j] = cut
                s0 += c0
                s1 += c1
                s2 += c2
                if grouping and group[k, j] >= 0:
                    g = group[k, j]
                    grouped[path[j], g, 0] += c0
                    grouped[path[j], g, 1] += c1
                    grouped[path[j], g, 2] += c2
                if first:
                    add_split(split, path[j], e0 * cut, e1 * cut, e2 * cut, h0 * cut, h1 * cut, h2 * cut, t0 * cut,
                              t1 * cut, t2 * cut, 0)
                elif splitting:
                    add_weighted(split, weights, path[j], c0, c1, c2)
        p = path[j]
        radiance[p, 0] += s0
        radiance[p, 1] += s1
        radiance[p, 2] += s2
    return traced, queued
