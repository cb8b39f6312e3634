"""Voronoi texture as Cycles' SVM computes it (svm/voronoi.h): F1, F2, smooth F1, distance to
edge and n-sphere radius in 1 to 4 dimensions, four metrics, fractal octaves.

One loop serves every dimension: a point's coordinates are the first ``dims`` entries of
4-vectors, and the neighbouring cells are visited in Cycles' order (x fastest), which
matters for the order-dependent smooth F1 and for ties.
"""
from __future__ import annotations

import math

import numpy as np

from ...base.jit import kernel
from .hash import hash_to_color, hash_to_point, pcg_color, pcg_point

F1, F2, SMOOTH_F1, DISTANCE_TO_EDGE, N_SPHERE_RADIUS = 0, 1, 2, 3, 4
FEATURES = {"F1": F1, "F2": F2, "SMOOTH_F1": SMOOTH_F1, "DISTANCE_TO_EDGE": DISTANCE_TO_EDGE,
            "N_SPHERE_RADIUS": N_SPHERE_RADIUS}
EUCLIDEAN, MANHATTAN, CHEBYCHEV, MINKOWSKI = 0, 1, 2, 3
METRICS = {"EUCLIDEAN": EUCLIDEAN, "MANHATTAN": MANHATTAN, "CHEBYCHEV": CHEBYCHEV, "MINKOWSKI": MINKOWSKI}


@kernel
def _distance(dims, metric, exponent, a, b):
    """voronoi_distance; in 1D always |b - a| whatever the metric, as in Cycles."""
    if dims == 1:
        return abs(b[0] - a[0])
    total = 0.0
    for k in range(dims):
        d = abs(a[k] - b[k])
        if metric == EUCLIDEAN:
            total += d * d
        elif metric == MANHATTAN:
            total += d
        elif metric == CHEBYCHEV:
            total = max(total, d)
        else:
            total += d ** exponent
    if metric == EUCLIDEAN:
        return math.sqrt(total)
    if metric == MINKOWSKI:
        return total ** (1.0 / exponent)
    return total


@kernel
def _euclid(dims, a, b):
    total = 0.0
    for k in range(dims):
        total += (a[k] - b[k]) * (a[k] - b[k])
    return math.sqrt(total)


