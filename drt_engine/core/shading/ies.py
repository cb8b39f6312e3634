"""IES Texture: a luminaire's measured intensity per direction, as Cycles reads and looks it up.

``parse`` reads an IESNA LM-63 photometric file the way Cycles' IESFile does (util/ies.cpp):
the numbers after ``TILT=`` (tilt data skipped), candelas times the candela multiplier, ballast
and ballast-lamp factors, converted to Cycles' watts by 4 pi / 177.83 (D65's luminous
efficacy); types A, B and C turned into type C's angles (vertical from the nadir 0 to 180
degrees, horizontal 0 to 360, symmetric halves and quadrants mirrored). What Cycles cannot
read gives None.

``lookup`` is svm_node_ies with kernel_ies_interp (kernel/util/ies.h): the direction's vertical
angle acos(-z) and horizontal angle atan2(x, y) + pi, Catmull-Rom cubic along the vertical
angles, then along the horizontal ones (wrapped where the table covers the whole circle),
clamped at 0; zero outside the table's angles.
"""
from __future__ import annotations

import math
import re

import numpy as np

from ..base.jit import kernel

CANDELA_TO_WATT = 0.0706650768394
"""Cycles' 4 pi / 177.83: candela to its light strength, assuming a D65 spectrum."""
TYPE_C, TYPE_B, TYPE_A = 1, 2, 3
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
UNREADABLE = 100.0
"""What Cycles' lookup gives for a profile it could not read (kernel_ies_interp's empty slot)."""


def parse(text: str):
    """(horizontal angles (H,), vertical angles (V,), intensity (H, V)) in radians and Cycles'
    watts, or None where Cycles' IESFile::load fails."""
    start = text.find("\nTILT=")
    if start < 0:
        return None
    body = text[start:].replace(",", " ")
    if body.startswith("\nTILT=INCLUDE"):
        numbers = _numbers(body[13:])
        if numbers is None or len(numbers) < 2:
            return None
        skip = 2 + 2 * int(numbers[1])
        numbers = numbers[skip:]
    else:
        line_end = body.find("\n", 1)
        if line_end < 0:
            return None
        numbers = _numbers(body[line_end + 1:])
    if numbers is None or len(numbers) < 13:
        return None
    factor = numbers[2] * numbers[10] * numbers[11] * CANDELA_TO_WATT
    v_num, h_num, kind = int(numbers[3]), int(numbers[4]), int(numbers[5])
    if kind not in (TYPE_A, TYPE_B, TYPE_C) or v_num <= 0 or h_num <= 0:
        return None
    data = numbers[13:]
    if len(data) < v_num + h_num + v_num * h_num:
        return None
    v = np.array(data[:v_num], np.float32)
    h = np.array(data[v_num:v_num + h_num], np.float32)
    grid = (factor * np.array(data[v_num + h_num:v_num + h_num + h_num * v_num])).astype(np.float32)
    h, v, rows = _process(kind, list(h), list(v), [list(r) for r in grid.reshape(h_num, v_num)])
    return (np.radians(np.array(h, np.float64)).astype(np.float32).astype(np.float64),
            np.radians(np.array(v, np.float64)).astype(np.float32).astype(np.float64),
            np.array(rows, np.float64))


def _numbers(text):
    """The whitespace-separated numbers of ``text`` up to the first that is none (strtod's reading)."""
    out = []
    for word in text.split():
        match = _NUMBER.match(word)
        if match is None:
            break
        out.append(float(match.group()))
        if match.end() != len(word):
            break
    return out


def _close(a, b):
    return abs(a - b) < 1e-4


def _process(kind, h, v, rows):
    """Cycles' process_type_a / _b / _c: every type to type C's angles, in degrees."""
    if kind == TYPE_A:
        v = [a + 90.0 for a in v]
        new_h = [180.0 - a for a in reversed(h)]
        new_rows = list(reversed(rows))
        if _close(h[0], 0.0):
            new_h += [180.0 + a for a in h[1:]]
            new_rows += rows[1:]
        return new_h, v, new_rows
    if kind == TYPE_B:  # the polar axis horizontal: angles swapped, as Cycles does
        rows = [list(col) for col in zip(*rows)]
        h, v = v, h
        if _close(h[0], 0.0):
            rows = rows[:0:-1] + rows
            h = [90.0 - a for a in h[:0:-1]] + [90.0 + a for a in h]
        else:
            h = [a + 90.0 for a in h]
        if _close(v[0], 0.0):
            rows = [r[:0:-1] + r for r in rows]
            v = [90.0 - a for a in v[:0:-1]] + [90.0 + a for a in v]
        else:
            v = [a + 90.0 for a in v]
        return h, v, rows
    if _close(h[0], 90.0):
        h = [a - 90.0 for a in h]
    if len(h) == 1:
        h, rows = [0.0, 360.0], [rows[0], rows[0]]
    if _close(h[-1], 90.0):
        h, rows = h + [180.0 - a for a in h[-2::-1]], rows + rows[-2::-1]
    if _close(h[-1], 180.0):
        h, rows = h + [360.0 - a for a in h[-2::-1]], rows + rows[-2::-1]
    if _close(h[0], 0.0) and not _close(h[-1], 360.0):
        gap = 360.0 - h[-1]
        if _close(h[-1] - h[-2], gap) or _close(h[1] - h[0], gap):
            h, rows = h + [360.0], rows + [rows[0]]
    return h, v, rows


