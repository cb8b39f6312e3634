"""Running Debian's Blender 4.3.2 in the root made by ``make blender-env``, from the host.

Every command goes through ``tools/blender-chroot.sh --timeout``, which mounts /proc and
/dev in a mount namespace of that command's own (gone with it, however it ends) and kills
the command's whole process group when it overruns; the host waits a little longer than
that and then kills the wrapper.
Blender runs with Python's warnings shown (``PYTHONWARNINGS=default`` read through
``--python-use-system-env``), so a Python warning fails the test that ran it.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

REPO = Path(__file__).resolve().parents[2]
CHROOT = REPO / "tools" / "blender-chroot.sh"
MARK = ".drt-blender-env"
SAMPLE_SCENES = ("cornell_box", "glossy_spheres", "dof_row", "motion_blur")
IGNIS_SCENES = ("lights", "box", "roughness", "sun", "mix", "flipped-prim")
"""File tools/blender-env.sh writes into a finished root."""

PYTHON_WARNING = re.compile(r"^\S+:\d+: \w*Warning: .*$", re.MULTILINE)
"""A line written by Python's warnings module (``file:line: Category: message``). Blender's own
renders and GUI give none, so any is ours, also one raised in Blender's modules by our calls
(gpu_extras' triangle fan); only its extension tool has one of its own (see ``install``)."""

BLENDER_PROBLEM = re.compile(r"^(?:Traceback|Error:|ERROR|.*DRT internal).*$", re.MULTILINE)
"""Lines of Blender's output that report a failure (operator reports are printed too)."""


@dataclass
class BlenderEnv:
    root: Path
    work: Path
    """Everything Blender reads or writes, ``/drt-test`` inside the root."""

    def inside(self, path: Path) -> str:
        """The path Blender sees for a host path under the root."""
        return "/" + str(Path(path).relative_to(self.root))

    def run(self, *args: str, timeout: int = 240) -> subprocess.CompletedProcess:
        """Run a command in the root, stdout and stderr together; fail the test on a timeout."""
        command = [str(CHROOT), "--timeout", str(timeout), str(self.root), *args]
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                   start_new_session=True)
        try:
            output, _ = process.communicate(timeout=timeout + 30)
        except subprocess.TimeoutExpired:  # the wrapper itself hangs: last resort
            os.killpg(process.pid, signal.SIGKILL)
            output, _ = process.communicate(timeout=30)
        if process.returncode == 124 or process.returncode == -signal.SIGKILL:
            pytest.fail(f"timed out after {timeout} s: {' '.join(args)}\n{output[-4000:]}")
        return subprocess.CompletedProcess(args, process.returncode, output, "")

    def blender(self, *args: str, timeout: int = 240, check=None) -> str:
        """Run Blender; fail with its output on a non-zero exit, a reported error or a Python warning."""
        done = self.run("env", "PYTHONWARNINGS=default", "blender", "--python-use-system-env", *args,
                        timeout=timeout)
        (check or check_output)(done.stdout, f"blender {' '.join(args)} exited with {done.returncode}",
                                done.returncode != 0)
        return done.stdout

    def processes_inside(self) -> list[str]:
        """Names of the processes whose root directory is this root (none once a command is done)."""
        names = []
        for proc in Path("/proc").iterdir():
            try:
                if proc.name.isdigit() and os.readlink(proc / "root") == str(self.root):
                    names.append((proc / "comm").read_text().strip())
            except OSError:  # gone meanwhile, or not ours to read
                pass
        return names

    def mounts_inside(self) -> list[str]:
        with open("/proc/self/mounts") as mounts:
            return [line.split()[1] for line in mounts if line.split()[1].startswith(f"{self.root}/")]


def check_output(output: str, what: str, failed: bool = False, warnings: re.Pattern = PYTHON_WARNING) -> None:
    """Fail when Blender's output reports an error or holds a Python warning."""
    problems = BLENDER_PROBLEM.findall(output) + warnings.findall(output)
    if failed or problems:
        pytest.fail(f"{what}: {problems}\n{output[-4000:]}")


def read_passes(path: Path, *names: str) -> list[np.ndarray]:
    """The RGB of passes of an EXR: single-layer R, G, B is Combined; multilayer *.NAME.R, ..."""
    image = oiio.ImageInput.open(str(path))
    assert image is not None, oiio.geterror()
    try:
        spec = image.spec()
        pixels = image.read_image(format="float").reshape(spec.height, spec.width, spec.nchannels)
    finally:
        image.close()
    channels = list(spec.channelnames)

    def index(name: str, c: str) -> int:
        return next(i for i, n in enumerate(channels)
                    if n.endswith(f".{name}.{c}") or n == f"{name}.{c}" or (name == "Combined" and n == c))

    return [pixels[..., [index(name, c) for c in "RGB"]] for name in names]
