"""Vectors and frames: rows of (N, 3) arrays for the wave-level code, and the per-ray scalar
forms the kernels call.

Most array helpers write their three products out instead of calling BLAS or a NumPy
reduction: on a length-3 axis those cost several times more, and BLAS's rounding depends on
the build (images must be bit-identical on every machine).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .constants import TINY
from .jit import kernel


def dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def dot_with(v, w):
    """Rows of v (N, 3) dotted with one vector w, written out: BLAS (``v @ w``) spends more on
    waking its threads than on such products (2x slower renders measured on a loaded 2-core
    machine), and its rounding depends on the build."""
    return v[:, 0] * w[0] + v[:, 1] * w[1] + v[:, 2] * w[2]


def transform(v, m):
    """Rows of v (N, 3) times a 3x3 matrix: ``v @ m.T`` without BLAS (see ``dot_with``)."""
    return v[:, 0:1] * m[:, 0] + v[:, 1:2] * m[:, 1] + v[:, 2:3] * m[:, 2]


def norm(v):
    """Lengths of 3-vectors along the last axis, summed in np.linalg.norm's order (a NumPy
    reduction over a length-3 axis costs ~10x these three products)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.sqrt(x * x + y * y + z * z)


def max3(v):
    """Largest of the three components along the last axis (~30x faster than .max(axis=-1))."""
    return np.maximum(np.maximum(v[..., 0], v[..., 1]), v[..., 2])


def orthonormal_basis(n):
    """Two unit vectors completing each unit row of n to a right-handed frame (Duff et al. 2017)."""
    s = np.where(n[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (s + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + s * n[:, 0] ** 2 * a, s * b, -s * n[:, 0]], axis=1)
    bt = np.stack([b, s + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bt


@dataclass(frozen=True)
class Frame:
    """Orthonormal frames, one per row of ``m`` (N, 3, 3): tangent ``t``, bitangent ``b`` and
    normal ``n`` as its rows (the layout kernels read). Shading works in the local frame (normal
    along +z); a frame carries both ways across."""

    m: np.ndarray

    @classmethod
    def about(cls, n) -> "Frame":
        """The frame completing each unit row of ``n`` (``orthonormal_basis``)."""
        t, b = orthonormal_basis(n)
        return cls(np.stack([t, b, n], axis=1))

    @classmethod
    def along(cls, n, tangent) -> "Frame":
        """The frame about each unit row of ``n`` whose tangent is ``tangent`` made perpendicular
        to it (Cycles' make_orthonormals_tangent: b = n x tangent normalised, t = b x n), the
        frame of an anisotropic lobe; ``about``'s where the tangent is (nearly) along n or zero."""
        b = np.cross(n, tangent)
        length = norm(b)
        ok = length > 1e-9
        b = b / np.where(ok, length, 1.0)[:, None]
        t = np.cross(b, n)
        fallback = cls.about(n).m
        return cls(np.where(ok[:, None, None], np.stack([t, b, n], axis=1), fallback))

    @property
    def t(self) -> np.ndarray:
        return self.m[:, 0]

    @property
    def b(self) -> np.ndarray:
        return self.m[:, 1]

    @property
    def n(self) -> np.ndarray:
        return self.m[:, 2]

    def __getitem__(self, rows) -> "Frame":
        return Frame(self.m[rows])

    def to_local(self, v):
        """World rows of ``v`` in each row's frame."""
        return np.stack([dot(v, self.t), dot(v, self.b), dot(v, self.n)], axis=1)

    def to_world(self, v):
        """Local rows of ``v`` back in world space."""
        return v[:, :1] * self.t + v[:, 1:2] * self.b + v[:, 2:] * self.n


def normalize(v, tiny: float = TINY):
    """Unit vectors along the last axis; lengths under ``tiny`` count as ``tiny``."""
    return v / np.maximum(norm(v)[..., None], tiny)


@kernel
def unit(x, y, z, tiny=TINY):
    """(x, y, z) scaled to unit length; lengths under ``tiny`` count as ``tiny``."""
    length = max(np.sqrt(x * x + y * y + z * z), tiny)
    return x / length, y / length, z / length


@kernel(inline="always")
def dot3(ax, ay, az, bx, by, bz):
    """a . b of two vectors given by components (the per-ray form of ``dot``)."""
    return ax * bx + ay * by + az * bz


@kernel(inline="always")
def cross3(ax, ay, az, bx, by, bz):
    """a x b of two vectors given by components."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@kernel(inline="always")
def safe_unit(x, y, z):
    """Cycles' safe_normalize: (x, y, z) scaled to unit length, the zero vector left as it is
    (``unit`` instead lengthens short vectors past their length)."""
    length = np.sqrt(x * x + y * y + z * z)
    if length == 0.0:
        return x, y, z
    return x / length, y / length, z / length


@kernel(inline="always")
def basis(nx, ny, nz):
    """Two unit vectors completing a unit vector to a right-handed frame (Duff et al. 2017);
    the per-ray form of ``orthonormal_basis``."""
    s = 1.0 if nz >= 0 else -1.0
    a = -1.0 / (s + nz)
    b = nx * ny * a
    return 1.0 + s * nx * nx * a, s * b, -s * nx, b, s + ny * ny * a, -ny
