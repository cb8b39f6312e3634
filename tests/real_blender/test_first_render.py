"""The first render after an install loads the kernels the Linux zip ships (tools/ship_kernels.py,
compiled for any CPU) instead of compiling them: a sample scene and a scene of procedural textures
render in Debian's Blender 4.3.2 with nothing compiled for this machine's CPU. Their wall times are
recorded, not asserted (bench/startup.py measures start-up)."""
from __future__ import annotations

import shutil
import time

from blender_env import REPO  # noqa: F401  (tests/ on sys.path for tests.support)
from tests.support.kernel_cache import kernel_cpus

KERNELS = "root/.config/blender/4.3/extensions/.user/user_default/drt_engine/kernels"
"""The installed extension's kernel cache, inside the root."""


def test_first_render_after_install_loads_the_shipped_kernels(installed, scenes, measured):
    """A sample scene, then a scene of procedural textures the sample scenes lack (made in this
    Blender: in_blender/textured_scene.py)."""
    env = installed
    textured = env.work / "textured" / "textured.blend"
    textured.parent.mkdir(exist_ok=True)
    env.blender("-b", "--python", env.inside(env.work / "in_blender" / "textured_scene.py"), "--",
                env.inside(textured))
    cache = env.root / KERNELS
    shutil.rmtree(cache, ignore_errors=True)  # as after a fresh install: nothing compiled here yet
    for name, blend in (("cornell_box", scenes["cornell_box"]), ("textured", textured)):
        out = env.work / "first_render" / name
        started = time.monotonic()
        env.blender("-b", env.inside(blend), "-E", "DRT", "-o", env.inside(out / "frame_"), "-f", "1", timeout=1200)
        seconds = time.monotonic() - started
        folders = [f.name for f in cache.iterdir() if f.is_dir()]
        cpus = kernel_cpus(cache)
        measured[f"first_render_after_install {name}"] = {"seconds": round(seconds, 1), "folders": folders,
                                                          "kernel_cpus": sorted(cpus)}
        assert len(folders) == 1 and folders[0].startswith("py313-"), folders
        assert cpus == {"generic"}, f"{name}: kernels compiled on first render for {sorted(cpus - {'generic'})}"
        assert list(out.glob("frame_*")), f"{name}: no image written"
