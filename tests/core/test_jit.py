"""core.base.jit's kernel cache: folders of other versions are kept up to KEEP by last use, other
Pythons' are never touched, and a cache folder that vanishes costs a recompile, not an error."""
import os
import subprocess
import sys
from pathlib import Path

import numba

from drt_engine.core.base import jit

ROOT = Path(__file__).resolve().parents[2]


def _folder(base: Path, name: str, used: float | None) -> Path:
    folder = base / name
    folder.mkdir()
    if used is not None:
        (folder / "compiled").touch()
        os.utime(folder / "compiled", (used, used))
    return folder


def test_the_most_recently_used_versions_stay(tmp_path, monkeypatch):
    python = jit._FINGERPRINT.split("-")[0]
    mine = tmp_path / jit._FINGERPRINT
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(mine))
    older = [_folder(tmp_path, f"{python}-{i:016x}", used=1_000_000 + i) for i in range(6)]
    unstamped = _folder(tmp_path, f"{python}-{'f' * 16}", used=None)
    other_python = _folder(tmp_path, "py27-0123456789abcdef", used=1.0)
    not_ours = _folder(tmp_path, "notes", used=1.0)
    assert jit.first_run()
    jit.mark_compiled()
    assert not jit.first_run()
    kept = sorted(p.name for p in tmp_path.iterdir())
    assert kept == sorted([mine.name, other_python.name, not_ours.name] + [f.name for f in older[-(jit.KEEP - 1):]])
    assert not unstamped.exists()


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
