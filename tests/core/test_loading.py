"""Modules loaded within a time limit: a module already imported is there at once; a slow import
is waited for only as long as the deadline allows, goes on in the background and is there for
the next call; a failing import raises in the caller; the still-loading answer has no plan."""

from __future__ import annotations

import builtins
import math
import sys
import textwrap
import threading
from pathlib import Path

import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.loading import loaded_within, still_loading
from searchtrack.core.result import Status


def _module(root: Path, name: str, body: str) -> None:
    (root / f"{name}.py").write_text(textwrap.dedent(body))


def test_an_imported_module_is_there_at_once() -> None:
    """A module in ``sys.modules`` is loaded even with no time left."""
    deadline = Deadline(1e-9)
    assert loaded_within("math", deadline)


def test_a_slow_import_goes_on_after_the_deadline(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """An import that waits on an event is not loaded within a short deadline; once the event
    is set, the same import (still one thread) completes and the module is loaded."""
    gate = threading.Event()
    monkeypatch.setattr(builtins, "st_slow_gate", gate, raising=False)
    _module(tmp_path, "st_slow_module", """
        import builtins
        builtins.st_slow_gate.wait(30.0)
        VALUE = 7
        """)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert not loaded_within("st_slow_module", Deadline(0.05))
    gate.set()
    assert loaded_within("st_slow_module", Deadline(30.0))
    assert sys.modules["st_slow_module"].VALUE == 7


def test_no_time_limit_waits_for_the_import(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """An infinite time limit waits for the import to finish."""
    _module(tmp_path, "st_plain_module", "VALUE = 3\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert loaded_within("st_plain_module", Deadline(math.inf))
    assert sys.modules["st_plain_module"].VALUE == 3


def test_a_failing_import_raises_in_the_caller(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """The import's own error reaches the caller, every time it asks."""
    _module(tmp_path, "st_broken_module", "raise ImportError('no solver here')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    for _ in range(2):
        with pytest.raises(ImportError, match="no solver here"):
            loaded_within("st_broken_module", Deadline(30.0))


def test_the_still_loading_answer() -> None:
    """``NO_SOLUTION`` without plan, naming the backend and the library."""
    res = still_loading("exact", "OR-Tools", Deadline(1.0))
    assert res.status is Status.NO_SOLUTION and res.plan is None and res.backend == "exact"
    assert "OR-Tools" in res.message
