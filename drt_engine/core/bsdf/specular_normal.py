"""Cycles' ensure_valid_specular_reflection (kernel/closure/bsdf_util.h): a shading normal that
would mirror the outgoing direction below the surface, turned toward the geometric normal just
enough that the mirror image leaves above it. Cycles gives it to every closure but the diffuse
ones, whose light does not depend on the outgoing direction; one kernel serves the hits of a
depth step (core.integrator.hits), the normals shader programs make and the coat's normal."""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel


@kernel(inline="always")
def raised(gx, gy, gz, ox, oy, oz, nx, ny, nz):
    """The normal (nx, ny, nz) raised toward (gx, gy, gz) (the geometric normal facing wo) until
    wo (ox, oy, oz) mirrored about it leaves at min(0.9 cos(wo, ng), 0.01) above the surface;
    itself where it already does."""
    c = nx * ox + ny * oy + nz * oz
    iz = ox * gx + oy * gy + oz * gz
    threshold = min(0.9 * iz, 0.01)
    if gx * (2.0 * c * nx - ox) + gy * (2.0 * c * ny - oy) + gz * (2.0 * c * nz - oz) >= threshold:
        return nx, ny, nz
    along = nx * gx + ny * gy + nz * gz
    xx, xy, xz = nx - along * gx, ny - along * gy, nz - along * gz
    length = np.sqrt(xx * xx + xy * xy + xz * xz)
    if length > 1e-20:
        xx, xy, xz = xx / length, xy / length, xz / length
    else:
        xx, xy, xz = nx, ny, nz
    ix = ox * xx + oy * xy + oz * xz
    a = ix * ix + iz * iz
    b = 2.0 * (a + iz * threshold)
    root = np.sqrt(max(b * b - 4.0 * a * (threshold + iz) ** 2, 0.0))
    nz2 = 0.25 * (b + root if ix < 0 else b - root) / max(a, 1e-30)
    sx, sz = np.sqrt(max(1.0 - nz2, 0.0)), np.sqrt(max(nz2, 0.0))
    return sx * xx + sz * gx, sx * xy + sz * gy, sx * xz + sz * gz


@kernel
def _raise_rows(ng, wo, n, out):
    for i in range(len(n)):
        out[i, 0], out[i, 1], out[i, 2] = raised(ng[i, 0], ng[i, 1], ng[i, 2], wo[i, 0], wo[i, 1], wo[i, 2],
                                                 n[i, 0], n[i, 1], n[i, 2])


def valid_specular_reflection(ng, wo, n) -> np.ndarray:
    """``raised`` over rows: normals ``n`` (N, 3) for outgoing directions ``wo`` and geometric
    normals ``ng`` facing them."""
    out = np.empty((len(n), 3))
    _raise_rows(*(np.ascontiguousarray(a, np.float64) for a in (ng, wo, n)), out)
    return out
