"""What the BSDF hands the integrator, one field per quantity and one row per hit: named
(NamedTuple, so a caller may still unpack them in order) instead of bare tuples."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class BsdfValue(NamedTuple):
    """BSDF times |cos| toward a light sample: the diffuse part, the non-diffuse part, and the
    density of continuing toward it through the non-diffuse lobes (for MIS)."""

    diffuse: np.ndarray
    glossy: np.ndarray
    pdf: np.ndarray


class BsdfSample(NamedTuple):
    """A direction sampled from a hit's non-diffuse lobes: local direction, the throughput
    it leaves (f |cos| / pdf), its pdf (0 for a delta lobe), whether it is a delta, valid,
    and whether it passed straight through (the transparent lobe)."""

    wi_l: np.ndarray
    weight: np.ndarray
    pdf: np.ndarray
    delta: np.ndarray
    valid: np.ndarray
    passthrough: np.ndarray
