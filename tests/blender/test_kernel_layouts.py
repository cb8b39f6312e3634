"""Each kernel compiles once for the array layouts it is given: the sample scenes rendered through
the engine (F12's path) in a fresh process, and one pixel's single sample, leave no kernel compiled
twice for arguments that differ only in layout (a strided view where another call passes a
C-contiguous array).

Numba compiles, and caches, one specialization per layout. The camera's rays were views such as
``out[:, :3]``, which NumPy flags contiguous when they hold one row: a wave of one sample (a
border, an adaptive round's last pixels) compiled the largest kernels (direct_light, surface_hits)
again, and a GUI render compiled for minutes what a headless one of the same scene had compiled.
"""
import json
import re
import subprocess
import sys
from pathlib import Path

from tests.support.sample_scene_files import SCENES

ROOT = Path(__file__).resolve().parents[2]

RENDER_AND_LIST = r"""
import importlib, json, pkgutil, sys
import bpy, numba
sys.path.insert(0, sys.argv[1])
import drt_engine, drt_engine.core
drt_engine.register()
def render(path, width, height, samples, border=None):
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = width, height, 100
    scene.render.use_border = border is not None
    if border is not None:
        (scene.render.border_min_x, scene.render.border_max_x,
         scene.render.border_min_y, scene.render.border_max_y) = border
    scene.drt.samples = samples
    scene.render.filepath = sys.argv[2]
    bpy.ops.render.render(write_still=True)
for path in sys.argv[3:]:
    render(path, 24, 16, 4)
# one pixel's one sample: a wave of one ray, whose strided views NumPy flags contiguous
render(sys.argv[3], 8, 8, 1, (0.5, 0.625, 0.5, 0.625))
found = {}
for info in pkgutil.walk_packages(drt_engine.core.__path__, "drt_engine.core."):
    for name, value in vars(importlib.import_module(info.name)).items():
        if isinstance(value, numba.core.dispatcher.Dispatcher):
            found[value.py_func.__module__ + "." + name] = [", ".join(map(str, sig)) for sig in value.signatures]
print("SIGNATURES " + json.dumps(found))
from drt_engine.headless.cli import exit_now
exit_now(0)  # bpy 4.2 crashes in Python's teardown
"""


def _layout_free(signature: str) -> str:
    """A signature as Numba prints its types (``array(float64, 2d, A)``) without the layouts."""
    return re.sub(r"(array\([^()]*), [CAF]\)", r"\1)", signature)


def test_no_kernel_compiles_twice_for_a_layout(tmp_path, sample_scene):
    done = subprocess.run([sys.executable, "-c", RENDER_AND_LIST, str(ROOT), str(tmp_path / "frame"),
                           *(str(sample_scene(name)) for name in SCENES)],
                          capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stderr[-3000:]
    traced = [line for line in done.stdout.splitlines() if line.startswith("DRT: rays traced:")]
    assert len(traced) == len(SCENES) + 1 and traced[-1].startswith("DRT: rays traced: camera 1,"), traced
    line = next(line for line in done.stdout.splitlines() if line.startswith("SIGNATURES "))
    signatures = json.loads(line.removeprefix("SIGNATURES "))
    direct = signatures["drt_engine.core.integrator.direct.direct_light"]
    assert direct, "the renders ran no direct light"
    assert _layout_free(direct[0]) != direct[0], f"no layout found to compare in {direct[0]}"
    twice = {}
    for kernel, sigs in signatures.items():
        keys = [_layout_free(s) for s in sigs]
        doubled = [s for s, key in zip(sigs, keys) if keys.count(key) > 1]
        if doubled:
            twice[kernel] = len(doubled)
    assert not twice, f"kernels compiled again for other array layouts (signatures): {twice}"
