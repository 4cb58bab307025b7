"""Tests mirror the package: each module with logic has ``tests/<same path>/test_<module>.py``."""

from __future__ import annotations

from pathlib import Path

import searchtrack

PACKAGE = Path(searchtrack.__file__).parent
TESTS = Path(__file__).parent

#: Modules without a test module of their own, and why.
EXEMPT = {
    "core/types.py": "type aliases only",
    "estimate/transport/simplex_kernels.py": "numba kernels, tested through simplex.py's tests",
    "models/particle_models.py": "protocols only; each implementation's tests check it fits",
    "plan/optw/ils_kernels.py": "numba kernels, tested through ils.py's tests",
    "plan/optw/labelling_expand.py": "numba kernel, tested through labelling_core.py's tests",
    "plan/optw/labelling_kernels.py": "numba kernels, tested through labelling.py's tests",
    "plan/optw/labelling_primitives.py": "numba kernels, tested through labelling.py's tests",
}


def _modules() -> list[Path]:
    return sorted(p.relative_to(PACKAGE) for p in PACKAGE.rglob("*.py")
                  if p.name not in ("__init__.py", "__main__.py"))


def test_every_module_with_logic_has_its_test_module() -> None:
    """``searchtrack/a/b.py`` is tested in ``tests/a/test_b.py`` unless exempt with a reason."""
    missing = [str(m) for m in _modules()
               if str(m) not in EXEMPT and not (TESTS / m.parent / f"test_{m.name}").is_file()]
    assert not missing, "modules without tests/<path>/test_<module>.py:\n" + "\n".join(missing)


def test_exemptions_name_real_modules() -> None:
    """Every exemption names a module that exists (no stale entries)."""
    stale = [m for m in EXEMPT if not (PACKAGE / m).is_file()]
    assert not stale, stale
