"""The first render after an install loads the kernels the Linux zip ships (tools/ship_kernels.py,
compiled for any CPU) instead of compiling them: a sample scene renders in Debian's Blender 4.3.2
with nothing compiled for this machine's CPU. Its wall time is recorded, not asserted (bench/startup.py
measures start-up)."""
from __future__ import annotations

import shutil
import time

from blender_env import REPO  # noqa: F401  (tests/ on sys.path for tests.support)
from tests.support.kernel_cache import kernel_cpus

KERNELS = "root/.config/blender/4.3/extensions/.user/user_default/drt_engine/kernels"
"""The installed extension's kernel cache, inside the root."""


def test_first_render_after_install_loads_the_shipped_kernels(installed, scenes, measured):
    env = installed
    cache = env.root / KERNELS
    shutil.rmtree(cache, ignore_errors=True)  # as after a fresh install: nothing compiled here yet
    out = env.work / "first_render"
    started = time.monotonic()
    env.blender("-b", env.inside(scenes["cornell_box"]), "-E", "DRT", "-o", env.inside(out / "frame_"), "-f", "1",
                timeout=1200)
    seconds = time.monotonic() - started
    folders = [f.name for f in cache.iterdir() if f.is_dir()]
    cpus = kernel_cpus(cache)
    measured["first_render_after_install"] = {"seconds": round(seconds, 1), "folders": folders,
                                              "kernel_cpus": sorted(cpus)}
    assert len(folders) == 1 and folders[0].startswith("py313-"), folders
    assert cpus == {"generic"}, f"kernels compiled on first render for {sorted(cpus - {'generic'})}"
    assert list(out.glob("frame_*")), "no image written"
