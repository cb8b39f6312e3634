"""docs/blender-versions.md's "Tested Blender versions" table, made from what the Makefile and CI run.

The rows come from the Makefile's ``BPY_VERSIONS`` (each version's requirements file gives its bpy,
NumPy and Python) and from the ``make`` lines of ``.ci/run`` (which targets CI runs, and for which
versions); the Debian binary of ``make test-blender`` is the one row written here. ``--write``
puts the table into docs/blender-versions.md between its markers; without it the table is printed.
tests/blender/test_version_matrix.py fails while that page's table differs from this output.
"""
from __future__ import annotations

import re
import shlex
import sys
from pathlib import Path

from blocks import replace_between

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "blender-versions.md"
BEGIN, END = "<!-- versions table: begin -->", "<!-- versions table: end -->"
DEFAULT = "5.0"  # the pinned default: .venv from requirements.txt
NAMES = {"4.2": "4.2 LTS", "5.2": "5.2 LTS"}


def matrix_versions() -> list[str]:
    match = re.search(r"^BPY_VERSIONS \?= (.+)$", (ROOT / "Makefile").read_text(), re.MULTILINE)
    return match[1].split()


def requirements(version: str) -> Path:
    return ROOT / ("requirements.txt" if version == DEFAULT else f"requirements-{version}.txt")


def pins(version: str) -> dict[str, str]:
    """bpy's and numpy's pinned versions and the venv's Python from a requirements file."""
    text = requirements(version).read_text()
    found = dict(re.findall(r"^(bpy|numpy)==(\S+)$", text, re.MULTILINE))
    found["python"] = re.search(r"^# python: *([0-9.]+)", text, re.MULTILINE)[1]
    return found


def ci_runs() -> dict[str, list[str]]:
    """make target -> its variable assignments, for each ``make`` line of .ci/run (run as is or
    through its ``stage`` timer)."""
    runs = {}
    for line in (ROOT / ".ci" / "run").read_text().splitlines():
        words = shlex.split(line, comments=True)
        if words[:1] == ["stage"]:
            words = words[1:]
        if words[:1] == ["make"]:
            targets = [w for w in words[1:] if "=" not in w]
            for target in targets:
                runs[target] = [w for w in words[1:] if "=" in w]
    return runs


def table() -> str:
    runs = ci_runs()
    versions = matrix_versions()
    ci_versions = versions
    for assignment in runs.get("test-versions", []):
        name, _, value = assignment.partition("=")
        if name == "BPY_VERSIONS":
            ci_versions = value.split()
    rows = ["| Blender | Python, NumPy | tested by | in CI (`.ci/run`) |", "|---|---|---|---|"]
    for version in versions:
        pin = pins(version)
        venv = ".venv" if version == DEFAULT else f".venv-{version}"
        how = [f"`make test-versions`: tests/core and tests/blender in `{venv}`"]
        in_ci = []
        if version == DEFAULT:
            how.insert(0, "`make test`: the whole suite")
            if "test" in runs:
                in_ci.append("`make test`")
        if "test-versions" in runs and version in ci_versions:
            in_ci.append("`make test-versions`")
        rows.append(f"| {NAMES.get(version, version)} as a Python module (`bpy` {pin['bpy']}) "
                    f"| {pin['python']}, {pin['numpy']} | {'; '.join(how)} | {', '.join(in_ci) or 'no'} |")
    rows.append("| 4.3.2 binary (Debian 13's `blender` package) | 3.13, 2.2 | `make test-blender`: the extension zip "
                f"installed and used as users do | {'`make test-blender`' if 'test-blender' in runs else 'no'} |")
    return "\n".join(rows) + "\n"


def write_page() -> None:
    replace_between(PAGE, BEGIN, END, table())


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        write_page()
    else:
        sys.stdout.write(table())
