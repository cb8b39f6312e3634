"""Inside Blender's GUI (under Xvfb): use DRT the way a user does, from bpy.app.timers.

blender FILE --python gui_driver.py -- OUTDIR

Selects DRT in the Render Properties, walks the Properties tabs (recording which panels
poll true), renders with F12's operator into the image editor, switches the 3D viewport
to Rendered shading (through the camera, after an edit, after orbiting; then maximised,
timed over orbit steps and edits, see ``measure_viewport``), back to Solid,
shows material previews (the slot icons and a large preview), and quits while the
viewport renders. DRT's engine class is wrapped to record, from Blender's calls, each
render (preview or not) and each viewport draw (the viewport render's image version and
status line), with times. Screenshots of the whole X screen (``import -window root``) go
to OUTDIR/NN_name.png and what Blender says to OUTDIR/state.json, which the test on the
host checks. Blender quits at the end, also after an error (recorded in the state).
"""
import ctypes
import importlib
import json
import math
import subprocess
import sys
import threading
import time
import traceback
from pathlib import Path

import bpy
from mathutils import Quaternion

OUT = Path(sys.argv[sys.argv.index("--") + 1])
RENDER_TIMEOUT = 120.0
"""Seconds the F12 render and each viewport render may take at most."""
FIRST_PREVIEW_TIMEOUT = 600.0
"""Seconds the slot icons may take: the first preview compiles the kernels the preview scene needs
and the Cornell box (compiled before the session) does not (139 s seen on 2 loaded cores)."""
F12_SIZE = 256
VIEWPORT_SAMPLES = 4
"""Viewport samples while the GUI session waits for viewport renders to finish."""
ORBITS, EDITS = 50, 20
REDRAWS = 10
"""Window redraws timed (Blender's redraw_timer) after the steps: what one frame costs in this GUI."""
ORBIT_DEGREES = 3.0
"""The timed orbit: steps of this many degrees about the vertical, as a slow drag makes them."""
TABS = (  # (Properties tab, object to make active first)
    ("RENDER", None),
    ("OUTPUT", None),
    ("VIEW_LAYER", None),
    ("DATA", "CAMERA"),
    ("DATA", "LIGHT"),
    ("MATERIAL", "MESH"),
    ("WORLD", None),
)
state = {"polls": {}, "screenshots": [], "renders": [], "viewport_renders": []}
shots = 0


def shot(name: str) -> None:
    global shots
    shots += 1
    path = OUT / f"{shots:02d}_{name}.png"
    subprocess.run(["import", "-window", "root", str(path)], check=True, timeout=60)
    state["screenshots"].append(path.name)


def area_of(window, kind: str):
    return next(a for a in window.screen.areas if a.type == kind)


def window_region(area):
    return next(r for r in area.regions if r.type == "WINDOW")


def record_polls(window, area, key: str) -> None:
    """poll() of every registered Properties panel of the shown tab, in that editor's context.

    A poll that raises counts as False (some other engines' sub-panels assume their parent
    polled true first, as Blender only asks them then)."""
    tab = area.spaces.active.context.lower()
    results = {}
    with bpy.context.temp_override(window=window, area=area, region=window_region(area)):
        state.setdefault("context_engine", bpy.context.engine)
        for panel in bpy.types.Panel.__subclasses__():
            if not panel.is_registered or getattr(panel, "bl_space_type", "") != "PROPERTIES":
                continue
            if getattr(panel, "bl_context", "") != tab:
                continue
            poll = getattr(panel, "poll", None)
            try:
                results[panel.__name__] = bool(poll(bpy.context)) if poll is not None else True
            except Exception:
                results[panel.__name__] = False
    state["polls"][key] = results


def select(kind: str):
    view_layer = bpy.context.view_layer
    target = next(o for o in view_layer.objects if o.type == kind and (kind != "MESH" or o.active_material))
    for obj in view_layer.objects:
        obj.select_set(obj == target)
    view_layer.objects.active = target
    return target


class DRT_TEST_PT_preview(bpy.types.Panel):
    """A large material preview in the Material tab (Blender's own Preview panel starts
    closed), rendered by the engine as any preview is."""
    bl_label = "Preview (test)"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    def draw(self, context):
        if context.material is not None:
            self.layout.template_preview(context.material)


