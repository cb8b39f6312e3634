"""Light linking read from Blender: each emitter's receiver collection, its objects and child
collections each included or excluded (the entry's link state), turned into the receiver sets and
memberships Cycles renders with (core.lights.linking)."""
from __future__ import annotations

from ...core.lights.linking import light_sets
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


class LightLinks:
    """The receiver collections of the exported emitters, by object name."""

    def __init__(self):
        self._collections: dict[str, object] = {}

    def look_at(self, obj) -> None:
        linking = getattr(obj, "light_linking", None)  # Blender 4.0+
        if linking is not None and linking.receiver_collection is not None:
            self._collections[obj.name] = linking.receiver_collection

    def apply(self, lights, instances) -> None:
        """Sets each light's and instance's membership and each instance's receiver set (nothing
        without a receiver collection: the defaults light everything)."""
        if not self._collections:
            return
        shared: dict[str, dict[str, bool]] = {}
        names = list(self._collections)
        links = [shared.setdefault(c.name, _links(c)) for c in self._collections.values()]
        receiver, membership = light_sets(links)
        member = dict(zip(names, membership))
        for light in lights:
            light.light_set_membership = member.get(light.name, LIGHT_SETS_ALL)
        for instance in instances:
            instance.light_set_membership = member.get(instance.name, LIGHT_SETS_ALL)
            instance.receiver_light_set = receiver.get(instance.name, 0)
