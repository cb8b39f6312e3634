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


def instance_mask(instance) -> int:
    """The mask bits of the ray kinds that see a ``core.scene.Instance`` (EVERY when all do)."""
    seen = (instance.visible_camera, instance.visible_diffuse, instance.visible_glossy,
            instance.visible_transmission, instance.visible_shadow)
    if all(seen):
        return EVERY
    return sum(bit for bit, on in zip((CAMERA, DIFFUSE, GLOSSY, TRANSMIT, SHADOW), seen) if on)