def instrument_engine() -> None:
    """Wrap DRT's render and view_draw to log what Blender asked and what came out."""
    engine = next(c for c in bpy.types.RenderEngine.__subclasses__() if getattr(c, "bl_idname", "") == "DRT")
    render, view_draw = engine.render, engine.view_draw
    module = importlib.import_module(engine.__module__.rsplit(".", 1)[0] + ".final")
    write_passes = module.write_passes
    written = {}

    def logged_write_passes(result, passes):
        write_passes(result, passes)
        if "Combined" in passes:  # the last write of a render is its final image
            written["mean_rgb"] = [round(float(v), 4) for v in passes["Combined"][..., :3].mean(axis=(0, 1))]

    def logged_render(self, depsgraph):
        started = time.monotonic()
        written.clear()
        render(self, depsgraph)
        state["renders"].append({"preview": bool(self.is_preview), "seconds": round(time.monotonic() - started, 3),
                                 "size": [self.resolution_x, self.resolution_y], **written})

    def logged_view_draw(self, context, depsgraph):
        started = time.monotonic()
        view_draw(self, context, depsgraph)
        viewport = self._viewport and self._viewport.worker
        if viewport is not None:
            version, image = viewport.latest()
            draws.append((time.monotonic(), version, viewport.status, None if image is None else list(image.shape)))
            events.append((started, "draw", round(time.monotonic() - started, 3)))

    engine.render, engine.view_draw = logged_render, logged_view_draw
    module.write_passes = logged_write_passes
    worker = importlib.import_module(engine.__module__.rsplit(".", 1)[0] + ".viewport").ViewportRender
    start, publish = worker.start, worker._publish

    def logged_start(self, *args):
        events.append((time.monotonic(), "start", None))
        start(self, *args)

    def logged_publish(self, image, stop, status):
        events.append((time.monotonic(), "publish", list(image.shape[:2])))
        publish(self, image, stop, status)

    worker.start, worker._publish = logged_start, logged_publish


draws = []
"""(time, image version, status, image shape) at each viewport draw."""
events = []
"""(time, "start" | "publish" | "draw", image shape or the draw's seconds): where a step's time goes."""


def wait_for_viewport(since: float):
    """Yield until a viewport draw after ``since`` shows a render finished after it (an image
    newer than any drawn before); record its timings."""
    old = max((d[1] for d in draws if d[0] <= since), default=0)
    done = []
    while time.monotonic() - since < RENDER_TIMEOUT:
        done = [d for d in draws if d[0] > since and d[1] > old and d[2].startswith("Done")]
        if done:
            break
        yield 0.25
    seen = [d for d in draws if d[0] > since]
    images = [d for d in seen if d[3] is not None and d[1] > old]
    state["viewport_renders"].append({
        "first_image_s": round(images[0][0] - since, 2) if images else None,
        "done_s": round(done[0][0] - since, 2) if done else None,
        "draws": len(seen),
        "last_status": seen[-1][2] if seen else None,
        "image_shape": images[-1][3] if images else None,
    })


def viewport_threads() -> list[str]:
    return sorted(t.name for t in threading.enumerate() if t.name == "DRT viewport" and t.is_alive())