@kernel(inline="always")
def _cubic(a, b, c, d, x):
    return 0.5 * (((d + 3.0 * (b - c) - a) * x + (2.0 * a - 5.0 * b + 4.0 * c - d)) * x + (c - a)) * x + b


@kernel(inline="always")
def _vertical(grid, wrap_low, wrap_high, vi, v_frac, hi):
    """Along the vertical angles at horizontal index hi; the ends held, or taken across the pole."""
    v_num = grid.shape[1]
    b, c = grid[hi, vi], grid[hi, vi + 1]
    a = grid[hi, vi - 1] if vi > 0 else (grid[hi, 1] if wrap_low else b)
    d = grid[hi, vi + 2] if vi + 2 < v_num else (grid[hi, v_num - 2] if wrap_high else c)
    return _cubic(a, b, c, d, v_frac)


@kernel(inline="always")
def interpolate(h_angles, v_angles, grid, h, v):
    """kernel_ies_interp at horizontal angle h and vertical angle v (radians)."""
    h_num, v_num = len(h_angles), len(v_angles)
    if v < v_angles[0] or v >= v_angles[v_num - 1] or h < h_angles[0] or h >= h_angles[h_num - 1]:
        return 0.0
    wrap_h = h_angles[0] < 1e-7 and h_angles[h_num - 1] > 2.0 * math.pi - 1e-7
    wrap_low = v_angles[0] < 1e-7
    wrap_high = v_angles[v_num - 1] > math.pi - 1e-7
    hi = 0
    while h_angles[hi + 1] < h:
        hi += 1
    vi = 0
    while v_angles[vi + 1] < v:
        vi += 1
    h_frac = (h - h_angles[hi]) / (h_angles[hi + 1] - h_angles[hi])
    v_frac = (v - v_angles[vi]) / (v_angles[vi + 1] - v_angles[vi])
    b = _vertical(grid, wrap_low, wrap_high, vi, v_frac, hi)
    c = _vertical(grid, wrap_low, wrap_high, vi, v_frac, hi + 1)
    a = b
    if hi > 0:
        a = _vertical(grid, wrap_low, wrap_high, vi, v_frac, hi - 1)
    elif wrap_h:
        a = _vertical(grid, wrap_low, wrap_high, vi, v_frac, h_num - 2)
    d = b
    if hi + 2 < h_num:
        d = _vertical(grid, wrap_low, wrap_high, vi, v_frac, hi + 2)
    elif wrap_h:
        d = _vertical(grid, wrap_low, wrap_high, vi, v_frac, 1)
    return max(_cubic(a, b, c, d, h_frac), 0.0)


@kernel
def _lookup(h_angles, v_angles, grid, vectors, strength, out):
    for j in range(len(vectors)):
        x, y, z = vectors[j, 0], vectors[j, 1], vectors[j, 2]
        length = math.sqrt(x * x + y * y + z * z)
        if not length > 0:
            out[j] = 0.0
            continue
        v = math.acos(min(max(-z / length, -1.0), 1.0))
        h = math.atan2(x / length, y / length) + math.pi
        out[j] = strength[j] * interpolate(h_angles, v_angles, grid, h, v)


def lookup(profile, vectors: np.ndarray, strength: np.ndarray) -> np.ndarray:
    """The node's Fac at ``vectors`` (N, 3) with ``strength`` (N,): ``profile`` from ``parse``,
    or None (unreadable: Cycles' constant ``UNREADABLE``)."""
    strength = np.ascontiguousarray(np.broadcast_to(strength, (len(vectors),)), np.float64)
    if profile is None:
        return UNREADABLE * strength
    out = np.empty(len(vectors))
    h, v, grid = profile
    _lookup(h, v, grid, np.ascontiguousarray(vectors, np.float64), strength, out)
    return out
