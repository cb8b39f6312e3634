"""`make extension` builds, with Blender's own extension tool, one zip per platform that Blender's
validator accepts, holding the package at the zip root, the manifest and exactly that platform's
embreex wheels, and nothing from the development tree. The zipped package imports and registers
under Blender's extension namespace, which only works with relative imports inside drt_engine."""
import subprocess
import sys
import textwrap
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MANIFEST = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
# Blender platform -> the wheel platform tag prefix PyPI uses for it.
WHEEL_TAG = {"linux-x64": "manylinux", "windows-x64": "win_amd64", "macos-arm64": "macosx"}
DEV_ONLY = ("tests/", "bench/", "sample_scenes/", ".venv/", ".git", "out/", "dist/")


def blender_ext():
    import bpy

    return Path(bpy.utils.system_resource("SCRIPTS"), "addons_core", "bl_pkg", "cli", "blender_ext.py")


@pytest.fixture(scope="module")
def dist(tmp_path_factory):
    """Run the real make target into a temporary dist folder (downloads the wheels if missing),
    without compiling the kernels the Linux zip ships (minutes of both cores; make test-blender
    installs a zip with them and checks its first render compiles nothing)."""
    out = tmp_path_factory.mktemp("dist")
    proc = subprocess.run(
        ["make", "-C", str(ROOT), "--no-print-directory", "extension", f"DIST={out}", "KERNELS="],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return out


def zip_for(dist, platform):
    name = f"{MANIFEST['id']}-{MANIFEST['version']}-{platform.replace('-', '_')}.zip"
    return dist / name


def test_manifest_declares_the_contract():
    assert MANIFEST["id"] == "drt_engine"
    assert MANIFEST["type"] == "add-on"
    assert MANIFEST["blender_version_min"] == "4.2.0"
    assert "Render" in MANIFEST["tags"]
    assert MANIFEST["license"] == ["SPDX:GPL-3.0-or-later"]
    assert set(MANIFEST["platforms"]) == set(WHEEL_TAG)
    assert not any("numpy" in wheel for wheel in MANIFEST["wheels"]), "Blender ships numpy"
    for platform, tag in WHEEL_TAG.items():
        pythons = {w.split("-")[2] for w in MANIFEST["wheels"] if w.split("-")[-1].startswith(tag)}
        assert pythons == {"cp311", "cp313"}, (platform, pythons)


def test_one_zip_per_platform_and_nothing_else(dist):
    assert sorted(p.name for p in dist.iterdir()) == sorted(zip_for(dist, p).name for p in MANIFEST["platforms"])


@pytest.mark.parametrize("platform", sorted(WHEEL_TAG))
def test_blender_validator_accepts_the_zip(dist, platform):
    proc = subprocess.run(
        [sys.executable, str(blender_ext()), "validate", str(zip_for(dist, platform))],
        capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.parametrize("platform", sorted(WHEEL_TAG))
def test_zip_holds_the_package_and_this_platforms_wheels_only(dist, platform):
    with zipfile.ZipFile(zip_for(dist, platform)) as archive:
        names = set(archive.namelist())
        manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())

    sources = {p.relative_to(ROOT / "drt_engine").as_posix() for p in (ROOT / "drt_engine").rglob("*.py")}
    assert "__init__.py" in names
    assert sources <= names, sorted(sources - names)

    wheels = {n for n in names if n.endswith(".whl")}
    expected = {w.removeprefix("./") for w in MANIFEST["wheels"] if w.split("-")[-1].startswith(WHEEL_TAG[platform])}
    assert wheels == expected
    assert manifest["build"]["generated"]["platforms"] == [platform]

    strays = sorted(n for n in names if n.startswith(DEV_ONLY) or "__pycache__" in n or n.endswith(".pyc"))
    assert not strays
    assert not any(n.endswith(".blend") or "numpy" in n for n in names)


def test_zipped_package_registers_under_the_extension_namespace(dist, tmp_path):
    """Blender imports an installed extension as bl_ext.<repo>.<id> (here extensions.user_default.drt_engine,
    bpy already owns bl_ext) with the repo root off sys.path."""
    package = tmp_path / "extensions" / "user_default" / "drt_engine"
    with zipfile.ZipFile(zip_for(dist, "linux-x64")) as archive:
        archive.extractall(package)
    script = textwrap.dedent("""
        import os
        import sys
        import bpy
        sys.path = [p for p in sys.path if p not in ("", %r)]
        sys.path.insert(0, %r)
        import importlib
        ext = importlib.import_module("extensions.user_default.drt_engine")
        ext.register()
        bpy.context.scene.render.engine = "DRT"  # a TypeError unless the engine is registered
        ext.unregister()
        bpy.context.scene.render.engine = "CYCLES"
        try:
            bpy.context.scene.render.engine = "DRT"
        except TypeError:
            pass
        else:
            raise AssertionError("DRT still registered after unregister()")
        assert not any(m.startswith("drt_engine") for m in sys.modules), "imported the repo copy"
        print("ok", flush=True)
        os._exit(0)  # no interpreter teardown: the bpy 4.2 module crashes there (tests/blender/conftest.py)
    """) % (str(ROOT), str(tmp_path))
    proc = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip().endswith("ok"), proc.stdout[-2000:] + proc.stderr[-3000:]


WHEEL_CHECK = """
import sys
sys.path.insert(0, %r)
import numpy as np
import embreex, llvmlite, numba
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh
for module in (embreex, llvmlite, numba):
    assert module.__file__.startswith(sys.path[0]), module.__file__

@numba.njit(cache=False, nogil=True)
def total(values):
    sum = 0.0
    for value in values:
        sum += value
    return sum

assert total(np.arange(10.0)) == 45.0
scene = rtcore_scene.EmbreeScene()
TriangleMesh(scene, np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]], np.int32))
hits = scene.run(np.array([[0, 0, 1], [5, 5, 1]], np.float32), np.array([[0, 0, -1], [0, 0, -1]], np.float32))
assert hits.tolist() == [0, -1], hits
print("ok", numba.__version__, np.__version__)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the zips' wheels are checked on Linux")
def test_zip_bundles_working_wheels_for_this_python(dist, tmp_path):
    """The linux-x64 zip holds embreex, numba and llvmlite wheels for this Blender's Python, and they
    work unpacked as Blender installs an extension's wheels (a folder of their own on sys.path), with
    this Python and its NumPy: run under each version of `make test-versions`, this checks that the
    bundled wheels cover each version's Python."""
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    site = tmp_path / "site-packages"
    with zipfile.ZipFile(zip_for(dist, "linux-x64")) as archive:
        wheels = [n for n in archive.namelist() if n.endswith(".whl") and f"-{tag}-" in n]
        assert sorted(w.split("/")[-1].split("-")[0] for w in wheels) == ["embreex", "llvmlite", "numba"], wheels
        for wheel in wheels:
            archive.extract(wheel, tmp_path)
    for wheel in wheels:
        with zipfile.ZipFile(tmp_path / wheel) as archive:
            archive.extractall(site)
    proc = subprocess.run([sys.executable, "-c", WHEEL_CHECK % str(site)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and proc.stdout.startswith("ok"), proc.stdout[-2000:] + proc.stderr[-3000:]
