"""The core's tests on the root's own Python 3.13 and NumPy 2.2 (the ones Debian's Blender runs
on), every warning an error: the same source runs there as on the wheel's Python 3.11 and
NumPy 1.26 without a warning. embreex is the cp313 wheel the extension installed."""
from __future__ import annotations

import re
import shutil

from blender_env import REPO

SITE_PACKAGES = "/root/.config/blender/4.3/extensions/.local/lib/python3.13/site-packages"
"""Where Blender installed the extension's bundled wheels."""


def test_core_tests_pass_on_python313_numpy22_with_warnings_as_errors(installed, measured):
    env = installed
    copy = env.work / "repo"
    shutil.copytree(REPO / "drt_engine", copy / "drt_engine", ignore=shutil.ignore_patterns("__pycache__"))
    for folder in ("core", "support"):  # the core's tests and the scene builders they import
        shutil.copytree(REPO / "tests" / folder, copy / "tests" / folder, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(REPO / "tests" / "conftest.py", copy / "tests")
    done = env.run("env", f"PYTHONPATH={SITE_PACKAGES}", "sh", "-c",
                   f"cd {env.inside(copy)} && python3 -c 'import sys, numpy; print(sys.version.split()[0], numpy.__version__)'"
                   " && python3 -m pytest tests/core -q -p no:cacheprovider -W error", timeout=1800)
    versions = done.stdout.splitlines()[0].split()
    summary = re.findall(r"^=*\s*(\d+ passed.*?)\s*=*$", done.stdout, re.MULTILINE)
    measured["core_on_python313"] = {"python": versions[0], "numpy": versions[1], "summary": summary}
    assert done.returncode == 0, done.stdout[-6000:]
    assert versions[0].startswith("3.13") and versions[1].startswith("2."), versions
