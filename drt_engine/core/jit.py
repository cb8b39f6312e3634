"""Compiled kernels: the one decorator for DRT's per-ray loops, and where their machine code lives.

Every kernel is a Numba ``njit`` function compiled on first call and cached on disk, so only
the first render after an install pays for compiling. Kernels release the GIL and run
serially: the renderer splits a wave into one piece per thread itself (pieces in a thread
pool, Embree calls between them), so no Numba threading layer is ever started and two renders
in one process (viewport during F12, a material preview) cannot contend for one.

The cache folder must be chosen before the modules that define kernels are imported: the
Blender layer calls ``use_cache_dir`` with the extension's user folder; the CLI and the tests
get the user's cache folder (``default_cache_dir``), and ``NUMBA_CACHE_DIR`` overrides both.
A read-only package folder is never written to.
"""
from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

_ENV = "NUMBA_CACHE_DIR"


def default_cache_dir() -> Path:
    """The user's cache folder for DRT's kernels (XDG on Linux, Library/Caches, LOCALAPPDATA)."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "drt" / "kernels"


if not os.environ.get(_ENV):
    os.environ[_ENV] = str(default_cache_dir())

import numba  # noqa: E402  (after the cache folder is known: Numba reads it at import)


def use_cache_dir(path) -> None:
    """Cache compiled kernels under ``path`` (call before kernel modules are imported)."""
    path = str(Path(path) / "kernels")
    os.environ[_ENV] = path
    numba.config.CACHE_DIR = path


def cache_dir() -> Path:
    return Path(numba.config.CACHE_DIR)


def kernel(fn=None, **options):
    """``@kernel``: compile ``fn`` with Numba, cached on disk, GIL released, NumPy's float rules.

    ``error_model="numpy"`` makes a division by zero give inf/nan as NumPy does (no Python
    exception from inside a loop, and no check per division); kernels guard their divisions.
    """
    opts = {"cache": True, "nogil": True, "error_model": "numpy"}
    opts.update(options)
    if fn is None:
        return lambda f: numba.njit(**opts)(f)
    return numba.njit(**opts)(fn)


def _fingerprint() -> str:
    """What decides whether cached kernels can be loaded: DRT's core sources, Numba, Python."""
    h = hashlib.sha256(f"{numba.__version__} {sys.version_info[:2]} {sys.platform}".encode())
    for source in sorted(Path(__file__).parent.rglob("*.py")):
        h.update(source.read_bytes())
    return h.hexdigest()[:16]


def _stamp() -> Path:
    return cache_dir() / f"drt-{_fingerprint()}.compiled"


def first_run() -> bool:
    """True until a render has compiled this version's kernels into the cache folder."""
    return not _stamp().exists()


def mark_compiled() -> None:
    """Record that this version's kernels are in the cache (best effort: a read-only cache folder
    only means the message shows again)."""
    try:
        stamp = _stamp()
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.touch()
    except OSError:
        pass