def steps():
    window = bpy.context.window_manager.windows[0]
    scene = bpy.context.scene
    state["window"] = [window.x, window.y, window.width, window.height]
    props = area_of(window, "PROPERTIES")
    props.spaces.active.context = "RENDER"
    scene.render.engine = "BLENDER_WORKBENCH"  # as a user who has not picked DRT yet
    state["engine_at_start"] = scene.render.engine
    yield 3.0
    shot("properties_render_workbench")

    scene.render.engine = "DRT"  # what choosing DRT in the Render Engine menu sets
    state["engine"] = scene.render.engine
    for tab, kind in TABS:
        if kind:
            select(kind)
            yield 0.5  # the editor rebuilds its tabs for the new active object
        props.spaces.active.context = tab
        yield 1.0
        key = tab.lower() if not kind else f"{tab.lower()}_{kind.lower()}"
        record_polls(window, props, key)
        shot(f"properties_{key}")

    # F12: the render operator as the key invokes it, shown in a full-screen image editor.
    scene.render.resolution_x = scene.render.resolution_y = F12_SIZE
    scene.drt.samples = 16
    view_preferences = bpy.context.preferences.view
    display_type = view_preferences.render_display_type
    view_preferences.render_display_type = "SCREEN"
    finished = {}
    bpy.app.handlers.render_complete.append(lambda *_: finished.setdefault("complete", time.monotonic()))
    bpy.app.handlers.render_cancel.append(lambda *_: finished.setdefault("cancel", time.monotonic()))
    view3d = area_of(window, "VIEW_3D")
    with bpy.context.temp_override(window=window, area=view3d, region=window_region(view3d)):
        started = time.monotonic()
        bpy.ops.render.render("INVOKE_DEFAULT")
    while not finished and time.monotonic() - started < RENDER_TIMEOUT:
        yield 0.5
    # render_complete runs in the render job's thread before the job hands its result to the Render Result
    # image; saving before the job has ended raced it ("does not have any image data" on a loaded machine)
    while bpy.app.is_job_running("RENDER") and time.monotonic() - started < RENDER_TIMEOUT:
        yield 0.25
    state["f12"] = {k: round(v - started, 2) for k, v in finished.items()}
    state["f12"]["job_ended"] = not bpy.app.is_job_running("RENDER")
    result = bpy.data.images.get("Render Result")
    if result is not None and state["f12"]["job_ended"]:  # the image editor's Render Result, for the host to check
        result.save_render(str(OUT / "f12_result.png"), scene=scene)
    yield 1.0
    shot("f12_render")
    image_editor = area_of(window, "IMAGE_EDITOR")
    with bpy.context.temp_override(window=window, area=image_editor, region=window_region(image_editor)):
        bpy.ops.render.view_cancel()
    view_preferences.render_display_type = display_type  # Blender saves changed preferences on quit
    yield 1.0

    # Rendered shading through the camera, then after an edit and after orbiting.
    scene.drt.preview_samples = VIEWPORT_SAMPLES
    view3d = area_of(window, "VIEW_3D")
    state["viewport_area"] = [view3d.x, view3d.y, view3d.width, view3d.height]
    state["viewport_region"] = [window_region(view3d).width, window_region(view3d).height]
    space = view3d.spaces.active
    region_3d = space.region_3d
    shot("viewport_solid")
    region_3d.view_perspective = "CAMERA"
    since = time.monotonic()
    space.shading.type = "RENDERED"
    yield 1.0
    state["viewport_threads_rendered"] = viewport_threads()
    yield from wait_for_viewport(since)
    shot("viewport_rendered")
    light = select("LIGHT")
    since = time.monotonic()
    light.data.color = (0.2, 0.4, 1.0)  # an edit the image must follow: the light turns blue
    yield from wait_for_viewport(since)
    shot("viewport_rendered_after_edit")
    camera = scene.camera  # orbit 25 degrees about the vertical through the point 3 m ahead
    forward = -camera.matrix_world.col[2].xyz.normalized()
    region_3d.view_perspective = "PERSP"
    region_3d.view_rotation = Quaternion((0.0, 0.0, 1.0), 0.44) @ camera.matrix_world.to_quaternion()
    region_3d.view_location = camera.matrix_world.translation + 3.0 * forward
    since = time.monotonic()
    region_3d.view_distance = 3.0
    yield from wait_for_viewport(since)
    shot("viewport_rendered_orbited")
    yield from measure_viewport(window, view3d, scene)
    space.shading.type = "SOLID"
    yield 3.0
    state["viewport_threads_solid"] = viewport_threads()

    # Material previews: the icons of the material slots render with DRT (bl_use_preview).
    material_object = select("MESH")
    yield 0.5
    props.spaces.active.context = "MATERIAL"
    # Icons asked for while F12 ran may have been dropped with Blender's preview job (a render
    # kills it): clear them, so the slot list renders all of them again, now.
    icons_before = sum(1 for r in state["renders"] if r["preview"])
    for slot in material_object.material_slots:
        slot.material.preview_ensure().reload()
    props.tag_redraw()
    yield from wait_for_previews(lambda size: size[0] <= 32, icons_before + len(material_object.material_slots),
                                 FIRST_PREVIEW_TIMEOUT)
    state["material_icons"] = {}
    for slot in material_object.material_slots:
        preview = slot.material.preview
        state["material_icons"][slot.material.name] = {
            "size": list(preview.icon_size), "mean_rgba": mean_rgba(preview.icon_pixels_float, preview.icon_size)}
    material_object.active_material_index = 1  # the red wall's material, in a large preview
    bpy.utils.register_class(DRT_TEST_PT_preview)
    yield from wait_for_previews(lambda size: size[0] > 64, 1)
    yield 1.0
    shot("material_previews")
    large = [r for r in state["renders"] if r["preview"] and r["size"][0] > 64]
    state["material_preview"] = {"material": material_object.active_material.name,
                                 "renders": large}
    state["engine_at_end"] = scene.render.engine

    # Quit while the viewport renders: Blender frees the engine, which stops its worker.
    space.shading.type = "RENDERED"
    yield 0.5
    state["viewport_threads_at_quit"] = viewport_threads()


