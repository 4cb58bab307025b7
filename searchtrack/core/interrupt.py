"""Cooperative interruption: one process-wide stop flag that Ctrl-C sets and every solver honours.

Every :class:`~searchtrack.core.deadline.Deadline` reads the flag, so a loop that stops at its
deadline also stops at a stop request; a backend whose native solver runs outside Python
(CP-SAT, SCIP, Ipopt) watches the flag with :func:`watch` and tells the solver to stop. A solve
cut short this way returns ``Status.INTERRUPTED`` with the best plan and bound so far.

Library code never installs a signal handler: the command line does, with :func:`sigint_stops`
(first Ctrl-C: stop cleanly; second: abort at once).
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
from collections.abc import Callable, Iterator
from types import FrameType

_STOP = threading.Event()


def request_stop() -> None:
    """Ask every running solve to stop as soon as it can (thread- and signal-safe)."""
    _STOP.set()


def stop_requested() -> bool:
    """True once a stop was requested and until :func:`clear_stop`."""
    return _STOP.is_set()


def clear_stop() -> None:
    """Forget a stop request (before starting new work)."""
    _STOP.clear()


def stop_clock() -> float:
    """``time.perf_counter()``, or ``+inf`` once a stop is requested: compiled kernels that
    compare the clock with a deadline read this and so stop on request too."""
    return math.inf if _STOP.is_set() else time.perf_counter()


@contextlib.contextmanager
def watch(on_stop: Callable[[], None], poll_s: float = 0.05) -> Iterator[None]:
    """Call ``on_stop`` once, from a helper thread, if a stop is requested inside the block.

    For native solvers that offer a thread-safe "stop now" (CP-SAT's ``StopSearch``, SCIP's
    ``InterruptSolve``). The thread ends with the block.
    """
    done = threading.Event()

    def run() -> None:
        while not done.wait(poll_s):
            if _STOP.is_set():
                on_stop()
                return

    thread = threading.Thread(target=run, name="searchtrack-stop-watch", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()


class Aborted(KeyboardInterrupt):
    """Raised by the second Ctrl-C inside :func:`sigint_stops`: stop at once."""


@contextlib.contextmanager
def sigint_stops() -> Iterator[None]:
    """Inside the block, the first SIGINT requests a cooperative stop and the second raises
    :class:`Aborted`. The previous handler comes back at the end; the flag is cleared on entry.
    Only the main thread may use it (a Python rule for signal handlers)."""
    clear_stop()

    def handler(signum: int, frame: FrameType | None) -> None:
        if _STOP.is_set():
            raise Aborted
        _STOP.set()

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