@kernel
def _cell_offset(dims, idx, base, off):
    """The ``idx``-th neighbour of a (base)^dims window, x fastest, centred on 0."""
    for k in range(dims):
        off[k] = float(idx % base - base // 2)
        idx //= base


@kernel
def _point(dims, pcg, randomness, cell, off, point):
    """The cell's random point relative to the current cell: offset + hash * randomness. Blender
    5.0 hashes integer cells with PCG in 2D to 4D (``pcg``); before, and in 1D, the float32 cell."""
    if pcg and dims > 1:
        h = pcg_point(dims, int(cell[0] + off[0]), int(cell[1] + off[1]), int(cell[2] + off[2]),
                      int(cell[3] + off[3]))
    else:
        h = hash_to_point(dims, cell[0] + off[0], cell[1] + off[1], cell[2] + off[2], cell[3] + off[3])
    for k in range(dims):
        point[k] = off[k] + h[k] * randomness
    return h


@kernel
def _color(dims, pcg, cell, off):
    if pcg and dims > 1:
        return pcg_color(dims, int(cell[0] + off[0]), int(cell[1] + off[1]), int(cell[2] + off[2]),
                         int(cell[3] + off[3]))
    return hash_to_color(dims, cell[0] + off[0], cell[1] + off[1], cell[2] + off[2], cell[3] + off[3])


@kernel
def _split(dims, coord, cell, local):
    for k in range(4):
        cell[k] = math.floor(coord[k]) if k < dims else 0.0
        local[k] = coord[k] - cell[k] if k < dims else 0.0


@kernel
def _f1_f2(dims, pcg, metric, exponent, randomness, second, coord, work, color, position):
    """F1 (or F2 when ``second``) of one octave: distance; colour and position written."""
    cell, local, off, point, off1, pos1, off2, pos2 = work[0], work[1], work[2], work[3], work[4], work[5], \
        work[6], work[7]
    _split(dims, coord, cell, local)
    d1 = np.inf
    d2 = np.inf
    for k in range(4):
        off1[k] = off2[k] = pos1[k] = pos2[k] = 0.0
    for idx in range(3 ** dims):
        _cell_offset(dims, idx, 3, off)
        _point(dims, pcg, randomness, cell, off, point)
        d = _distance(dims, metric, exponent, point, local)
        if d < d1:
            d2 = d1
            d1 = d
            for k in range(dims):
                off2[k], pos2[k] = off1[k], pos1[k]
                off1[k], pos1[k] = off[k], point[k]
        elif d < d2:
            d2 = d
            for k in range(dims):
                off2[k], pos2[k] = off[k], point[k]
    if second:
        color[0], color[1], color[2] = _color(dims, pcg, cell, off2)
        for k in range(4):
            position[k] = pos2[k] + cell[k]
        return d2
    color[0], color[1], color[2] = _color(dims, pcg, cell, off1)
    for k in range(4):
        position[k] = pos1[k] + cell[k]
    return d1


@kernel
def _smoothstep01(x):
    if x < 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return (3.0 - 2.0 * x) * (x * x)


@kernel
def _smooth_f1(dims, pcg, metric, exponent, randomness, smoothness, coord, work, color, position):
    cell, local, off, point, spos = work[0], work[1], work[2], work[3], work[4]
    _split(dims, coord, cell, local)
    sd = 0.0
    color[0] = color[1] = color[2] = 0.0
    for k in range(4):
        spos[k] = 0.0
    h = -1.0
    for idx in range(5 ** dims):
        _cell_offset(dims, idx, 5, off)
        r = _point(dims, pcg, randomness, cell, off, point)
        d = _distance(dims, metric, exponent, point, local)
        h = 1.0 if h == -1.0 else _smoothstep01(0.5 + 0.5 * (sd - d) / smoothness)
        corr = smoothness * h * (1.0 - h)
        sd = sd + h * (d - sd) - corr
        corr /= 1.0 + 3.0 * smoothness
        # PCG in 3D and 4D colours a cell with its point's own hash
        c = (r[0], r[1], r[2]) if pcg and dims >= 3 else _color(dims, pcg, cell, off)
        for k in range(3):
            color[k] = color[k] + h * (c[k] - color[k]) - corr
        for k in range(dims):
            spos[k] = spos[k] + h * (point[k] - spos[k]) - corr
    for k in range(4):
        position[k] = cell[k] + spos[k]
    return sd


@kernel
def _distance_to_edge(dims, pcg, randomness, coord, work, vectors):
    """``vectors`` (81, 4): scratch for the vectors to the neighbours' points, hashed once."""
    cell, local, off, point, closest, perp = work[0], work[1], work[2], work[3], work[4], work[5]
    _split(dims, coord, cell, local)
    if dims == 1:
        mid = hash_to_point(1, cell[0], 0.0, 0.0, 0.0)[0] * randomness
        left = -1.0 + hash_to_point(1, cell[0] - 1.0, 0.0, 0.0, 0.0)[0] * randomness
        right = 1.0 + hash_to_point(1, cell[0] + 1.0, 0.0, 0.0, 0.0)[0] * randomness
        return min(abs((mid + left) / 2.0 - local[0]), abs((mid + right) / 2.0 - local[0]))
    best = np.inf
    for idx in range(3 ** dims):
        _cell_offset(dims, idx, 3, off)
        _point(dims, pcg, randomness, cell, off, point)
        d = 0.0
        for k in range(dims):
            vectors[idx, k] = point[k] - local[k]
            d += vectors[idx, k] * vectors[idx, k]
        if d < best:
            best = d
            for k in range(dims):
                closest[k] = vectors[idx, k]
    best = np.inf
    for idx in range(3 ** dims):
        p2 = 0.0
        for k in range(dims):
            perp[k] = vectors[idx, k] - closest[k]
            p2 += perp[k] * perp[k]
        if p2 > 0.0001:
            length = math.sqrt(p2)
            edge = 0.0
            for k in range(dims):
                edge += (closest[k] + vectors[idx, k]) / 2.0 * (perp[k] / length)
            best = min(best, edge)
    return best


@kernel
def _n_sphere_radius(dims, pcg, randomness, coord, work):
    cell, local, off, point, closest, closest_off, other = work[0], work[1], work[2], work[3], work[4], \
        work[5], work[6]
    _split(dims, coord, cell, local)
    best = np.inf
    for k in range(4):
        closest[k] = closest_off[k] = other[k] = 0.0
    for idx in range(3 ** dims):
        _cell_offset(dims, idx, 3, off)
        _point(dims, pcg, randomness, cell, off, point)
        d = _euclid(dims, point, local)
        if d < best:
            best = d
            for k in range(dims):
                closest[k], closest_off[k] = point[k], off[k]
    best = np.inf
    centre = (3 ** dims) // 2
    for idx in range(3 ** dims):
        if idx == centre:
            continue
        _cell_offset(dims, idx, 3, off)
        for k in range(dims):
            off[k] += closest_off[k]
        _point(dims, pcg, randomness, cell, off, point)
        d = _euclid(dims, closest, point)
        if d < best:
            best = d
            for k in range(dims):
                other[k] = point[k]
    return _euclid(dims, other, closest) / 2.0


@kernel
def _max_distance(dims, metric, exponent, feature, randomness):
    """The distance normalisation: the farthest a feature point can be, per metric."""
    m = 0.5 + 0.5 * randomness
    if feature == DISTANCE_TO_EDGE:
        return m
    factor = 2.0 if feature == F2 else 1.0
    if dims == 1 or metric == CHEBYCHEV:
        return m * factor
    if metric == EUCLIDEAN:
        return math.sqrt(dims * m * m) * factor
    if metric == MANHATTAN:
        return dims * m * factor
    return (dims * m ** exponent) ** (1.0 / exponent) * factor


@kernel
def voronoi_texture(dims, feature, metric, normalize, pcg, vector, w_in, scale, detail, roughness, lacunarity,
                    smoothness, exponent, randomness):
    """Cycles' svm_node_tex_voronoi over all points:
    (distance (N,), colour (N, 3), position (N, 3), w (N,), radius (N,))."""
    n = len(scale)
    distance = np.zeros(n)
    color = np.zeros((n, 3))
    position = np.zeros((n, 3))
    w_out = np.zeros(n)
    radius = np.zeros(n)
    work = np.zeros((8, 4))
    vectors = np.zeros((81, 4))
    coord = np.zeros(4)
    scaled = np.zeros(4)
    oct_color = np.zeros(3)
    oct_pos = np.zeros(4)
    acc_color = np.zeros(3)
    acc_pos = np.zeros(4)
    for i in range(n):
        s = scale[i]
        if dims == 1:
            coord[0] = w_in[i] * s
        else:
            for k in range(3):
                coord[k] = vector[i, k] * s
            coord[3] = w_in[i] * s
        det = min(max(detail[i], 0.0), 15.0)
        rough = min(max(roughness[i], 0.0), 1.0)
        rnd = min(max(randomness[i], 0.0), 1.0)
        smooth = min(max(smoothness[i] / 2.0, 0.0), 0.5)
        lac = lacunarity[i]
        e = exponent[i]
        if feature == N_SPHERE_RADIUS:
            radius[i] = _n_sphere_radius(dims, pcg, rnd, coord, work)
            continue
        max_dist = _max_distance(dims, metric, e, feature, rnd)
        zero_input = det == 0.0 or rough == 0.0
        amp = 1.0
        octave_scale = 1.0
        if feature == DISTANCE_TO_EDGE:
            max_amp = max_dist
            dist = 8.0
            for octave in range(int(math.ceil(det)) + 1):
                for k in range(4):
                    scaled[k] = coord[k] * octave_scale
                od = _distance_to_edge(dims, pcg, rnd, scaled, work, vectors)
                if zero_input:
                    dist = od
                    break
                if octave <= det:
                    max_amp = max_amp + amp * (max_dist / octave_scale - max_amp)
                    dist = dist + amp * (min(dist, od / octave_scale) - dist)
                    octave_scale *= lac
                    amp *= rough
                else:
                    rem = det - math.floor(det)
                    if rem != 0.0:
                        lerp_amp = max_amp + amp * (max_dist / octave_scale - max_amp)
                        max_amp = max_amp + rem * (lerp_amp - max_amp)
                        lerp_dist = dist + amp * (min(dist, od / octave_scale) - dist)
                        dist = dist + rem * (min(dist, lerp_dist) - dist)
            distance[i] = dist / max_amp if normalize else dist
            continue
        max_amp = 0.0
        dist = 0.0
        for k in range(4):
            acc_pos[k] = 0.0
        for k in range(3):
            acc_color[k] = 0.0
        for octave in range(int(math.ceil(det)) + 1):
            for k in range(4):
                scaled[k] = coord[k] * octave_scale
            if feature == F2:
                od = _f1_f2(dims, pcg, metric, e, rnd, True, scaled, work, oct_color, oct_pos)
            elif feature == SMOOTH_F1 and smooth != 0.0:
                od = _smooth_f1(dims, pcg, metric, e, rnd, smooth, scaled, work, oct_color, oct_pos)
            else:
                od = _f1_f2(dims, pcg, metric, e, rnd, False, scaled, work, oct_color, oct_pos)
            if zero_input:
                max_amp = 1.0
                dist = od
                for k in range(3):
                    acc_color[k] = oct_color[k]
                for k in range(4):
                    acc_pos[k] = oct_pos[k]
                break
            if octave <= det:
                max_amp += amp
                dist += od * amp
                for k in range(3):
                    acc_color[k] += oct_color[k] * amp
                for k in range(4):
                    acc_pos[k] = acc_pos[k] + amp * (oct_pos[k] / octave_scale - acc_pos[k])
                octave_scale *= lac
                amp *= rough
            else:
                rem = det - math.floor(det)
                if rem != 0.0:
                    max_amp = max_amp + rem * amp
                    dist = dist + rem * (od * amp)
                    for k in range(3):
                        acc_color[k] = acc_color[k] + rem * (oct_color[k] * amp)
                    for k in range(4):
                        lerp_pos = acc_pos[k] + amp * (oct_pos[k] / octave_scale - acc_pos[k])
                        acc_pos[k] = acc_pos[k] + rem * (lerp_pos - acc_pos[k])
        if normalize:
            dist /= max_amp * max_dist
            for k in range(3):
                acc_color[k] /= max_amp
        distance[i] = dist
        for k in range(3):
            color[i, k] = acc_color[k]
        for k in range(4):
            acc_pos[k] = acc_pos[k] / s if s != 0.0 else 0.0
        if dims == 1:
            w_out[i] = acc_pos[0]
        else:
            for k in range(3):
                position[i, k] = acc_pos[k] if k < dims else 0.0
            w_out[i] = acc_pos[3] if dims == 4 else 0.0
    return distance, color, position, w_out, radius
