"""The layout's rules (../shared/DESIGN.md, "Layout"), read from the code's own imports.

Every import in drt_engine/, at module level or inside a function, is an edge: a module
imports only its own package and the layers below it, no import circle exists anywhere, and
only drt_engine/blender/ imports bpy (and the core's own tests import without it). The checker is
tested on a small tree of its own, so that a rule it stopped seeing fails here too.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "drt_engine"

CONTRACT = ("scene", "settings", "errors", "validate")
"""The modules at core/'s top: the plain-data description both sides fill in and read."""

LAYERS = (
    ("base",),
    ("contract",),
    ("sampling",),
    ("geometry", "film", "bsdf"),
    ("shading",),
    ("lights",),
    ("integrator",),
    ("render",),
    ("blender",),
    ("headless",),
    ("top",),
)
"""Lowest first. A unit imports itself and the units of lower ranks; units of one rank are peers
and import none of each other."""

RANK = {unit: rank for rank, units in enumerate(LAYERS) for unit in units}


def unit_of(module: str) -> str:
    """The layer unit of a dotted module name under drt_engine."""
    parts = module.split(".")[1:]
    if not parts:
        return "top"
    if parts[0] == "core":
        if len(parts) == 1:
            return "contract"
        return "contract" if parts[1] in CONTRACT else parts[1]
    return parts[0] if parts[0] in RANK else "top"


def module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, root: Path) -> set[str]:
    """Dotted names this file imports (``from . import x`` gives the submodule when there is one)."""
    module = module_name(path, root)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            found.add(target)
            for alias in node.names:
                sub = target + "." + alias.name
                if module_file(sub, root) is not None:
                    found.add(sub)
    return found


def module_file(module: str, root: Path) -> Path | None:
    path = root.parent.joinpath(*module.split("."))
    for candidate in (path.with_suffix(".py"), path / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def graph(root: Path) -> dict[str, set[str]]:
    """Module -> the modules of ``root``'s package it imports."""
    edges = {}
    for path in sorted(root.rglob("*.py")):
        here = module_name(path, root)
        edges[here] = {m for m in imports(path, root)
                       if m.split(".")[0] == root.name and module_file(m, root) is not None and m != here}
    return edges


def layering_violations(edges: dict[str, set[str]]) -> list[str]:
    wrong = []
    for module, targets in edges.items():
        mine = unit_of(module)
        for target in targets:
            theirs = unit_of(target)
            if theirs != mine and RANK[theirs] >= RANK[mine]:
                wrong.append(f"{module} ({mine}) imports {target} ({theirs})")
    return sorted(wrong)


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Every strongly connected set of more than one module (Tarjan), each as a sorted list."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def bpy_outside_blender(root: Path) -> list[str]:
    wrong = []
    for path in sorted(root.rglob("*.py")):
        module = module_name(path, root)
        if unit_of(module) != "blender" and any(m == "bpy" or m.startswith("bpy.") or m in ("gpu", "mathutils")
                                                  for m in imports(path, root)):
            wrong.append(module)
    return wrong


def test_every_import_follows_the_layers():
    assert layering_violations(graph(PACKAGE)) == []


KNOWN_CIRCLES = []
"""Circles still to break; empty since issue #21's layout. Listed so that no new circle comes in."""

KNOWN_BPY_OUTSIDE_BLENDER = []
"""Modules outside drt_engine/blender/ that import bpy; empty since the headless CLI reaches Blender
through drt_engine.blender.batch (#21)."""


def test_no_import_circle_but_the_known_ones():
    assert sorted(circles(graph(PACKAGE))) == KNOWN_CIRCLES


def test_only_the_blender_layer_imports_blender():
    assert bpy_outside_blender(PACKAGE) == KNOWN_BPY_OUTSIDE_BLENDER


def test_the_cores_tests_import_without_blender():
    """tests/core also runs where there is no bpy (tests/real_blender/test_core_on_python313.py, on
    the Python Debian's Blender runs on): none of its modules, nor the support modules they use,
    may import bpy or mathutils."""
    code = ("import importlib, pathlib, sys\n"
            "sys.modules['bpy'] = sys.modules['mathutils'] = None\n"
            "sys.path.insert(0, 'tests/core')\n"
            "for path in sorted(pathlib.Path('tests/core').glob('test_*.py')):\n"
            "    importlib.import_module('tests.core.' + path.stem)\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]


def _tree(tmp_path, files: dict[str, str]) -> Path:
    root = tmp_path / "drt_engine"
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


ALLOWED = {
    "__init__.py": "",
    "core/scene.py": "from .base.jit import kernel\n",
    "core/base/jit.py": "",
    "core/base/vectors.py": "from .jit import kernel\n",
    "core/bsdf/lobes.py": "from ..base import vectors\nfrom ..scene import Material\n",
    "core/lights/kinds.py": "def f():\n    from ..bsdf import lobes\n",
    "blender/engine.py": "import bpy\nfrom ..core.lights import kinds\n",
    "headless/cli.py": "from ..blender import engine\n",
}


def test_the_checker_passes_a_tree_that_follows_the_rules(tmp_path):
    root = _tree(tmp_path, ALLOWED)
    edges = graph(root)
    assert "drt_engine.core.bsdf.lobes" in edges["drt_engine.core.lights.kinds"]
    assert layering_violations(edges) == [] and circles(edges) == [] and bpy_outside_blender(root) == []


def test_the_checker_finds_an_upward_import(tmp_path):
    """A lobe importing a light kind (bsdf is below lights), even inside a function."""
    root = _tree(tmp_path, {**ALLOWED, "core/bsdf/lobes.py": "def f():\n    from ..lights.kinds import x\n"})
    assert layering_violations(graph(root)) == [
        "drt_engine.core.bsdf.lobes (bsdf) imports drt_engine.core.lights.kinds (lights)"]


def test_the_checker_finds_a_peer_import_and_the_contract_reaching_up(tmp_path):
    root = _tree(tmp_path, {**ALLOWED, "core/film/film.py": "from ..bsdf import lobes\n",
                            "core/settings.py": "from .render import render\n", "core/render/render.py": ""})
    assert layering_violations(graph(root)) == [
        "drt_engine.core.film.film (film) imports drt_engine.core.bsdf.lobes (bsdf)",
        "drt_engine.core.settings (contract) imports drt_engine.core.render.render (render)"]


def test_the_checker_finds_a_circle_within_one_layer(tmp_path):
    root = _tree(tmp_path, {**ALLOWED, "blender/viewport.py": "from . import engine\n",
                            "blender/engine.py": "import bpy\n\ndef later():\n    from .viewport import x\n"})
    edges = graph(root)
    assert layering_violations(edges) == []
    assert circles(edges) == [["drt_engine.blender.engine", "drt_engine.blender.viewport"]]


def test_the_checker_finds_bpy_outside_the_blender_layer(tmp_path):
    root = _tree(tmp_path, {**ALLOWED, "headless/scene.py": "def open_file():\n    import bpy\n"})
    assert bpy_outside_blender(root) == ["drt_engine.headless.scene"]
