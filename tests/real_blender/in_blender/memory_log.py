"""Inside Blender, before ``-a``: log the resident memory and DRT's live objects after every frame.

blender -b FILE --python memory_log.py -E DRT -o OUT -s 1 -e 3 -a -- LOG

LOG gets "motion_blur True|False" and then one "FRAME RSS_MB OBJECTS" line per frame, OBJECTS
counting the instances of the extension's classes (scenes, renderers, films...) still alive
after a full garbage collection: a frame that leaves one behind makes the count grow.
"""
import gc
import sys

import bpy

LOG = sys.argv[sys.argv.index("--") + 1]


def resident_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS in /proc/self/status")


def live_drt_objects() -> int:
    gc.collect()
    modules = (getattr(type(o), "__module__", None) for o in gc.get_objects())
    return sum(1 for module in modules if isinstance(module, str) and "drt_engine." in module)


def log_frame(scene, *_):
    with open(LOG, "a") as log:
        log.write(f"{scene.frame_current} {resident_mb():.1f} {live_drt_objects()}\n")


with open(LOG, "w") as log:
    log.write(f"motion_blur {bpy.context.scene.render.use_motion_blur}\n")
bpy.app.handlers.render_post.append(log_frame)
