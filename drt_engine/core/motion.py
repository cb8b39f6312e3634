"""Transforms over the shutter, interpolated at each ray's own time.

Matrices sampled at S evenly spaced shutter times are decomposed once into
translation, rotation (a quaternion) and the remaining stretch (polar decomposition),
then interpolated per ray piecewise between steps: translation and stretch linearly,
rotation by slerp. A spinning object keeps its size, and several steps keep curved
paths curved.
"""
from __future__ import annotations

import numpy as np

_TINY = 1e-30


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


def _matrix_from_quat(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def _polar(m3: np.ndarray):
    """m3 = R @ P with R a proper rotation and P symmetric (it carries any mirroring)."""
    u, s, vt = np.linalg.svd(m3)
    d = np.sign(np.linalg.det(u @ vt))
    fix = np.ones((len(m3), 3))
    fix[:, 2] = d
    r = (u * fix[:, None, :]) @ vt
    p = np.transpose(vt, (0, 2, 1)) @ ((s * fix)[:, :, None] * vt)
    return r, p


class Motion:
    """Object-to-world transforms over the shutter (S >= 1 steps)."""

    def __init__(self, matrices: np.ndarray):
        matrices = np.asarray(matrices, dtype=np.float64).reshape(-1, 4, 4)
        self.steps = len(matrices)
        self.translation = matrices[:, :3, 3]
        self.linear = matrices[:, :3, :3]
        rotation, self.stretch = _polar(self.linear)
        q = _quat_from_matrix(rotation)
        for k in range(1, len(q)):  # shortest arcs between steps
            if np.dot(q[k], q[k - 1]) < 0:
                q[k] = -q[k]
        self.quat = q
        self.moving = self.steps > 1 and not np.allclose(matrices, matrices[:1], rtol=0, atol=1e-12)

    def at(self, time: np.ndarray):
        """Per-ray (linear (N, 3, 3), translation (N, 3)) at shutter fractions in [0, 1]."""
        n = len(time)
        if not self.moving:
            return np.broadcast_to(self.linear[0], (n, 3, 3)), np.broadcast_to(self.translation[0], (n, 3))
        x = np.clip(time, 0.0, 1.0) * (self.steps - 1)
        i = np.minimum(x.astype(np.int64), self.steps - 2)
        u = (x - i)[:, None]
        translation = (1 - u) * self.translation[i] + u * self.translation[i + 1]
        stretch = (1 - u[:, :, None]) * self.stretch[i] + u[:, :, None] * self.stretch[i + 1]
        rotation = _matrix_from_quat(_slerp(self.quat[i], self.quat[i + 1], u[:, 0]))
        return rotation @ stretch, translation

    def matrix_at(self, time: float) -> np.ndarray:
        linear, translation = self.at(np.array([time]))
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = linear[0], translation[0]
        return m


def inverse3(m: np.ndarray) -> np.ndarray:
    """Inverses of a stack of 3x3 matrices by cofactors (LAPACK per matrix is far slower)."""
    a, b, c = m[:, 0, 0], m[:, 0, 1], m[:, 0, 2]
    d, e, f = m[:, 1, 0], m[:, 1, 1], m[:, 1, 2]
    g, h, i = m[:, 2, 0], m[:, 2, 1], m[:, 2, 2]
    co = np.stack([
        np.stack([e * i - f * h, c * h - b * i, b * f - c * e], -1),
        np.stack([f * g - d * i, a * i - c * g, c * d - a * f], -1),
        np.stack([d * h - e * g, b * g - a * h, a * e - b * d], -1),
    ], axis=1)
    det = a * co[:, 0, 0] + b * co[:, 1, 0] + c * co[:, 2, 0]
    safe = np.where(np.abs(det) > _TINY, det, _TINY)
    return co / safe[:, None, None]


def _slerp(q0: np.ndarray, q1: np.ndarray, u: np.ndarray) -> np.ndarray:
    cos = np.clip(np.sum(q0 * q1, axis=1), -1.0, 1.0)
    theta = np.arccos(cos)
    sin = np.sin(theta)
    small = sin < 1e-6
    a = np.where(small, 1 - u, np.sin((1 - u) * theta) / np.where(small, 1.0, sin))
    b = np.where(small, u, np.sin(u * theta) / np.where(small, 1.0, sin))
    q = a[:, None] * q0 + b[:, None] * q1
    return q / np.maximum(np.linalg.norm(q, axis=1, keepdims=True), _TINY)
