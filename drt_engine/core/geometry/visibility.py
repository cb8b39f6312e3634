"""Objects' ray visibility as Embree masks: each instance carries the bits of the ray kinds that
see it, each ray the bit of its kind, and Embree skips an instance whose mask shares no bit with
the ray's (Cycles' object visibility in its BVH). Rays of a scene whose objects are all fully
visible keep ``EVERY`` and cost what they did.

Measured on embreex 4.4's libembree4 (tests/core/test_ray_visibility.py): ray masks are honoured on
instances; a geometry's default mask is 1, so the meshes under instances get every bit."""
from __future__ import annotations

CAMERA, DIFFUSE, GLOSSY, TRANSMIT, SHADOW = 1, 2, 4, 8, 16
"""Mask bits: camera rays, diffuse and glossy reflections, any transmission, shadow rays."""
EVERY = -1
"""Every bit (0xFFFFFFFF as an int32): a ray every object stops, an object every ray sees."""
BLOCKER_SETS = 26
"""Shadow linking's blocker sets 1 to 26 take the mask bits above SHADOW (set s: bit 4 + s; set 0,
the default, SHADOW itself); the export keeps objects of further sets in the default set."""


def instance_mask(instance, shadow_linking: bool = False) -> int:
    """The mask bits of the ray kinds that see a ``core.scene.Instance`` (EVERY when all do and no
    ``shadow_linking`` asks for the shadow bit of its blocker set)."""
    seen = (instance.visible_camera, instance.visible_diffuse, instance.visible_glossy,
            instance.visible_transmission, instance.visible_shadow)
    if all(seen) and not shadow_linking:
        return EVERY
    s = instance.blocker_shadow_set
    shadow = SHADOW if s == 0 or s > BLOCKER_SETS else 1 << (4 + s)
    return sum(bit for bit, on in zip((CAMERA, DIFFUSE, GLOSSY, TRANSMIT, shadow), seen) if on)


def shadow_ray_mask(membership: int) -> int:
    """The Embree mask (an int32) of shadow rays of an emitter whose shadows the blocker sets of
    ``membership`` cast (core.lights.linking)."""
    bits = SHADOW if membership & 1 else 0
    for s in range(1, BLOCKER_SETS + 1):
        if membership >> s & 1:
            bits |= 1 << (4 + s)
    return bits - (1 << 32) if bits >= 1 << 31 else bits
