"""IES profiles written for the tests (LM-63 text, no luminaire's data), without bpy: the core's
tests read them too.

The profiles vary with both angles, so a light's orientation, the horizontal angle's origin and the
vertical angle's direction all show on a lit floor: ``ASYMMETRIC`` covers the whole circle (type C,
0 to 360 degrees), ``QUADRANT`` one quadrant that Cycles mirrors to four (0 to 90 degrees), and
``TYPE_B`` a type B file (its polar axis horizontal, angles swapped as Cycles reads it).
"""
from __future__ import annotations

import math

import numpy as np


def lm63(v_angles, h_angles, candela, kind=1, multiplier=1.0) -> str:
    """An LM-63 file of photometric type ``kind`` (1 C, 2 B, 3 A): ``candela`` (H, V)."""
    lines = ["IESNA:LM-63-2002", "[TEST] DRT parity profile", "[MANUFAC] none", "TILT=NONE",
             f"1 -1 {multiplier:g} {len(v_angles)} {len(h_angles)} {kind} 2 0.1 0.1 0.05", "1.0 1.0 40",
             " ".join(f"{a:g}" for a in v_angles), " ".join(f"{a:g}" for a in h_angles)]
    lines += [" ".join(f"{c:.2f}" for c in row) for row in candela]
    return "\r\n".join(lines) + "\r\n"


def _candela(v_angles, h_angles, lobe, floor=40.0):
    return [[(1000.0 + lobe * math.cos(math.radians(h))) * max(math.cos(math.radians(v)), 0.0) ** 3 + floor
             for v in v_angles] for h in h_angles]


V_FULL = np.arange(0.0, 181.0, 7.5)
ASYMMETRIC = lm63(V_FULL, np.arange(0.0, 361.0, 22.5), _candela(V_FULL, np.arange(0.0, 361.0, 22.5), 850.0))
V_LOWER = np.arange(0.0, 91.0, 5.0)
QUADRANT = lm63(V_LOWER, np.arange(0.0, 91.0, 15.0),
                [[c * (1.0 + 0.6 * h / 90.0) for c in row]
                 for row, h in zip(_candela(V_LOWER, np.arange(0.0, 91.0, 15.0), 0.0), np.arange(0.0, 91.0, 15.0))])
_B_V = np.arange(-90.0, 91.0, 10.0)
_B_H = np.arange(0.0, 91.0, 10.0)
TYPE_B = lm63(_B_V, _B_H, [[600.0 * math.cos(math.radians(v)) ** 2 * (1.0 + h / 90.0) + 30.0 for v in _B_V]
                           for h in _B_H], kind=2)
