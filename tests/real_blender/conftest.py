"""Fixtures for the tests against a real Blender (Debian 13's Blender 4.3.2 in the root made by
``make blender-env``), run by ``make test-blender``.

``make test`` collects nothing here: the test modules are named ``check_*.py``, which pytest
collects only when they are named on its command line, as ``make test-blender`` does. This file
stays import-light because ``make test`` still imports it.

Everything Blender reads or writes lives in ``/drt-test`` inside the root (``work`` on the host),
emptied at the start of each session; commands run through ``tools/blender-chroot.sh``, which
mounts /proc and /dev for each command only.
"""
from __future__ import annotations

import os
import shutil
import signal
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
CHROOT = REPO / "tools" / "blender-chroot.sh"
ZIP = REPO / "dist" / "drt_engine-0.1.0-linux_x64.zip"
IGNIS = Path(os.environ.get("DRT_IGNIS_SCENES", REPO.parent / "shared" / "scenes" / "ignis-cycles-eval"))
SAMPLE_SCENES = ("cornell_box", "glossy_spheres", "dof_row", "motion_blur")
IGNIS_SCENES = ("lights", "box", "roughness", "sun", "mix", "flipped-prim")
WIDTH = 32
"""Width in pixels of every headless render (height keeps the scene's aspect)."""
SAMPLES = 8


@dataclass
class BlenderEnv:
    root: Path
    work: Path

    def inside(self, path: Path) -> str:
        """The path Blender sees for a host path under the root."""
        return "/" + str(Path(path).relative_to(self.root))

    def run(self, *args: str, timeout: float = 300.0) -> subprocess.CompletedProcess:
        """Run a command in the root; on timeout TERM its process group (the wrapper unmounts)."""
        process = subprocess.Popen([str(CHROOT), str(self.root), *args], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, start_new_session=True)
        try:
            output, _ = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGTERM)
            output, _ = process.communicate(timeout=30)
            pytest.fail(f"timed out after {timeout} s: {' '.join(args)}\n{output[-4000:]}")
        return subprocess.CompletedProcess(args, process.returncode, output, "")

    def script(self, name: str) -> str:
        """Path inside the root of one of the scripts in tests/real_blender/in_blender."""
        return self.inside(self.work / "in_blender" / name)

    def blender(self, *args: str, timeout: float = 300.0) -> str:
        """Run Blender; fail with its output on a non-zero exit or a Python traceback."""
        done = self.run("blender", *args, timeout=timeout)
        if done.returncode != 0 or "Traceback" in done.stdout:
            pytest.fail(f"blender {' '.join(args)} exited with {done.returncode}:\n{done.stdout[-4000:]}")
        return done.stdout


@pytest.fixture(scope="session")
def blender_env() -> BlenderEnv:
    root = os.environ.get("DRT_BLENDER_ENV")
    if not root or not (Path(root) / ".drt-blender-env").is_file():
        pytest.fail("no Blender root: run `make test-blender` (it builds one with `make blender-env`)")
    root = Path(root)
    work = root / "drt-test"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir()
    shutil.copytree(HERE / "in_blender", work / "in_blender")
    return BlenderEnv(root, work)


@pytest.fixture(scope="session")
def installed(blender_env) -> BlenderEnv:
    """The extension zip from `make extension` installed into the root's Blender (user_default)."""
    if not ZIP.is_file():
        pytest.fail(f"{ZIP} is missing: run `make extension`")
    zip_copy = blender_env.work / ZIP.name
    shutil.copy(ZIP, zip_copy)
    output = blender_env.blender("--command", "extension", "install-file", "-r", "user_default", "-e",
                                 blender_env.inside(zip_copy))
    assert "Error" not in output, output
    return blender_env


@pytest.fixture(scope="session")
def scenes(installed) -> dict[str, Path]:
    """Host paths of tiny copies of the sample scenes (built by their scripts inside Blender 4.3,
    which cannot open the committed 5.0 files) and of the Ignis scenes, saved by Blender 4.3 with
    DRT selected, WIDTH pixels wide, SAMPLES samples, seed 0; so Blender 5.0 opens them too."""
    env = installed
    shutil.copytree(REPO / "sample_scenes", env.work / "sample_scenes",
                    ignore=shutil.ignore_patterns("*.blend", "*.blend1", "__pycache__"))
    built = env.work / "built"
    for name in SAMPLE_SCENES:
        env.blender("-b", "--factory-startup", "--python", env.inside(env.work / "sample_scenes" / f"build_{name}.py"),
                    "--", env.inside(built / f"{name}.blend"))
    sources = {name: built / f"{name}.blend" for name in SAMPLE_SCENES}
    if IGNIS.is_dir():
        shutil.copytree(IGNIS, env.work / "ignis")
        for name in IGNIS_SCENES:
            sources[f"ignis_{name}"] = env.work / "ignis" / "evaluation" / "blender" / f"{name}.blend"
    (env.work / "scenes").mkdir()
    prepared = {name: env.work / "scenes" / f"{name}.blend" for name in sources}
    jobs = [arg for name in sources for arg in (env.inside(sources[name]), env.inside(prepared[name]))]
    env.blender("-b", "--python", env.script("prepare_scenes.py"), "--",
                str(WIDTH), str(SAMPLES), *jobs)
    return prepared
