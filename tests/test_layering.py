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

#: What ``searchtrack.plan.*`` may import from ``searchtrack.estimate.*``: the belief seam only,
#: the protocols and the plain beliefs with their pure steps (planners read beliefs through them,
#: never through a filter's internals).
PLAN_MAY_IMPORT_FROM_ESTIMATE = frozenset({
    "searchtrack.estimate.belief",              # NodeBelief ... RoadParticleBelief,
                                                # LabelledParticleBelief
    "searchtrack.estimate.particle_belief",     # ParticleBelief, WeightedParticles
    "searchtrack.estimate.labelled_particles",  # LabelledParticles, update, resample
    "searchtrack.estimate.labelled_motion",   # the labelled cloud's motion step (pure)
})


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


def test_planners_import_only_the_belief_seam_from_estimate() -> None:
    """No planner module imports an estimate module outside the allow-list (even the
    ``searchtrack.estimate`` package face, which reaches every filter)."""
    estimate = LAYERS.index("estimate")
    reach = [f"{path.relative_to(PACKAGE)}:{line} imports {module}"
             for path in (PACKAGE / "plan").rglob("*.py") for line, module in _imports(path)
             if _layer(module) == estimate and module not in PLAN_MAY_IMPORT_FROM_ESTIMATE]
    assert not reach, "\n".join(reach)


def test_the_belief_seam_imports_no_other_estimate_module() -> None:
    """The allow-listed seam modules import, from the estimate layer, only one another: reading
    a belief never pulls in a filter."""
    estimate = LAYERS.index("estimate")
    reach = []
    for name in sorted(PLAN_MAY_IMPORT_FROM_ESTIMATE):
        path = PACKAGE.parent.joinpath(*name.split(".")).with_suffix(".py")
        reach += [f"{name}:{line} imports {module}" for line, module in _imports(path)
                  if _layer(module) == estimate and module not in PLAN_MAY_IMPORT_FROM_ESTIMATE]
    assert not reach, "\n".join(reach)


def test_importing_the_planners_loads_only_the_belief_seam() -> None:
    """In a fresh interpreter, importing every plan module loads no estimate module but the
    seam's (and the ``searchtrack.estimate`` package itself, their parent)."""
    modules = sorted({_module_name(p) for p in (PACKAGE / "plan").rglob("*.py")})
    allowed = sorted(PLAN_MAY_IMPORT_FROM_ESTIMATE | {"searchtrack.estimate"})
    code = (f"import importlib, sys\nfor m in {modules!r}:\n    importlib.import_module(m)\n"
            f"bad = sorted(m for m in sys.modules if m.startswith('searchtrack.estimate')\n"
            f"             and m not in {allowed!r})\n"
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_no_module_imports_another_modules_private_names() -> None:
    """``from searchtrack.x import _name`` nowhere in the package: what one module shares with
    another is public (a leading underscore means "this module only")."""
    offenders = []
    for path in SOURCES:
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "")
                                                    .startswith("searchtrack")):
                offenders += [f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {a.name}"
                              for a in node.names
                              if a.name.startswith("_") and not a.name.startswith("__")]
    assert not offenders, offenders
