"""The version matrix says what it does: docs/blender-versions.md's table is the one the Makefile and CI make, the
extension's oldest Blender is the oldest one tested, and every tested Blender's Python has the
extension's wheels on every platform."""
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
import versions_table  # noqa: E402
from test_extension import WHEEL_TAG  # noqa: E402

MANIFEST = tomllib.loads((ROOT / "blender_manifest.toml").read_text())


def test_docs_table_is_what_the_makefile_and_ci_run():
    page = versions_table.PAGE.read_text()
    start = page.index(versions_table.BEGIN) + len(versions_table.BEGIN)
    assert page[start:page.index(versions_table.END)] == "\n" + versions_table.table(), (
        "docs/blender-versions.md's table is stale: run `python3 bench/versions_table.py --write`")


def test_ci_runs_the_other_versions():
    runs = versions_table.ci_runs()
    assert {"test", "test-blender", "test-versions"} <= set(runs)
    ci = [w.partition("=")[2].split() for w in runs["test-versions"] if w.startswith("BPY_VERSIONS=")]
    tested_in_ci = set(ci[0] if ci else versions_table.matrix_versions()) | {versions_table.DEFAULT}
    assert tested_in_ci == set(versions_table.matrix_versions())


def test_blender_version_min_is_the_oldest_tested_blender():
    oldest = min(versions_table.matrix_versions(), key=lambda v: tuple(map(int, v.split("."))))
    assert MANIFEST["blender_version_min"] == f"{oldest}.0"


def test_wheels_cover_every_tested_python_on_every_platform():
    pythons = {"cp" + versions_table.pins(v)["python"].replace(".", "") for v in versions_table.matrix_versions()}
    pythons.add("cp313")  # Debian's Blender 4.3.2 of `make test-blender`
    for platform in MANIFEST["platforms"]:
        tag = WHEEL_TAG[platform]
        for package in ("embreex", "numba", "llvmlite"):
            have = {w.split("-")[2] for w in MANIFEST["wheels"]
                    if w.split("/")[-1].startswith(package + "-") and w.split("-")[-1].startswith(tag)}
            assert pythons <= have, (platform, package, sorted(pythons - have))
