"""core.base.jit's kernel cache: folders of other versions are kept up to KEEP by last use, other
Pythons' are never touched, and a cache folder that vanishes costs a recompile, not an error."""
import os
import subprocess
import sys
from pathlib import Path

import numba

from drt_engine.core.base import jit

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


def _run(cache: Path) -> int:
    """Run KERNEL in a fresh process with ``cache`` as the cache's base; how often it loaded from it."""
    script = cache.parent / "kernel_script.py"
    script.write_text(KERNEL)
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))  # keep the caller's (Blender's site-packages)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=path)
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
