"""Fixtures for the tests against a real Blender (Debian 13's Blender 4.3.2, Python 3.13,
NumPy 2.2, in the root made by ``make blender-env``), run by ``make test-blender``, which
names the root in DRT_BLENDER_ENV; without it ``make test`` leaves this folder out.

Everything Blender reads or writes lives in ``/drt-test`` inside the root (``work`` on the
host), emptied at the start of each session. The figures the tests measure (image
differences, memory per frame, GUI timings) go to out/real_blender/measurements.json and
are printed at the end of the run.
"""
from __future__ import annotations

import fcntl
import json
import os
import re
import shutil
import time
from pathlib import Path

import pytest

from blender_env import IGNIS_SCENES, MARK, REPO, SAMPLE_SCENES, BlenderEnv, check_output

HERE = Path(__file__).resolve().parent
ZIP = REPO / "dist" / "drt_engine-0.1.0-linux_x64.zip"
IGNIS = Path(os.environ.get("DRT_IGNIS_SCENES", REPO.parent / "shared" / "scenes" / "ignis-cycles-eval"))
"""The Ignis evaluation scenes; without them (a fresh clone) the copies in tests/data."""
WIDTH = 48
"""Width in pixels of every headless render (height keeps the scene's aspect)."""
SAMPLES = 8
MEASUREMENTS = REPO / "out" / "real_blender" / "measurements.json"
LOCK_WAIT = 900.0
"""Seconds a session waits for another one on the same root to finish."""


def copy_ignis(target: Path) -> dict[str, Path]:
    """The Ignis scenes at hand copied to ``target``, keeping their relative texture paths."""
    if IGNIS.is_dir():
        shutil.copytree(IGNIS, target)
    else:  # a fresh clone without ../shared: the copies in tests/data
        (target / "evaluation" / "blender").mkdir(parents=True)
        (target / "textures").mkdir()
        for blend in (REPO / "tests" / "data").glob("*.blend"):
            shutil.copy(blend, target / "evaluation" / "blender")
        shutil.copy(REPO / "tests" / "data" / "grid_weight.png", target / "textures")
    folder = target / "evaluation" / "blender"
    return {f"ignis_{name}": folder / f"{name}.blend" for name in IGNIS_SCENES if (folder / f"{name}.blend").is_file()}


@pytest.fixture(scope="session")
def measured():
    """Figures by test, written to MEASUREMENTS at the end of the session."""
    figures: dict = {}
    yield figures
    MEASUREMENTS.parent.mkdir(parents=True, exist_ok=True)
    MEASUREMENTS.write_text(json.dumps(figures, indent=1, sort_keys=True) + "\n")


def pytest_terminal_summary(terminalreporter):
    if MEASUREMENTS.is_file():
        terminalreporter.section("measured in the real Blender")
        terminalreporter.write_line(MEASUREMENTS.read_text())


@pytest.fixture(scope="session")
def blender_env() -> BlenderEnv:
    root = os.environ.get("DRT_BLENDER_ENV")
    if not root or not (Path(root) / MARK).is_file():
        pytest.fail("no Blender root: run `make test-blender` (it builds one with `make blender-env`)")
    root = Path(root).resolve()
    with open(root / ".drt-test.lock", "w") as lock:
        wait_for_lock(lock)
        yield from session_env(root)


def wait_for_lock(lock) -> None:
    """One test session at a time per root: they share its Blender's user extensions and /drt-test."""
    started = time.monotonic()
    while True:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() - started > LOCK_WAIT:
                pytest.fail(f"another test session has held {lock.name} for {LOCK_WAIT:.0f} s")
            time.sleep(2.0)


def session_env(root: Path):
    work = root / "drt-test"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir()
    shutil.copytree(HERE / "in_blender", work / "in_blender")
    env = BlenderEnv(root, work)
    yield env
    assert env.processes_inside() == [], "processes left running in the Debian root"
    assert env.mounts_inside() == [], "file systems left mounted in the Debian root"


def check_install(output: str, what: str, failed: bool) -> None:
    """Blender's extension tool leaves a file unclosed (a ResourceWarning in bl_pkg): only
    warnings about our files count here."""
    check_output(output, what, failed, warnings=re.compile(r"^\S*drt_engine\S*:\d+: \w*Warning: .*$", re.M))


@pytest.fixture(scope="session")
def installed(blender_env) -> BlenderEnv:
    """The extension zip from `make extension` installed into the root's Blender (user_default)."""
    if not ZIP.is_file():
        pytest.fail(f"{ZIP} is missing: run `make extension`")
    zip_copy = blender_env.work / ZIP.name
    shutil.copy(ZIP, zip_copy)
    output = blender_env.blender("--command", "extension", "install-file", "-r", "user_default", "-e",
                                 blender_env.inside(zip_copy), check=check_install)
    assert "nstalled \"drt_engine\"" in output, output  # "Installed", or "Reinstalled" over an earlier run
    return blender_env


@pytest.fixture(scope="session")
def scenes(installed) -> dict[str, Path]:
    """Host paths of small copies of the sample scenes (built by their scripts inside Blender 4.3,
    which cannot open the committed 5.0 files) and of the Ignis scenes, saved by Blender 4.3 with
    DRT selected, WIDTH pixels wide, SAMPLES samples, seed 0 and the Noise pass; the bpy wheel
    (Blender 5.0) opens these files too."""
    env = installed
    shutil.copytree(REPO / "sample_scenes", env.work / "sample_scenes",
                    ignore=shutil.ignore_patterns("*.blend", "*.blend1", "__pycache__"))
    built = env.work / "built"
    for name in SAMPLE_SCENES:
        env.blender("-b", "--factory-startup", "--python", env.inside(env.work / "sample_scenes" / f"build_{name}.py"),
                    "--", env.inside(built / f"{name}.blend"))
    sources = {name: built / f"{name}.blend" for name in SAMPLE_SCENES}
    sources.update(copy_ignis(env.work / "ignis"))
    (env.work / "scenes").mkdir()
    prepared = {name: env.work / "scenes" / f"{name}.blend" for name in sources}
    jobs = [arg for name in sources for arg in (env.inside(sources[name]), env.inside(prepared[name]))]
    env.blender("-b", "--python", env.inside(env.work / "in_blender" / "prepare_scenes.py"), "--",
                str(WIDTH), str(SAMPLES), *jobs)
    return prepared
