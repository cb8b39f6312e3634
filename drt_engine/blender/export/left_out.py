"""What of a scene Cycles renders and DRT does not yet, found while exporting: objects of the types
it leaves out (one warning), object and light settings it does not read (another) and the view
layer's passes it does not write (a third), so that a scene relying on them is never rendered
differently without a word.

Each object is looked at once (its instances share its settings). Objects' and lights' ray
visibility, lights' Cast Shadow, objects' Holdout and Shadow Catcher and the world's ray visibility are
read (export.geometry, export.lights, export.world) and so are light and shadow linking
(export.linking): they are not listed here.
"""
from __future__ import annotations

TYPES = {"CURVES": "hair curves", "POINTCLOUD": "point cloud", "VOLUME": "volume"}
"""Object types Cycles renders and DRT does not (text, curves and surfaces reach the export as
meshes; empties, armatures, grease pencil and the like render in neither)."""

SHOWN = 3
"""Object names a setting's entry shows before "and N more"."""

PASSES = (  # view-layer toggle, the pass as Blender's Passes panel names it
    ("use_pass_ambient_occlusion", "Ambient Occlusion"),
)
"""Cycles' passes DRT does not write yet (its Diffuse, Glossy and Transmission Color, Direct and
Indirect it does, core.integrator.lightpasses): a view layer that asks for them gets no such pass,
so the warning names them."""

OBJECT_SETTINGS = ()  # (attribute, the value DRT renders as, what the warning calls another value): none left


class LeftOut:
    """What of the exported objects DRT does not render: objects by their name, settings by what is
    left out. ``render``: the depsgraph is a final render's (modifiers' render switches apply)."""

    def __init__(self, render: bool):
        self.render = render
        self._seen: set[str] = set()
        self._objects: dict[str, str] = {}  # object name -> what of it is not rendered
        self._names: dict[str, list[str]] = {}

    def look_at(self, obj, instanced: bool) -> bool:
        """Note what of ``obj`` DRT leaves out (once per object; ``instanced``: seen as an instance,
        whose particle systems are its instancer's); False for an object DRT does not render at all."""
        if obj.name not in self._seen:
            self._seen.add(obj.name)
            self._note(obj, obj.name, instanced)
        return obj.type not in TYPES

    def _note(self, obj, name: str, instanced: bool) -> None:
        if obj.type in TYPES:
            self._objects[name] = TYPES[obj.type]
        elif obj.type == "MESH" and not instanced and self._shows_hair(obj):
            self._objects[name] = "hair particles"
        for attribute, rendered, what in OBJECT_SETTINGS:
            if obj.type != "LIGHT" and getattr(obj, attribute, rendered) != rendered:
                self._add(what, name)

    def _shows_hair(self, obj) -> bool:
        """Whether the object shows hair particles as strands (Cycles renders them as curves)."""
        return any(m.type == "PARTICLE_SYSTEM" and (m.show_render if self.render else m.show_viewport)
                   and m.particle_system.settings.type == "HAIR" and m.particle_system.settings.render_type == "PATH"
                   for m in obj.modifiers)

    def _add(self, what: str, name: str) -> None:
        self._names.setdefault(what, []).append(name)

    def warnings(self) -> list[str]:
        """One line naming the objects not rendered, one naming every setting left out and the
        objects that use it (each only when there is something to name)."""
        out = []
        if self._objects:
            out.append("not rendered (DRT does not render these yet): "
                       + ", ".join(f"'{name}' ({what})" for name, what in sorted(self._objects.items())))
        if not self._names:
            return out
        parts = []
        for what, names in self._names.items():
            shown = ", ".join(n if n.startswith("world '") else f"'{n}'" for n in names[:SHOWN])
            more = f" and {len(names) - SHOWN} more" if len(names) > SHOWN else ""
            parts.append(f"{what} ({shown}{more})")
        return out + ["object and light settings DRT does not render yet, rendered as if unset: " + "; ".join(parts)]


def passes_left_out(view_layer) -> list[str]:
    """One line naming the view layer's enabled passes DRT does not write (none: no line)."""
    names = [name for toggle, name in PASSES if getattr(view_layer, toggle, False)]
    return ["passes DRT does not write yet (not in the render result): " + ", ".join(names)] if names else []
