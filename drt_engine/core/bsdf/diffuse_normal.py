"""The diffuse lobes' own normal at a hit. Where a smooth or bumped shading normal turns away
from the viewer (a silhouette's rim), Cycles gives its diffuse closures (Lambert, Oren-Nayar,
sheen, diffuse toon, translucent) that normal as it is (sd->N) and raises the others' (glossy,
glass, coat: core.bsdf.specular_normal). A hit's frame is about the raised normal; the diffuse
lobes take theirs, (dx, dy, dz) in that frame, which is exactly (0, 0, 1) where the two are one,
so that the lobes' arithmetic there is the frame's to the bit."""
from __future__ import annotations

from ..base.jit import kernel
from ..base.vectors import basis


@kernel(inline="always")
def tilted(dx, dy):
    """The diffuse lobes' normal is not the frame's."""
    return dx != 0.0 or dy != 0.0


@kernel(inline="always")
def into(dx, dy, dz, x, y, z):
    """(x, y, z), a direction in the hit's frame, in the frame about the unit normal d (``basis``)."""
    tx, ty, tz, bx, by, bz = basis(dx, dy, dz)
    return x * tx + y * ty + z * tz, x * bx + y * by + z * bz, x * dx + y * dy + z * dz


@kernel(inline="always")
def out_of(dx, dy, dz, x, y, z):
    """(x, y, z), a direction in the frame about d, in the hit's frame (``into``'s inverse)."""
    tx, ty, tz, bx, by, bz = basis(dx, dy, dz)
    return x * tx + y * bx + z * dx, x * ty + y * by + z * dy, x * tz + y * bz + z * dz
