"""core.base.jit's kernel cache: folders of other versions are kept up to KEEP by last use, other
Pythons' are never touched, and a cache folder that vanishes costs a recompile, not an error."""
import os
import subprocess
import sys
from pathlib import Path

import numba

from drt_engine.core.base import jit
from tests.support.kernel_cache import kernel_cpus

ROOT = Path(__file__).resolve().parents[2]


def _folder(base: Path, name: str, used: float | None, changed: float = 1.0) -> Path:
    """A cache folder stamped at ``used`` (None: never stamped) whose files last changed at ``changed``."""
    folder = base / name
    (folder / "base_0123").mkdir(parents=True)
    if used is not None:
        (folder / "compiled").touch()
        os.utime(folder / "compiled", (used, used))
    os.utime(folder / "base_0123", (changed, changed))
    os.utime(folder, (changed, changed))
    return folder


def test_the_most_recently_used_versions_stay(tmp_path, monkeypatch):
    python = jit._FINGERPRINT.split("-")[0]
    mine = tmp_path / jit._FINGERPRINT
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(mine))
    older = [_folder(tmp_path, f"{python}-{i:016x}", used=1_000_000 + i) for i in range(6)]
    abandoned = _folder(tmp_path, f"{python}-{'f' * 16}", used=None)
    filling = _folder(tmp_path, f"{python}-{'e' * 16}", used=None)  # another render compiling into it now
    os.utime(filling / "base_0123")
    other_python = _folder(tmp_path, "py27-0123456789abcdef", used=1.0)
    not_ours = _folder(tmp_path, "notes", used=1.0)
    assert jit.first_run()
    jit.mark_compiled()
    assert not jit.first_run()
    kept = sorted(p.name for p in tmp_path.iterdir())
    newest = [filling.name] + [f.name for f in older[-(jit.KEEP - 2):]]
    assert kept == sorted([mine.name, other_python.name, not_ours.name] + newest)
    assert not abandoned.exists()


KERNEL = """
from drt_engine.core.base.jit import kernel

@kernel
def triple(x):
    return 3 * x

assert triple(14) == 42
print(triple.stats.cache_hits.get(triple.signatures[0], 0))
"""


def _run(cache: Path, **env) -> int:
    """Run KERNEL in a fresh process with ``cache`` as the cache's base (and ``env``); how often it
    loaded from it."""
    script = cache.parent / "kernel_script.py"
    script.write_text(KERNEL)
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))  # keep the caller's (Blender's site-packages)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=path, **env)
    done = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, cwd=str(ROOT))
    assert done.returncode == 0, done.stderr
    return int(done.stdout.split()[-1])


def test_a_vanished_cache_folder_costs_a_recompile_not_an_error(tmp_path):
    cache = tmp_path / "kernels"
    assert _run(cache) == 0  # compiled and saved
    assert _run(cache) == 1  # loaded from the cache
    data = [f for f in cache.rglob("*.nbc")]
    assert data
    for f in data:  # another checkout pruned the data files under a still-listed index
        f.unlink()
    assert _run(cache) == 0
    for f in sorted(cache.rglob("*"), reverse=True):  # the whole folder gone
        f.unlink() if f.is_file() else f.rmdir()
    cache.rmdir()
    assert _run(cache) == 0
    assert _run(cache) == 1


def test_a_cache_folder_pruned_while_a_kernel_saves_leaves_it_unsaved(tmp_path, monkeypatch):
    """Another checkout's mark_compiled may remove this render's folder while a kernel compiles: the
    kernel runs and is not saved (Numba alone raised FileNotFoundError mid-render)."""
    cache = tmp_path / "kernels"
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(cache))

    @jit.kernel
    def quadruple(x):
        return 4 * x

    for f in sorted(cache.rglob("*"), reverse=True):
        f.unlink() if f.is_file() else f.rmdir()
    cache.rmdir()
    cache.write_text("not a folder")  # so the save cannot make the folder again either
    assert quadruple(10.5) == 42.0
    assert cache.read_text() == "not a folder"


