"""What the BSDF hands the integrator, one field per quantity and one row per hit (or, for
``LobeSample``, one hit inside a kernel): named (NamedTuple, so a caller may still unpack them in
order) instead of bare tuples."""
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


class LobeSample(NamedTuple):
    """One hit's continuation through one lobe of its mixture (core.bsdf.mixture.sample_lobes),
    built and read inside kernels: local direction (x, y, z), the throughput it leaves w = f |cos| / pdf
    (RGB), pdf (0 for a delta lobe), the flags, and a sampled hair lobe's own part."""

    x: float
    y: float
    z: float
    w0: float
    w1: float
    w2: float
    pdf: float
    delta: bool
    valid: bool
    passthrough: bool
    """The transparent lobe was taken."""
    diffuse: bool
    """A diffuse lobe was taken."""
    crosses: bool
    """wi leaves through the surface (below the shading normal, but for a reflection about a
    lobe's own normal)."""
    own: int
    """The hair lobe sampled (-1: none), whose own f |cos| (o0, o1, o2) the mixture's holds and the
    light passes file by its closure."""
    o0: float
    o1: float
    o2: float
    transmits: bool
    """Cycles' label of the sample, a transmission: ``crosses``, but a hair lobe's by its sample's lobe."""