def resident_mb(field: str = "VmRSS") -> float:
    """Resident memory: VmRSS, or RssAnon (the anonymous part a leak grows; VmRSS also counts
    file-backed pages such as Blender's own code, which the kernel drops under memory pressure:
    seen 270 MB less within one step while other processes needed memory)."""
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) / 1024.0 for line in status if line.startswith(field + ":"))


def settled_mb():
    """(RssAnon, jemalloc's live bytes) in MB with nothing in flight: yields until the viewport's
    worker has finished its render, then purges the freed pages jemalloc (this Blender's allocator)
    keeps for reuse. Read right after a step's first full-resolution image, RssAnon also counts the
    running render's buffers and the freed pages jemalloc returns over about ten seconds: 670-775 MB
    within one run. Settled, it still moves between runs by what is mapped outside jemalloc (-1 to
    +17 MB from step 5 to step 70 in four runs) while jemalloc's live bytes, everything malloc'd
    (Blender, Python's larger objects, NumPy's and the kernels' arrays, Embree's small blocks), held
    within 0.3 MB."""
    since = time.monotonic()
    while viewport_threads():
        if time.monotonic() - since > RENDER_TIMEOUT:
            raise RuntimeError("the viewport's render did not finish")
        yield 0.05
    jemalloc = ctypes.CDLL(None)
    purged = jemalloc.mallctl(b"arena.4096.purge", None, None, None, ctypes.c_size_t(0))  # 4096: every arena
    size = ctypes.c_size_t(8)
    epoch, allocated = ctypes.c_uint64(1), ctypes.c_size_t(0)
    refreshed = jemalloc.mallctl(b"epoch", ctypes.byref(epoch), ctypes.byref(size), ctypes.byref(epoch), size)
    read = jemalloc.mallctl(b"stats.allocated", ctypes.byref(allocated), ctypes.byref(size), None, ctypes.c_size_t(0))
    if purged or refreshed or read:
        raise RuntimeError(f"jemalloc's mallctl failed (purge {purged}, epoch {refreshed}, stats.allocated {read})")
    return round(resident_mb("RssAnon"), 1), round(allocated.value / 2**20, 1)


SETTLED_AFTER = {"orbits": (4, 9), "edits": (14, 19)}
"""Steps after which the memory held is measured (settled_mb): two near the start, two at the end."""
STEP_TIMEOUT = 30.0
"""Seconds one timed orbit step or edit may take to reach its full-resolution image."""


def wait_for_image(since: float, full: tuple[int, int]):
    """Yield until a draw after ``since`` shows an image of the full size ``full`` newer than
    the draw that restarted the render; returns (seconds to the first newer image, to the
    full-size one, what happened meanwhile: the restart and the worker's images, in seconds)."""
    first = done = None
    while time.monotonic() - since < STEP_TIMEOUT:
        after = [d for d in draws if d[0] > since]
        if not after:
            yield 0.02
            continue
        old = after[0][1]  # the first draw restarts the render; older images cannot come after it
        newer = [d for d in after if d[1] > old and d[3] is not None]
        first = newer[0][0] - since if newer else None
        done = next((d[0] - since for d in newer if d[3][:2] == [full[1], full[0]]), None)
        if done is not None:
            break
        yield 0.02
    seen = [[round(t - since, 3), kind, shape] for t, kind, shape in events if t > since]
    return first, done, seen[:12]


