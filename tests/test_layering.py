"""Data flows one way: core → models → estimate → plan → sim → cli; nothing imports upward."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import searchtrack

PACKAGE = Path(searchtrack.__file__).parent
LAYERS = ("core", "models", "estimate", "plan", "sim", "cli")


def _layer(module: str) -> int:
    """Rank of the layer ``searchtrack.<layer>...`` belongs to (the package root ranks as core)."""
    parts = module.split(".")
    if parts[0] != "searchtrack":
        raise ValueError(module)
    if len(parts) == 1:
        return 0
    return LAYERS.index(parts[1])


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path: Path) -> list[tuple[int, str]]:
    """``(line, module)`` for every searchtrack module ``path`` imports, wherever it does."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    here = _module_name(path).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package[: len(package) - node.level + 1])
                mod = f"{base}.{node.module}" if node.module else base
            else:
                mod = node.module or ""
            if mod == "searchtrack":  # from searchtrack import cli, sim ...
                found += [(node.lineno, f"searchtrack.{a.name}") for a in node.names
                          if a.name in LAYERS]
            else:
                found.append((node.lineno, mod))
    return [(line, m) for line, m in found if m == "searchtrack" or m.startswith("searchtrack.")]


SOURCES = sorted(PACKAGE.rglob("*.py"))


def test_every_module_belongs_to_a_layer() -> None:
    """Every module of the package sits in one of the six layers (or is the package root)."""
    stray = [str(p.relative_to(PACKAGE)) for p in SOURCES
             if p.parent != PACKAGE and p.relative_to(PACKAGE).parts[0] not in LAYERS]
    stray += [p.name for p in SOURCES if p.parent == PACKAGE and p.name != "__init__.py"]
    assert not stray, f"modules outside the layers {LAYERS}: {stray}"


@pytest.mark.parametrize("layer", LAYERS)
def test_no_module_imports_upward(layer: str) -> None:
    """No module of ``layer`` imports a module of a later layer, even inside a function."""
    rank = LAYERS.index(layer)
    upward = []
    for path in (PACKAGE / layer).rglob("*.py"):
        for line, module in _imports(path):
            if _layer(module) > rank:
                upward.append(f"{path.relative_to(PACKAGE)}:{line} imports {module}")
    assert not upward, "\n".join(upward)


def test_package_root_imports_only_core() -> None:
    """``import searchtrack`` pulls in the core layer and nothing above it."""
    bad = [m for _, m in _imports(PACKAGE / "__init__.py") if _layer(m) > 0]
    assert not bad, bad


@pytest.mark.parametrize("layer", LAYERS[:-1])
def test_importing_a_layer_loads_no_later_layer(layer: str) -> None:
    """In a fresh interpreter, importing every module of ``layer`` loads no later layer."""
    later = tuple(f"searchtrack.{name}" for name in LAYERS[LAYERS.index(layer) + 1:])
    modules = sorted({_module_name(p) for p in (PACKAGE / layer).rglob("*.py")})
    code = (f"import importlib, sys\nfor m in {modules!r}:\n    importlib.import_module(m)\n"
            f"bad = sorted(m for m in sys.modules if m.startswith({later!r}))\n"
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
