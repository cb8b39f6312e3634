"""Light linking: which emitters light which objects, as Blender computes it for Cycles.

Blender (depsgraph light linking) gives every object a receiver light set, an id from 0 to 63 (0:
the default set of objects no receiver collection names; objects named alike share an id), and
every emitter (light or emissive object) a 64-bit membership of the sets it lights. An emitter
with a receiver collection lights the sets of the objects its collection includes, or, when it
includes none, every set but those it excludes; one without lights all. Cycles then lights an
object with an emitter when bit (object's set) of the emitter's membership is set
(kernel/light/light.h, light_link_object_match); camera rays see every emitter.
"""
from __future__ import annotations

import numpy as np

from ..scene import LIGHT_SETS_ALL

MAX_SET = 63
"""Largest set id (a 64-bit membership); objects past it stay in the default set, as Blender's."""
MAX_COLLECTIONS = 64
"""Receiver collections Blender tells apart; emitters of further ones light everything."""


def light_sets(collections: list[dict[str, bool] | None], max_set: int = MAX_SET
               ) -> tuple[dict[str, int], list[int]]:
    """(set per object named in some collection, membership per emitter) for emitters' receiver
    (or blocker) collections as {object name: included} (None: the emitter has none), sets
    numbered up to ``max_set``. Emitters that share a collection share it here too (pass the same
    dict). Shadow linking's blocker sets are made alike: an emitter's shadows are cast by the
    objects of the sets of its shadow membership."""
    ids: dict[int, int] = {}  # id() of a collection -> its bit
    for links in collections:
        if links is not None and id(links) not in ids and len(ids) < MAX_COLLECTIONS:
            ids[id(links)] = len(ids)
    include: dict[str, int] = {}
    exclude: dict[str, int] = {}
    for links in collections:
        if links is None or id(links) not in ids:
            continue
        bit = 1 << ids[id(links)]
        for name, included in links.items():
            include[name] = include.get(name, 0) | bit if included else include.get(name, 0) & ~bit
            exclude[name] = exclude.get(name, 0) & ~bit if included else exclude.get(name, 0) | bit
    set_of: dict[tuple[int, int], int] = {}
    receiver: dict[str, int] = {}
    included = [0] * len(ids)
    excluded = [0] * len(ids)
    for name in include:
        key = (include[name], exclude[name])
        if key not in set_of:
            if len(set_of) + 1 > max_set:
                continue
            set_of[key] = len(set_of) + 1
        s = set_of[key]
        receiver[name] = s
        for c in range(len(ids)):
            if key[0] >> c & 1:
                included[c] |= 1 << s
            if key[1] >> c & 1:
                excluded[c] |= 1 << s
    membership = []
    for links in collections:
        if links is None or id(links) not in ids:
            membership.append(LIGHT_SETS_ALL)
            continue
        c = ids[id(links)]
        membership.append((included[c] or LIGHT_SETS_ALL) & ~excluded[c] & LIGHT_SETS_ALL)
    return receiver, membership


def lights(membership: np.ndarray, receiver: np.ndarray) -> np.ndarray:
    """Whether emitters of ``membership`` (uint64) light objects of receiver sets ``receiver``."""
    return (membership >> receiver.astype(np.uint64)) & np.uint64(1) != 0