def measure_viewport(window, view3d, scene):
    """The 3D view maximised: ORBITS orbit steps (the view matrix turned as a user's drag
    turns it), then EDITS edits (a light's colour, an object moved, in turn), each timed from
    the change to the first new image drawn and to the first full-resolution one, with the
    resident memory after each and, after the steps SETTLED_AFTER names, the memory held once
    the render has finished (the next step then starts from a finished render); written to
    OUTDIR/viewport_times.json."""
    with bpy.context.temp_override(window=window, area=view3d):
        bpy.ops.screen.screen_full_area(use_hide_panels=True)
    yield 2.0
    view3d = area_of(window, "VIEW_3D")
    region = window_region(view3d)
    region_3d = view3d.spaces.active.region_3d
    full = (region.width, region.height)
    times = {"region": list(full), "preview_samples": scene.drt.preview_samples, "orbits": [], "edits": []}
    since = time.monotonic()
    yield from wait_for_image(since, full)  # the maximised region's own first render
    shot("viewport_full_resolution")
    turn = Quaternion((0.0, 0.0, 1.0), math.radians(ORBIT_DEGREES))
    for step in range(ORBITS):
        since = time.monotonic()
        region_3d.view_rotation = turn @ region_3d.view_rotation
        first, done, seen = yield from wait_for_image(since, full)
        times["orbits"].append({"first_image_s": first, "full_resolution_s": done, "rss_mb": round(resident_mb(), 1),
                                "anon_mb": round(resident_mb("RssAnon"), 1), "worker": seen})
        if step in SETTLED_AFTER["orbits"]:
            times["orbits"][-1]["settled_mb"], times["orbits"][-1]["heap_mb"] = yield from settled_mb()
        if step == 0:
            shot("viewport_orbit")
    light = next(o for o in scene.objects if o.type == "LIGHT")
    box = next(o for o in scene.objects if o.type == "MESH" and o.name != "Room")
    for step in range(EDITS):
        since = time.monotonic()
        if step % 2:
            box.location.x += 0.02 if step % 4 == 1 else -0.02
        else:
            light.data.color = (1.0, 0.9, 0.8) if step % 4 == 0 else (0.2, 0.4, 1.0)
        first, done, seen = yield from wait_for_image(since, full)
        times["edits"].append({"kind": "transform" if step % 2 else "light", "first_image_s": first,
                               "full_resolution_s": done, "rss_mb": round(resident_mb(), 1),
                               "anon_mb": round(resident_mb("RssAnon"), 1), "worker": seen})
        if step in SETTLED_AFTER["edits"]:
            times["edits"][-1]["settled_mb"], times["edits"][-1]["heap_mb"] = yield from settled_mb()
    with bpy.context.temp_override(window=window, area=view3d, region=region):
        started = time.monotonic()
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=REDRAWS)
    times["window_redraw_s"] = round((time.monotonic() - started) / REDRAWS, 3)  # Blender's own frame time here
    images = [d for d in draws if d[3] is not None]
    times["last_image_shape"] = images[-1][3] if images else None
    state["viewport_times"] = times
    (OUT / "viewport_times.json").write_text(json.dumps(times, indent=1))
    with bpy.context.temp_override(window=window, area=view3d):
        bpy.ops.screen.back_to_previous()
    yield 1.0


def wait_for_previews(fits, count: int, timeout: float = RENDER_TIMEOUT):
    """Yield until ``count`` preview renders whose size ``fits`` are logged (or ``timeout``)."""
    since = time.monotonic()
    while time.monotonic() - since < timeout:
        if sum(1 for r in state["renders"] if r["preview"] and fits(r["size"])) >= count:
            return
        yield 0.5


def mean_rgba(pixels, size) -> list[float]:
    values = list(pixels)
    return [sum(values[c::4]) / max(1, size[0] * size[1]) for c in range(4)]


def run():
    """Step through ``steps`` from a timer; on the last step or any error (also while setting
    up), write the state and quit, so Blender never waits for the host's timeout."""
    try:
        instrument_engine()
        generator = steps()
    except Exception:
        state["error"] = traceback.format_exc()
        generator = iter(())

    def tick():
        try:
            return next(generator)
        except StopIteration:
            pass
        except Exception:
            state["error"] = traceback.format_exc()
        (OUT / "state.json").write_text(json.dumps(state, indent=1, sort_keys=True))
        bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(tick, first_interval=1.0)


run()
