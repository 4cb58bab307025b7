"""Solver libraries loaded within a time limit.

The first import of a large solver library takes longer than the short time limits a planner
in a closed loop gives its exact stage (OR-Tools: tenths of a second, once per process).
Imported inside the stage, it made the first call overrun its limit. :func:`loaded_within`
imports the module on a background thread and waits only for the time the stage has: when the
import is not done by then, the stage answers without the library (``auto`` keeps its
heuristic's answer) and the import goes on, so a later call finds it loaded. An import that
fails raises its error in the caller, as a plain import would.
"""

from __future__ import annotations

import importlib
import math
import sys
import threading
from typing import Any

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status

_LOCK = threading.Lock()
_THREADS: dict[str, threading.Thread] = {}
_ERRORS: dict[str, BaseException] = {}


def _load(name: str) -> None:
    try:
        importlib.import_module(name)
    except BaseException as exc:  # handed to the caller that waits for it
        _ERRORS[name] = exc


def loaded_within(name: str, deadline: Deadline) -> bool:
    """Whether module ``name`` is imported by the time ``deadline`` expires (waiting at most
    that long; the import continues in the background after a ``False``).

    Raises
    ------
    BaseException
        Whatever the import raised.
    """
    with _LOCK:
        thread = _THREADS.get(name)
        if thread is None:
            if name in sys.modules:
                return True
            thread = threading.Thread(target=_load, args=(name,), name=f"import {name}",
                                      daemon=True)
            _THREADS[name] = thread
            thread.start()
    remaining = deadline.remaining()
    thread.join(remaining if math.isfinite(remaining) else None)
    if thread.is_alive():
        return False
    error = _ERRORS.get(name)
    if error is not None:
        raise error
    return True


def still_loading(backend: str, library: str, deadline: Deadline) -> Result[Any]:
    """The ``NO_SOLUTION`` answer of ``backend`` whose time limit ran out while ``library``
    loaded."""
    return Result(Status.NO_SOLUTION, None, None, deadline.elapsed(), backend, None,
                  message=f"the time limit ran out while {library} loaded (once per process; "
                          "it goes on loading for the next call)")
