"""A cached kernel that calls another module's kernel compiles afresh when only the callee's
source changes (numba alone would load the stale machine code)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from searchtrack.core.kernel_cache import callee_files

CALLEE = """
from numba import njit

@njit(cache=True)
def value():
    return {value}
"""

CALLER = """
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from {package} import callee
from {package}.callee import value

@njit(cache=True)
def direct():
    return value()

@njit(cache=True)
def through_module():
    return callee.value() + 100

{follow}
"""


def _package(root: Path, name: str, follow: bool) -> None:
    pkg = root / name
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "callee.py").write_text(CALLEE.format(value=1))
    follow_line = "follow_callees(__name__, globals())" if follow else ""
    (pkg / "caller.py").write_text(textwrap.dedent(CALLER.format(package=name,
                                                                 follow=follow_line)))


def _run(root: Path, name: str) -> str:
    code = f"from {name}.caller import direct, through_module; print(direct(), through_module())"
    env = {**os.environ, "PYTHONPATH": f"{root}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    env.pop("NUMBA_DISABLE_JIT", None)
    env.pop("NUMBA_CACHE_DIR", None)
    return subprocess.run([sys.executable, "-c", code], env=env, check=True,
                          capture_output=True, text=True, timeout=300).stdout.strip()


@pytest.mark.parametrize("follow", [True, False])
def test_a_changed_callee_is_compiled_into_its_callers(tmp_path: Path, follow: bool) -> None:
    """With the stamp the callers see the callee's new value; without it numba's cache keeps
    the old one (which is why the stamp exists)."""
    name = f"kernels_{'followed' if follow else 'plain'}"
    _package(tmp_path, name, follow)
    assert _run(tmp_path, name) == "1 101"
    assert _run(tmp_path, name) == "1 101"  # from the cache
    callee = tmp_path / name / "callee.py"
    callee.write_text(CALLEE.format(value=22))  # another size: another stamp
    assert _run(tmp_path, name) == ("22 122" if follow else "1 101")


def test_callee_files_follow_kernels_across_modules() -> None:
    """The EMD pair kernels reach the simplex kernels and their starting basis, not themselves."""
    from searchtrack.estimate.transport import pair_batch

    names = {p.name for p in callee_files(pair_batch.__name__, vars(pair_batch))}
    assert {"simplex_kernels.py", "simplex_start.py"} <= names
    assert "pair_batch.py" not in names
