"""Compiled kernels: the one decorator for DRT's per-ray loops, and where their machine code lives.

Every kernel is a Numba ``njit`` function compiled on first call and cached on disk, so only
the first render after an install pays for compiling. Kernels release the GIL and run
serially: the renderer splits a wave into one piece per thread itself (pieces in a thread
pool, Embree calls between them), so no Numba threading layer is ever started and two renders
in one process (viewport during F12, a material preview) cannot contend for one.

Numba checks a cached kernel against its own source file only, not against the files of the
kernels it calls: a kernel cached before ``microfacet.py`` changed would be loaded stale. So
the cache lives in a folder named by a fingerprint of all of DRT's core sources (every file
under ``core/``, subpackages included), Numba and
Python (``_fingerprint``); a changed source means a new folder. The most recently used folders of
one Python are kept (``KEEP``; a folder being filled counts as used now), so that two checkouts or
extension versions sharing the user's cache folder do not wipe each other's kernels; a file or
folder removed while a render loads from it or saves into it costs a recompile, never an error
(``_SharedFolderCache``).

The cache's base folder must be chosen before the modules that define kernels are imported:
the Blender layer calls ``use_cache_dir`` with the extension's user folder; the CLI and the
tests get the user's cache folder (``default_cache_dir``), and ``NUMBA_CACHE_DIR`` overrides
both. A read-only package folder is never written to.

Kernels can ship with the extension (``tools/ship_kernels.py``, run by ``make extension``): a
fingerprint folder compiled for any CPU of the platform (Numba's ``generic`` CPU) under the
package's ``kernels`` folder. Where the user's cache has no folder for this fingerprint yet, the
shipped one is copied in (``_seed``), and a kernel with no entry for this machine's CPU loads the
portable entry (``_SharedFolderCache._load_portable``): the first render after an install loads
instead of compiling. Kernels cache under their path inside the package (``_PackageLocator``), not
under a hash of the folder they were installed in, and the module names an entry holds are read as
the installed package's (``_Unpickler``), so the shipped folder fits any install.
"""
from __future__ import annotations

import hashlib
import os
import pickle
import re
import shutil
import sys
from pathlib import Path

import numba
from numba.core import environment
from numba.core.caching import (CompileResultCacheImpl, FunctionCache, IndexDataCacheFile,
                                UserProvidedCacheLocator)

_STAMP = "compiled"  # written into a cache folder once a render has filled it; touched by each render
KEEP = 4
"""Fingerprint folders kept per Python, the most recently used first."""
PORTABLE_CPU = ("generic", "")
"""Numba's CPU name and features for kernels that run on any CPU of the platform (what
``NUMBA_CPU_NAME=generic`` compiles for): the shipped kernels."""
_PACKAGE = Path(__file__).resolve().parents[2]
SHIPPED = _PACKAGE / "kernels"
"""Where an extension build puts its compiled kernels, one fingerprint folder per Python (none
in a checkout)."""


def default_cache_dir() -> Path:
    """The user's cache folder for DRT's kernels (XDG on Linux, Library/Caches, LOCALAPPDATA)."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "drt" / "kernels"


def _fingerprint() -> str:
    """What decides whether cached kernels can be loaded: DRT's core sources, Numba, Python."""
    h = hashlib.sha256(f"{numba.__version__} {sys.version_info[:2]} {sys.platform}".encode())
    core = Path(__file__).resolve().parents[1]
    for source in sorted(core.rglob("*.py")):
        h.update(str(source.relative_to(core)).encode())
        h.update(source.read_bytes())
    return f"py{sys.version_info[0]}{sys.version_info[1]}-{h.hexdigest()[:16]}"


_FINGERPRINT = _fingerprint()
_base = Path(os.environ.get("NUMBA_CACHE_DIR") or default_cache_dir())


def _apply() -> None:
    numba.config.CACHE_DIR = str(_base / _FINGERPRINT)


_seeded: set[Path] = set()


def _seed(shipped: Path, folder: Path) -> None:
    """Copy the shipped kernels into a cache folder this fingerprint does not have yet: into a
    folder of this process's own, renamed into place whole, so that another process never reads
    a half-copied index (best effort: where it cannot, kernels compile as without)."""
    if not shipped.is_dir() or folder.exists():
        return
    partial = folder.with_name(f"{folder.name}.{os.getpid()}.partial")
    try:
        shutil.copytree(shipped, partial)
        partial.rename(folder)
    except OSError:
        pass
    shutil.rmtree(partial, ignore_errors=True)


def use_cache_dir(path) -> None:
    """Cache compiled kernels under ``path``/kernels (call before kernel modules are imported)."""
    global _base
    _base = Path(path) / "kernels"
    _apply()


def cache_dir() -> Path:
    return Path(numba.config.CACHE_DIR)


_apply()


