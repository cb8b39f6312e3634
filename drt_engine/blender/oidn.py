"""Where the running Blender keeps its OpenImageDenoise library, for core.film.denoiser.

Blender's official builds and the bpy module ship OIDN as a shared library of their own: in the
``lib`` folder beside the version folder (``<blender>/lib/`` on Linux, ``bpy/lib/`` in the bpy
wheel, ``Blender.app/Contents/Resources/lib/`` on macOS), or beside ``blender.exe`` and in
``blender.shared`` on Windows. On Linux a Blender that has loaded it shows it in /proc/self/maps.
Debian's Blender 4.3.2 ships none: denoising is unavailable there, and the UI says why.
"""
from __future__ import annotations

import functools
import sys
from pathlib import Path

import bpy

NAMES = {"linux": ("libOpenImageDenoise.so.2", "libOpenImageDenoise.so"),
         "win32": ("OpenImageDenoise.dll",),
         "darwin": ("libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib")}
"""The library's file names per platform, most specific first."""

UNAVAILABLE = "This Blender has no OpenImageDenoise library: denoising is unavailable"


def library_folders() -> list[Path]:
    """Folders that may hold the library, most likely first."""
    folders = []
    local = bpy.utils.resource_path("LOCAL")
    if local:
        root = Path(local).parent
        folders += [root / "lib", root / "blender.shared", root]
    if bpy.app.binary_path:
        exe = Path(bpy.app.binary_path).parent
        folders += [exe / "lib", exe / "blender.shared", exe, exe.parent / "Resources" / "lib"]
    return list(dict.fromkeys(folders))


def loaded_library() -> Path | None:
    """The OIDN library this process has already mapped (Linux), if any."""
    maps = Path("/proc/self/maps")
    if not maps.is_file():
        return None
    try:
        lines = maps.read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        path = Path(line.split()[-1]) if line.split() else None
        if path is not None and path.name.startswith("libOpenImageDenoise.so"):
            return path
    return None


def find_in(folders, names) -> Path | None:
    """The first file named one of ``names`` in one of ``folders``."""
    for folder in folders:
        for name in names:
            candidate = Path(folder) / name
            if candidate.is_file():
                return candidate
    return None


@functools.lru_cache(maxsize=1)
def search() -> str | None:
    """The library's path or None, looked for once per session (tests replace this function)."""
    names = NAMES.get(sys.platform, NAMES["linux"])
    found = find_in(library_folders(), names) or (loaded_library() if sys.platform == "linux" else None)
    return str(found) if found is not None else None


def oidn_library() -> str | None:
    """The path of the running Blender's OpenImageDenoise library, or None where it has none."""
    return search()


def unavailable_reason() -> str | None:
    """Why denoising cannot run here, or None when it can."""
    return None if oidn_library() else UNAVAILABLE
