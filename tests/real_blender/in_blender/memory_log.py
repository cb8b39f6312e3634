"""Inside Blender, before ``-a``: log the resident memory after every rendered frame.

blender -b FILE --python memory_log.py -E DRT -o OUT -s 1 -e 3 -a -- LOG

LOG gets "motion_blur True|False" and then one "FRAME RSS_MB" line per frame.
"""
import sys

import bpy

LOG = sys.argv[sys.argv.index("--") + 1]


def resident_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS in /proc/self/status")


def log_frame(scene, *_):
    with open(LOG, "a") as log:
        log.write(f"{scene.frame_current} {resident_mb():.1f}\n")


with open(LOG, "w") as log:
    log.write(f"motion_blur {bpy.context.scene.render.use_motion_blur}\n")
bpy.app.handlers.render_post.append(log_frame)