def kernel(fn=None, **options):
    """``@kernel``: compile ``fn`` with Numba, cached on disk, GIL released, NumPy's float rules.

    ``error_model="numpy"`` makes a division by zero give inf/nan as NumPy does (no Python
    exception from inside a loop, and no check per division); kernels guard their divisions.
    """
    opts = {"cache": True, "nogil": True, "error_model": "numpy"}
    opts.update(options)

    def compile_(f):
        caching = opts["cache"] and not numba.config.DISABLE_JIT  # NUMBA_DISABLE_JIT: the plain function
        if caching and cache_dir() not in _seeded:  # the folder chosen by now (``use_cache_dir``), once,
            _seeded.add(cache_dir())  # before Numba's own cache makes folders in it
            _seed(SHIPPED / _FINGERPRINT, cache_dir())
        dispatcher = numba.njit(**opts)(f)
        if caching:
            dispatcher._cache = _SharedFolderCache(dispatcher.py_func)
        return dispatcher

    return compile_ if fn is None else compile_(fn)


class _PackageLocator(UserProvidedCacheLocator):
    """A kernel of ``drt_engine/core/bsdf/x.py`` caches in ``<fingerprint folder>/core/bsdf``
    (Numba's own locator names the folder by a hash of its absolute path, which differs with
    every install); a kernel outside the package (a test's) keeps Numba's folder."""

    @classmethod
    def get_suitable_cache_subpath(cls, py_file):
        folder = Path(py_file).resolve().parent
        if folder.is_relative_to(_PACKAGE):
            return str(folder.relative_to(_PACKAGE))
        return super().get_suitable_cache_subpath(py_file)


class _PackageCacheImpl(CompileResultCacheImpl):
    _locator_classes = [_PackageLocator]


_CHECKOUT = "drt_engine"
"""The package's name where kernels are shipped from (a checkout, ``tools/ship_kernels.py``)."""
_INSTALLED = __name__.removesuffix(".core.base.jit")
"""Its name here: Blender imports an installed extension as ``bl_ext.<repository>.drt_engine``."""


def _installed_module(name: str) -> str:
    if name == _CHECKOUT or name.startswith(_CHECKOUT + "."):
        return _INSTALLED + name[len(_CHECKOUT):]
    return name


def _rebuild_env(modname, consts, env_name):
    return environment._rebuild_env(_installed_module(modname), consts, env_name)


class _Unpickler(pickle.Unpickler):
    """A cache entry names the modules of its kernel and of the functions it holds (its globals
    are rebuilt from the module); one compiled in a checkout names them ``drt_engine.*``, which
    an installed extension imports under another name."""

    def find_class(self, module, name):
        if (module, name) == ("numba.core.environment", "_rebuild_env"):
            return _rebuild_env
        return super().find_class(_installed_module(module), name)


class _DataFile(IndexDataCacheFile):
    def _load_data(self, name):
        with open(self._data_path(name), "rb") as f:
            return _Unpickler(f).load()


class _SharedFolderCache(FunctionCache):
    """Numba's on-disk cache of one kernel, in a folder another process may prune at any moment
    (``mark_compiled`` of another checkout): Numba itself tolerates a data file gone under its
    index but raises when the folder goes while it saves (FileNotFoundError mid-render, seen with
    two checkouts). Here any OSError while loading is a miss and while saving leaves it unsaved."""

    _impl_class = _PackageCacheImpl

    def __init__(self, py_func):
        super().__init__(py_func)
        self._cache_file = _DataFile(self._cache_path, self._impl.filename_base,
                                     self._impl.locator.get_source_stamp())

    def load_overload(self, sig, target_context):
        try:
            found = super().load_overload(sig, target_context)
            return found if found is not None else self._load_portable(sig, target_context)
        except OSError:
            return None

    def _load_portable(self, sig, target_context):
        """The entry compiled for any CPU (``PORTABLE_CPU``), where this CPU has none."""
        if not self._enabled:
            return None
        signature, (triple, *_), hashes = self._index_key(sig, target_context.codegen())
        data = self._cache_file.load((signature, (triple, *PORTABLE_CPU), hashes))
        return None if data is None else self._impl.rebuild(target_context, data)

    def save_overload(self, sig, data):
        try:
            super().save_overload(sig, data)
        except OSError:
            pass


def first_run() -> bool:
    """True until a render has compiled this version's kernels into the cache folder."""
    return not (cache_dir() / _STAMP).exists()


def mark_compiled() -> None:
    """Record that this version's kernels are in the cache and were used now, and remove the
    folders of older versions for the same Python beyond the ``KEEP`` most recently used (other
    Pythons' folders belong to other Blenders or venvs and stay; best effort: a read-only cache
    folder only means the message shows again)."""
    try:
        folder = cache_dir()
        folder.mkdir(parents=True, exist_ok=True)
        (folder / _STAMP).touch()
        same_python = re.escape(_FINGERPRINT.split("-")[0]) + r"-[0-9a-f]{16}"
        older = [f for f in folder.parent.iterdir()
                 if f != folder and re.fullmatch(same_python, f.name) and f.is_dir()]
        for old in sorted(older, key=_last_use, reverse=True)[KEEP - 1:]:
            shutil.rmtree(old, ignore_errors=True)
    except OSError:
        pass


def _last_use(folder: Path) -> float:
    """When a render last used ``folder``: its stamp's time, or the latest change of the folder and
    its per-package subfolders if later (Numba's writes land there, so a folder another process is
    compiling into now, stamped only when that render ends, is not taken for an old one)."""
    times = [0.0]
    try:
        for path in (folder, *folder.iterdir()):
            times.append(path.stat().st_mtime)
    except OSError:
        pass
    return max(times)
