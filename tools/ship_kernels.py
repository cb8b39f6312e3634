"""Compile DRT's kernels for the extension zip, so that its first render after an install loads
them instead of compiling for minutes (core.base.jit: shipped kernels).

    python tools/ship_kernels.py build ZIP WORK [BLENDER_ROOT]   # what `make extension` runs

``build`` exports the sample scenes and the parity tests' shading scenes (``_shading_scenes``) as
the core's input (``export``, with bpy), renders them under each Python the zip bundles Numba for
(``compile``: this venv's 3.11 and, where ``make blender-env`` made it, the Blender root's 3.13, side
by side) and adds the kernels to the Linux zip (``add``). Kernels compile for Numba's ``generic``
CPU, so they run on any CPU of the platform. The sample scenes render as F12 would (their own
settings and passes, small and few samples) and once more with every pass DRT writes (Cryptomatte,
the data passes: some have kernels of their own); the shading scenes reach the kernels of
procedural textures, other nodes and closures, Ambient Occlusion, Bevel and skies. Kernels a scene
needs beyond those still compile on first use. Windows and macOS zips ship none (no such machine here).
"""
from __future__ import annotations

import dataclasses
import os
import pickle
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WIDTH, SAMPLES = 48, 4


def _shading_scenes():
    """(name, scene builder) of the parity tests' scenes whose shading has kernels of its own (the
    procedural textures, the other shader nodes, the closures the sample scenes lack, as far as this
    Blender has them, Ambient Occlusion and Bevel, each sky model this Blender offers): without them
    a first render with a Noise or Voronoi texture compiled for about 18 s of CPU."""
    import bpy
    from tests.support import node_scenes, procedural_scenes, sky_scenes

    yield "textures", procedural_scenes.grid_scene
    yield "nodes", node_scenes.grid_scene
    closures = [case for case in node_scenes.CLOSURES if bpy.app.version >= case.since]
    yield "closures", lambda: node_scenes.closure_scene(closures)  # Toon, Metallic, thin films, ...
    yield "facing", node_scenes.facing_scene  # Fresnel and Layer Weight
    yield "ambient_occlusion", node_scenes.ambient_occlusion_scene  # they trace rays of their own
    yield "bevel", node_scenes.bevel_scene
    for sky_type in sorted({props["sky_type"] for props in sky_scenes.CASES.values()}):
        if sky_scenes.offered(sky_type):
            yield f"sky_{sky_type.lower()}", lambda t=sky_type: sky_scenes.sky_scene({"sky_type": t}, WIDTH, WIDTH * 3 // 4)


def export(out: Path) -> None:
    """The sample scenes as F12 would render them (SceneData, RenderSettings), and with every pass,
    then the shading scenes (``_shading_scenes``), pickled into ``out``."""
    import bpy

    sys.path.insert(0, str(ROOT))
    import drt_engine
    from bench.scenes import SCENES, load
    from drt_engine.blender.export import export_scene
    from drt_engine.blender.properties import settings_from_scene
    from drt_engine.core.settings import PASSES

    drt_engine.register()
    out.mkdir(parents=True, exist_ok=True)

    def write(name, scene, data, **changes):
        settings = dataclasses.replace(settings_from_scene(scene, bpy.context.view_layer), samples=SAMPLES, **changes)
        (out / f"{name}.pickle").write_bytes(pickle.dumps((data, settings)))

    for name in SCENES:
        scene, data = load(name, WIDTH)
        write(name, scene, data)
        write(f"{name}_every_pass", scene, data, passes=PASSES)
    for name, build in _shading_scenes():
        scene = build()
        write(name, scene, export_scene(bpy.context.evaluated_depsgraph_get()))


def compile_(out: Path, scenes: Path) -> None:
    """Render the pickled scenes with this Python, the kernels compiled for any CPU into ``out``
    (the environment is set before Numba is imported: it reads it once)."""
    os.environ.update(NUMBA_CACHE_DIR=str(out), NUMBA_CPU_NAME="generic", NUMBA_CPU_FEATURES="")
    sys.path.insert(0, os.environ.get("DRT_SHIP_ROOT", str(ROOT)))
    from drt_engine.core.base import jit
    from drt_engine.core.render.render import Renderer

    for path in sorted(scenes.glob("*.pickle")):
        data, settings = pickle.loads(path.read_bytes())
        Renderer(data, settings).render()
        print(f"ship_kernels: {path.stem} rendered, kernels in {jit.cache_dir()}", flush=True)
    jit.mark_compiled()
    for folder in sorted(out.rglob("*"), reverse=True):  # Numba's own locator leaves empty folders
        if folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()


def add(zip_path: Path, out: Path) -> None:
    """``out``'s fingerprint folders into the zip's ``kernels`` folder (the package's, installed)."""
    with zipfile.ZipFile(zip_path, "a", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(out.rglob("*")):
            if path.is_file():
                z.write(path, "kernels/" + path.relative_to(out).as_posix())
    print(f"ship_kernels: {', '.join(p.name for p in sorted(out.iterdir()))} added to {zip_path.name}")


def _in_root(root: Path, scenes: Path) -> tuple[subprocess.Popen, Path]:
    """Start ``compile`` under the Blender root's Python 3.13 with the zip's cp313 wheels; (the
    process, where its kernels land)."""
    work = root / "drt-ship"
    shutil.rmtree(work, ignore_errors=True)
    for wheel in ROOT.glob("wheels/*-cp313-*manylinux*.whl"):
        zipfile.ZipFile(wheel).extractall(work / "site")
    shutil.copytree(ROOT / "drt_engine" / "core", work / "drt_engine" / "core",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (work / "drt_engine" / "__init__.py").write_text("")
    shutil.copy(__file__, work / "ship_kernels.py")
    shutil.copytree(scenes, work / "scenes")
    inside = Path("/drt-ship")
    command = [str(ROOT / "tools" / "blender-chroot.sh"), "--timeout", "3000", str(root), "env",
               f"PYTHONPATH={inside / 'site'}", "DRT_SHIP_ROOT=/drt-ship", "python3", str(inside / "ship_kernels.py"),
               "compile", str(inside / "kernels"), str(inside / "scenes")]
    return subprocess.Popen(command), work / "kernels"


def build(zip_path: Path, work: Path, root: Path | None = None) -> None:
    shutil.rmtree(work, ignore_errors=True)
    subprocess.run([sys.executable, __file__, "export", str(work / "scenes")], check=True,
                   stdout=subprocess.DEVNULL)
    jobs = [(subprocess.Popen([sys.executable, __file__, "compile", str(work / "kernels"), str(work / "scenes")]),
             work / "kernels")]
    if root is not None and (root / ".drt-blender-env").is_file() and os.geteuid() == 0:
        jobs.append(_in_root(root, work / "scenes"))
    else:
        print("ship_kernels: no Blender root (make blender-env) to compile Python 3.13's kernels in; "
              "the zip ships Python 3.11's only")
    for process, _ in jobs:
        if process.wait() != 0:
            sys.exit(f"ship_kernels: compiling the kernels failed ({process.args[-4:]})")
    for _, kernels in jobs[1:]:
        shutil.copytree(kernels, work / "kernels", dirs_exist_ok=True)
    add(zip_path, work / "kernels")
    shutil.rmtree(work)
    if len(jobs) > 1:
        shutil.rmtree(jobs[1][1].parent)


def main(argv: list[str]) -> None:
    command, *paths = argv
    {"export": export, "compile": compile_, "add": add, "build": build}[command](*map(Path, paths))


if __name__ == "__main__":
    main(sys.argv[1:])
