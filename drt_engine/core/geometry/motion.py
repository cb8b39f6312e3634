"""Transforms over the shutter, interpolated at each ray's own time.

Matrices sampled at S evenly spaced shutter times are decomposed once into
translation, rotation (a quaternion) and the remaining stretch (polar decomposition),
then interpolated per ray piecewise between steps: translation and stretch linearly,
rotation by slerp. A spinning object keeps its size, and several steps keep curved
paths curved.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.constants import TINY
from ..base.jit import kernel


def _quat_from_matrix(r: np.ndarray) -> np.ndarray:
    """(S, 3, 3) proper rotations to (S, 4) unit quaternions (w, x, y, z)."""
    out = np.empty((len(r), 4))
    for k, m in enumerate(r):
        tr = np.trace(m)
        if tr > 0:
            s = np.sqrt(tr + 1.0) * 2
            q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
        else:
            i = int(np.argmax(np.diag(m)))
            j, l = (i + 1) % 3, (i + 2) % 3
            s = np.sqrt(1.0 + m[i, i] - m[j, j] - m[l, l]) * 2
            q = np.zeros(4)
            q[0] = (m[l, j] - m[j, l]) / s
            q[1 + i] = 0.25 * s
            q[1 + j] = (m[j, i] + m[i, j]) / s
            q[1 + l] = (m[l, i] + m[i, l]) / s
        out[k] = q
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def quaternions(rotations: np.ndarray) -> np.ndarray:
    """(S, 3, 3) proper rotations to (S, 4) unit quaternions (w, x, y, z), each on the shorter arc
    from the one before: what slerp between consecutive steps needs."""
    q = _quat_from_matrix(rotations)
    for k in range(1, len(q)):
        if np.dot(q[k], q[k - 1]) < 0:
            q[k] = -q[k]
    return q


def _polar(m3: np.ndarray):
    """m3 = R @ P with R a proper rotation and P symmetric (it carries any mirroring)."""
    u, s, vt = np.linalg.svd(m3)
    d = np.sign(np.linalg.det(u @ vt))
    fix = np.ones((len(m3), 3))
    fix[:, 2] = d
    r = (u * fix[:, None, :]) @ vt
    p = np.transpose(vt, (0, 2, 1)) @ ((s * fix)[:, :, None] * vt)
    return r, p


def moves(matrices: np.ndarray) -> bool:
    """Whether transforms over the shutter (S, 4, 4) differ at all (to 1e-12)."""
    return len(matrices) > 1 and not np.allclose(matrices, matrices[:1], rtol=0, atol=1e-12)


def deforms(mesh) -> bool:
    """Whether a mesh's vertices move over the shutter (its ``motion_vertices`` differ)."""
    steps = mesh.motion_vertices
    return steps is not None and not np.allclose(steps, steps[:1])


class Motion:
    """Object-to-world transforms over the shutter (S >= 1 steps)."""

    def __init__(self, matrices: np.ndarray):
        matrices = np.asarray(matrices, dtype=np.float64).reshape(-1, 4, 4)
        self.steps = len(matrices)
        self.translation = np.ascontiguousarray(matrices[:, :3, 3])  # the kernels' one layout
        self.linear = matrices[:, :3, :3]
        rotation, self.stretch = _polar(self.linear)
        self.quat = quaternions(rotation)
        self.moving = moves(matrices)

    @property
    def table(self):
        """What ``frame_at`` takes before the time: the steps' translation, quaternion, stretch."""
        if not self.moving:  # one step: every time gets it
            return self.translation[:1], self.quat[:1], self.stretch[:1]
        return self.translation, self.quat, self.stretch

    def at(self, time: np.ndarray):
        """Per-ray (linear (N, 3, 3), translation (N, 3)) at shutter fractions in [0, 1]."""
        n = len(time)
        if not self.moving:
            return np.broadcast_to(self.linear[0], (n, 3, 3)), np.broadcast_to(self.translation[0], (n, 3))
        frames = np.empty((n, 3, 4))
        _frames(*self.table, np.asarray(time, dtype=np.float64), frames)
        return frames[:, :, :3], frames[:, :, 3]

    def matrix_at(self, time: float) -> np.ndarray:
        linear, translation = self.at(np.array([time]))
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = linear[0], translation[0]
        return m


