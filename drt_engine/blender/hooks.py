"""What a render leaves for, or takes from, whoever started it besides Blender's render result.

The headless CLI runs Blender's render operator in its own process (batch.py): this is how it
gets the engine's reports and parts back and hears the render's progress. Persistent Data keeps
its prepared scenes here between frames.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable


@dataclasses.dataclass
class RenderHooks:
    last_reports: dict[str, dict] = dataclasses.field(default_factory=dict)
    """The report (core.render.report.report_dict) of the newest final render of each view layer, by name:
    the CLI writes ``<OUT stem>.drt.json`` from it."""

    progress_listener: Callable | None = None
    """Called with every core ProgressUpdate of a final render when set: the CLI's live progress line."""

    persistent: dict[str, tuple[str, object]] = dataclasses.field(default_factory=dict)
    """With Blender's Persistent Data on (Render Properties > Performance, as for Cycles): per view
    layer, the content key (core.render.prepared.content_key) and prepared scene of its last final render,
    so the next frame reuses the Embree scenes, lights and materials when only the camera changed."""

    collect_parts: bool = False
    """True: keep every final render's part in ``last_parts`` instead of writing part files."""

    last_parts: dict[str, object] = dataclasses.field(default_factory=dict)
    """The newest part (core.film.parts.Part) of each view layer, by name, while ``collect_parts`` is on."""


render_hooks = RenderHooks()
"""The one set of hooks of this Blender process."""
