"""Cooperative interruption: one process-wide stop flag that Ctrl-C sets and every solver honours.

Every :class:`~searchtrack.core.deadline.Deadline` reads the flag, so a loop that stops at its
deadline also stops at a stop request; a backend whose native solver runs outside Python
(CP-SAT, SCIP, Ipopt) watches the flag with :func:`watch` and tells the solver to stop. A solve
cut short this way returns ``Status.INTERRUPTED`` with the best plan and bound so far.

Library code never installs a signal handler: the command line does, with :func:`sigint_stops`
(first Ctrl-C: stop cleanly; second: abort at once).

Work that has nothing to keep when cut short (measuring a map before any answer exists) calls
:func:`check_stop` in its loops: inside :func:`stops_raise` a stop request raises
:class:`StopRequested` there, which the caller that opened the block catches; elsewhere the call
does nothing, so such work runs to its end for callers that never expect the exception.
"""

from __future__ import annotations

import _thread
import contextlib
import contextvars
import math
import signal
import socket
import threading
import time
from collections.abc import Callable, Iterator
from types import FrameType

_STOP = threading.Event()
_RAISES: contextvars.ContextVar[bool] = contextvars.ContextVar("searchtrack_stop_raises",
                                                               default=False)


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


class StopRequested(Exception):
    """Raised by :func:`check_stop` inside :func:`stops_raise` once a stop is requested."""


@contextlib.contextmanager
def stops_raise() -> Iterator[None]:
    """Inside the block (in this thread or task), :func:`check_stop` raises
    :class:`StopRequested` once a stop is requested."""
    token = _RAISES.set(True)
    try:
        yield
    finally:
        _RAISES.reset(token)


def check_stop() -> None:
    """Raise :class:`StopRequested` if a stop is requested inside :func:`stops_raise`; else
    nothing (cheap enough for every iteration of a loop)."""
    if _STOP.is_set() and _RAISES.get():
        raise StopRequested


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


#: SIGINTs this close after the first (s) are the same press: ``timeout -s INT`` signals the
#: command and then its whole process group, the command included, at once.
SAME_PRESS_S = 0.25


class Aborted(KeyboardInterrupt):
    """Raised in the main thread by the second Ctrl-C inside :func:`sigint_stops`."""


def _interrupt_main() -> None:
    _thread.interrupt_main(signal.SIGINT)


@contextlib.contextmanager
def sigint_stops(abort: Callable[[], None] = _interrupt_main) -> Iterator[None]:
    """Inside the block, the first SIGINT requests a cooperative stop; the second (after
    :data:`SAME_PRESS_S`) calls ``abort`` (by default: raise :class:`Aborted` in the main thread
    as soon as it runs Python).

    A signal reaches Python's own handler only when the main thread runs Python code, which it
    does not while a native solver (CP-SAT, SCIP, Ipopt) holds it; so the presses are counted by
    a helper thread woken through :func:`signal.set_wakeup_fd`, which sees them at once. A
    command line passes an ``abort`` that exits the process (the main thread may be inside a
    native call for minutes). The previous handler comes back at the end; the flag is cleared
    on entry. Outside the main thread (where Python allows no handler) it changes nothing.
    """
    clear_stop()
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread may set handlers; Ctrl-C keeps its default meaning
        return
    aborting = threading.Event()

    def handler(signum: int, frame: FrameType | None) -> None:
        if aborting.is_set():
            raise Aborted

    read_fd, write_fd = socket.socketpair()
    read_fd.setblocking(True)
    write_fd.setblocking(False)
    presses = 0
    first = 0.0

    def count() -> None:
        nonlocal presses, first
        while True:
            data = read_fd.recv(64)
            if not data:
                return
            for signum in data:
                if signum == 0:  # the block ended
                    return
                if signum != signal.SIGINT or aborting.is_set():
                    continue
                if presses == 1 and time.monotonic() - first < SAME_PRESS_S:
                    continue  # one press delivered twice (see SAME_PRESS_S)
                presses += 1
                if presses == 1:
                    first = time.monotonic()
                    _STOP.set()
                else:
                    aborting.set()
                    abort()

    previous = signal.signal(signal.SIGINT, handler)
    previous_fd = signal.set_wakeup_fd(write_fd.fileno(), warn_on_full_buffer=False)
    watcher = threading.Thread(target=count, name="searchtrack-sigint", daemon=True)
    watcher.start()
    try:
        yield
    finally:
        signal.set_wakeup_fd(previous_fd)
        signal.signal(signal.SIGINT, previous)
        with contextlib.suppress(OSError):
            write_fd.send(b"\x00")
        watcher.join(timeout=1.0)
        read_fd.close()
        write_fd.close()