@kernel
def frame_at(translation, quat, stretch, time, m):
    """Object-to-world transform at shutter fraction ``time`` into m (3, 4): linear | translation.

    Piecewise between steps: translation and stretch linearly, rotation by slerp.
    """
    steps = len(translation)
    if steps == 1:
        i, u = 0, 0.0
    else:
        x = min(max(time, 0.0), 1.0) * (steps - 1)
        i = min(int(x), steps - 2)
        u = x - i
    j = min(i + 1, steps - 1)
    # slerp between the steps' quaternions
    cos = 0.0
    for k in range(4):
        cos += quat[i, k] * quat[j, k]
    cos = min(max(cos, -1.0), 1.0)
    if 1.0 - cos * cos < 1e-12:  # sin(theta) < 1e-6 (a step without turning): slerp is a lerp
        a, b = 1.0 - u, u
    else:
        theta = math.acos(cos)
        sin = math.sin(theta)
        a, b = math.sin((1.0 - u) * theta) / sin, math.sin(u * theta) / sin
    w, x, y, z = (a * quat[i, 0] + b * quat[j, 0], a * quat[i, 1] + b * quat[j, 1],
                  a * quat[i, 2] + b * quat[j, 2], a * quat[i, 3] + b * quat[j, 3])
    length = max(math.sqrt(w * w + x * x + y * y + z * z), TINY)
    w, x, y, z = w / length, x / length, y / length, z / length
    r00, r01, r02 = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    r10, r11, r12 = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    r20, r21, r22 = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    for c in range(3):
        s0 = (1 - u) * stretch[i, 0, c] + u * stretch[j, 0, c]
        s1 = (1 - u) * stretch[i, 1, c] + u * stretch[j, 1, c]
        s2 = (1 - u) * stretch[i, 2, c] + u * stretch[j, 2, c]
        m[0, c] = r00 * s0 + r01 * s1 + r02 * s2
        m[1, c] = r10 * s0 + r11 * s1 + r12 * s2
        m[2, c] = r20 * s0 + r21 * s1 + r22 * s2
        m[c, 3] = (1 - u) * translation[i, c] + u * translation[j, c]


@kernel
def _frames(translation, quat, stretch, time, out):
    for n in range(len(time)):
        frame_at(translation, quat, stretch, time[n], out[n])


@kernel
def invert_frame(m, inv):
    """inv (3, 4) = the inverse of the affine transform m (3, 4), by cofactors (a singular
    linear part is treated as having determinant 1e-30, never divided by zero)."""
    a, b, c = m[0, 0], m[0, 1], m[0, 2]
    d, e, f = m[1, 0], m[1, 1], m[1, 2]
    g, h, i = m[2, 0], m[2, 1], m[2, 2]
    c00, c01, c02 = e * i - f * h, c * h - b * i, b * f - c * e
    c10, c11, c12 = f * g - d * i, a * i - c * g, c * d - a * f
    c20, c21, c22 = d * h - e * g, b * g - a * h, a * e - b * d
    det = a * c00 + b * c10 + c * c20
    if abs(det) <= TINY:
        det = TINY
    inv[0, 0], inv[0, 1], inv[0, 2] = c00 / det, c01 / det, c02 / det
    inv[1, 0], inv[1, 1], inv[1, 2] = c10 / det, c11 / det, c12 / det
    inv[2, 0], inv[2, 1], inv[2, 2] = c20 / det, c21 / det, c22 / det
    for r in range(3):
        inv[r, 3] = -(inv[r, 0] * m[0, 3] + inv[r, 1] * m[1, 3] + inv[r, 2] * m[2, 3])