def test_kernels_compiled_for_any_cpu_load_on_this_one(tmp_path):
    """What an extension build ships (compiled with NUMBA_CPU_NAME=generic) loads where this CPU
    has no entry of its own, instead of compiling again."""
    cache = tmp_path / "kernels"
    assert _run(cache, NUMBA_CPU_NAME="generic") == 0
    assert kernel_cpus(cache) == {jit.PORTABLE_CPU[0]}
    assert _run(cache) == 1
    assert kernel_cpus(cache) == {jit.PORTABLE_CPU[0]}  # loaded, so nothing compiled for this CPU


def test_shipped_kernels_seed_a_new_cache_folder_only(tmp_path):
    shipped = tmp_path / "shipped"
    (shipped / "core" / "bsdf").mkdir(parents=True)
    (shipped / "core" / "bsdf" / "lobe.nbi").write_text("shipped")
    fresh = tmp_path / "cache" / "py3x-fresh"
    jit._seed(shipped, fresh)
    assert (fresh / "core" / "bsdf" / "lobe.nbi").read_text() == "shipped"
    assert [p.name for p in fresh.parent.iterdir()] == ["py3x-fresh"]  # no partial copy left
    (fresh / "core" / "bsdf" / "lobe.nbi").write_text("compiled here")
    jit._seed(shipped, fresh)
    assert (fresh / "core" / "bsdf" / "lobe.nbi").read_text() == "compiled here"


def test_a_kernel_caches_under_its_path_in_the_package():
    """The same folder wherever the extension is installed, so shipped kernels are found."""
    source = Path(jit.__file__).parents[1] / "bsdf" / "microfacet.py"
    assert jit._PackageLocator.get_suitable_cache_subpath(str(source)) == os.path.join("core", "bsdf")


def test_the_first_kernel_defined_seeds_the_cache_folder_from_the_shipped_one(tmp_path, monkeypatch):
    """Before Numba's own cache makes folders in it (which would leave the copy out)."""
    shipped = tmp_path / "shipped"
    (shipped / jit._FINGERPRINT / "core").mkdir(parents=True)
    (shipped / jit._FINGERPRINT / "compiled").touch()
    folder = tmp_path / "cache" / jit._FINGERPRINT
    monkeypatch.setattr(jit, "SHIPPED", shipped)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(folder))

    @jit.kernel
    def quintuple(x):
        return 5 * x

    assert quintuple(8.4) == 42.0
    assert (folder / "compiled").is_file() and not jit.first_run()


INSTALLED = """
import importlib
vectors = importlib.import_module("repository.drt_engine.core.base.vectors")
assert "drt_engine" not in __import__("sys").modules
x, _, _ = vectors.unit(3.0, 0.0, 4.0)
print(x, vectors.unit.stats.cache_hits.get(vectors.unit.signatures[0], 0))
"""


def test_kernels_compiled_in_a_checkout_load_in_an_installed_package(tmp_path):
    """Blender imports an installed extension as ``bl_ext.<repository>.drt_engine`` while the shipped
    kernels were compiled as ``drt_engine.*``: the names a cache entry holds (its module, whose globals
    it rebuilds) are read as the installed package's. ``unit`` reads a module global (TINY)."""
    cache = tmp_path / "kernels"
    top = tmp_path / "top"
    (top / "repository").mkdir(parents=True)
    (top / "repository" / "__init__.py").touch()
    (top / "repository" / "drt_engine").symlink_to(ROOT / "drt_engine")
    caller = os.environ.get("PYTHONPATH")
    for code, cwd, path, extra in (
            ("from drt_engine.core.base.vectors import unit; print(unit(3.0, 0.0, 4.0)[0], 0)", ROOT, ROOT,
             {"NUMBA_CPU_NAME": "generic"}),
            (INSTALLED, top, top, {})):
        env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), **extra,
                   PYTHONPATH=os.pathsep.join(filter(None, [str(path), caller])))
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=str(cwd))
        assert done.returncode == 0, done.stderr[-3000:]
    value, hits = done.stdout.split()
    assert float(value) == 0.6 and hits == "1"
