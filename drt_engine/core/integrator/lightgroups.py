"""Light groups, as Cycles has them: the view layer names groups, each light, emissive object and
the world may be in one, and a pass ``Combined_<group>`` (RGB) holds what that group's emitters
give to Combined, contribution by contribution as Cycles' film writes it (light_passes.h:
film_write_direct_light for light samples, film_write_surface_emission and film_write_background
for emission a ray finds, after the clamp, MIS-weighted as in Combined). The groups of a scene
whose every emitter is in one sum to Combined (with shadow catchers, to the matte: a path adds
nothing to a group once it met a catcher, core.integrator.shadow_catcher). Light no group owns is in
Combined alone.

Each contribution goes to its emitter's group where it goes to the wave's radiance: the emission
rays find (core.integrator.mis.add_emitted, ``rows``' group), light samples in the direct-light
kernel and transparent shadows (each sample's group, core.lights.strategies.LightSamples.group).
A scene with no group pass asked for, or no emitter in a group, carries none of this."""
from __future__ import annotations

import numpy as np

from ..settings import lightgroup_pass

NO_GROUPS = np.zeros((0, 0, 3))
"""The kernels' ``grouped`` when nothing is grouped."""


class LightGroups:
    """The group passes of one render: ``names`` the passes in the order of the wave's ``grouped``
    columns, ``slots`` per scene light group (index -1 last: none) its column or -1."""

    def __init__(self, scene, passes):
        self.names = [lightgroup_pass(g) for g in scene.light_groups if lightgroup_pass(g) in passes]
        self.slots = np.full(len(scene.light_groups) + 1, -1, np.int64)
        for column, name in enumerate(self.names):
            self.slots[[lightgroup_pass(g) for g in scene.light_groups].index(name)] = column

    def column(self, group) -> np.ndarray:
        """The ``grouped`` column of each scene light group in ``group`` (-1: none or not a pass)."""
        return self.slots[group]

    def new(self, n: int) -> np.ndarray:
        return np.zeros((n, len(self.names), 3))


def light_groups(scene, lights, passes) -> LightGroups | None:
    """The render's light groups, None when no group pass is asked for or no emitter is in a group
    (the passes then stay zero: nothing traced writes them)."""
    if not lights.grouped or not any(lightgroup_pass(g) in passes for g in scene.light_groups):
        return None
    return LightGroups(scene, passes)
