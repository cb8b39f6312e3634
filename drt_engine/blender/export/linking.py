"""Light and shadow linking read from Blender: each emitter's receiver and blocker collections,
their objects and child collections each included or excluded (the entry's link state), turned
into the receiver and blocker sets and memberships Cycles renders with (core.lights.linking)."""
from __future__ import annotations

from ...core.lights.linking import MAX_SET, light_sets
from ...core.geometry.visibility import BLOCKER_SETS
from ...core.scene import LIGHT_SETS_ALL


def _links(collection) -> dict[str, bool]:
    """{object name: included} of a receiver collection: a child collection's objects (at any depth)
    take the state of its entry, the collection's own objects theirs; the last entry wins, as in
    Blender's depsgraph (children first, then objects)."""
    out: dict[str, bool] = {}
    for child, entry in zip(collection.children, collection.collection_children):
        for obj in child.all_objects:
            out[obj.name] = entry.light_linking.link_state == "INCLUDE"
    for obj, entry in zip(collection.objects, collection.collection_objects):
        out[obj.name] = entry.light_linking.link_state == "INCLUDE"
    return out


def _sets(collections: dict, max_set: int):
    """(set per object, membership per emitter name) of emitters' ``collections`` by name."""
    shared: dict[str, dict[str, bool]] = {}
    links = [shared.setdefault(c.name, _links(c)) for c in collections.values()]
    sets, membership = light_sets(links, max_set)
    return sets, dict(zip(collections, membership))


class LightLinks:
    """The receiver and blocker collections of the exported emitters, by object name."""

    def __init__(self):
        self._receivers: dict[str, object] = {}
        self._blockers: dict[str, object] = {}

    def look_at(self, obj) -> None:
        linking = getattr(obj, "light_linking", None)  # Blender 4.0+
        if linking is not None and linking.receiver_collection is not None:
            self._receivers[obj.name] = linking.receiver_collection
        if linking is not None and linking.blocker_collection is not None:
            self._blockers[obj.name] = linking.blocker_collection

    def apply(self, lights, instances, instancers, warnings: list[str]) -> None:
        """Sets each light's and instance's memberships and each instance's receiver and blocker
        sets (nothing without such collections: the defaults light everything, every object
        casting every shadow). An instance takes its instancer's (``instancers``: a name per
        instance, "" for none) receiver and blocker set where that is not the default, else its
        own, its own memberships always (Cycles' BlenderLightLink). DRT tells
        core.geometry.visibility.BLOCKER_SETS blocker sets apart, Blender MAX_SET: a scene that
        needs more is named in ``warnings``."""
        if self._receivers:
            receiver, member = _sets(self._receivers, MAX_SET)
            for emitter in (*lights, *instances):
                emitter.light_set_membership = member.get(emitter.name, LIGHT_SETS_ALL)
            for instance, instancer in zip(instances, instancers):
                instance.receiver_light_set = receiver.get(instancer, 0) or receiver.get(instance.name, 0)
        if self._blockers:
            blocker, member = _sets(self._blockers, BLOCKER_SETS)
            needed = max(_sets(self._blockers, MAX_SET)[0].values(), default=0)
            if needed > BLOCKER_SETS:
                warnings.append(f"shadow linking: the blocker collections make {needed} sets of objects, DRT tells "
                                f"{BLOCKER_SETS} apart (Cycles {MAX_SET}): objects of the others cast every "
                                "emitter's shadows")
            for emitter in (*lights, *instances):
                emitter.shadow_set_membership = member.get(emitter.name, LIGHT_SETS_ALL)
            for instance, instancer in zip(instances, instancers):
                instance.blocker_shadow_set = blocker.get(instancer, 0) or blocker.get(instance.name, 0)
