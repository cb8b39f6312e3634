"""What a Dask worker runs: one sample range of one frame, rendered as a part.

bpy is not thread-safe (opening a file or rendering from a Dask worker's task thread
crashes it), so a task renders in a child process, ``python -m drt_engine render
--sample-range``, which also gives each task a fresh Blender. The child dies with its
worker (Linux: PR_SET_PDEATHSIG), so a killed worker leaves nothing running. The .blend
reaches each worker once (the client scatters its bytes to every worker) and is written
to the worker's local directory once.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import embreex  # noqa: F401  (a worker without it must fail the check, not the first task)

from ..core.film import parts

ROOT = Path(__file__).resolve().parents[2]  # where `-m drt_engine` imports this checkout
_files_lock = threading.Lock()


class TaskError(Exception):
    """A task that failed on a worker: the message names the worker and the reason."""


def check() -> None:
    """Run on every worker before the render: DRT, embreex and bpy are importable there."""
    if importlib.util.find_spec("bpy") is None:
        raise ImportError("No module named 'bpy'")


def _blend_file(directory: str, data: bytes, name: str) -> Path:
    """The shipped .blend on this worker's disk, written by the first task that needs it."""
    digest = hashlib.sha256(data).hexdigest()[:16]
    path = Path(directory) / "drt-blend" / digest / name
    with _files_lock:
        if not path.is_file():
            path.parent.mkdir(parents=True, exist_ok=True)
            partial = path.with_suffix(".partial")
            partial.write_bytes(data)
            partial.replace(path)
    return path


def _die_with_parent():  # pragma: no cover (runs in the child)
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def render_range(data: bytes, name: str, options: list[str], frame: int, start: int, end: int):
    """Render samples start..end-1 of ``frame``: (Part, timing dict in seconds)."""
    from distributed import get_worker

    began = time.perf_counter()
    worker = get_worker()
    path = _blend_file(worker.local_directory, data, name)
    with tempfile.TemporaryDirectory(dir=worker.local_directory) as folder:
        out = Path(folder) / "part.exr"
        command = [sys.executable, "-m", "drt_engine", "render", str(path), "-o", str(out),
                   "--frame", str(frame), "--sample-range", f"{start}:{end}", *options]
        before = _children_cpu()
        child = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                 env=_render_environment(), preexec_fn=_die_with_parent if os.name == "posix" else None)
        _, errors = child.communicate()
        if child.returncode != 0:
            lines = [line for line in errors.splitlines() if line.strip()]
            reason = lines[-1] if lines else f"exit code {child.returncode}"
            raise TaskError(f"worker {worker.address}, frame {frame} samples {start}:{end}: {reason}")
        part = parts.read(out)
        cpu = _children_cpu() - before
    stats = part.header["report"]["stats"]
    timing = {"task": time.perf_counter() - began, "render": stats["elapsed"], "cpu": cpu,
              "render_cpu": stats["cpu"], "worker": worker.address}
    return part, timing


def _render_environment() -> dict:
    """The worker's environment without the malloc trim threshold Dask's nanny sets for its workers:
    with it, glibc returns every freed wave array to the system and maps it again (measured on a
    96x96 render of 128 samples: 6.4 CPU seconds instead of 3.4, most of it in the kernel)."""
    return {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}


def _children_cpu() -> float:
    """CPU seconds of this process's finished children: a worker runs one task at a time, so the
    difference around a task is its render process's (a loaded machine stretches wall time, not this)."""
    if os.name != "posix":
        return float("nan")
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime
