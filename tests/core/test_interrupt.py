"""Cooperative interruption: the stop flag, deadlines that honour it, the SIGINT handler."""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator

import pytest

from searchtrack.core import Deadline, Result, Status
from searchtrack.core.interrupt import (
    SAME_PRESS_S,
    Aborted,
    clear_stop,
    request_stop,
    sigint_stops,
    stop_requested,
    watch,
)
from searchtrack.core.result import interrupted


@pytest.fixture(autouse=True)
def _clean_flag() -> Iterator[None]:
    clear_stop()
    yield
    clear_stop()


def test_a_stop_request_expires_every_deadline() -> None:
    """A long deadline expires at once on a stop request, with nothing remaining."""
    deadline = Deadline(3600.0)
    assert not deadline.expired() and deadline.remaining() > 3000
    request_stop()
    assert stop_requested() and deadline.expired() and deadline.remaining() == 0.0
    clear_stop()
    assert not deadline.expired()


def test_watch_calls_the_native_stop_once() -> None:
    """``watch`` calls its callback from a helper thread soon after a stop request."""
    called = threading.Event()
    with watch(called.set, poll_s=0.005):
        threading.Timer(0.02, request_stop).start()
        assert called.wait(2.0)


def test_watch_does_nothing_without_a_request() -> None:
    """Without a stop request the callback never runs and the thread ends with the block."""
    calls: list[int] = []
    with watch(lambda: calls.append(1), poll_s=0.005):
        time.sleep(0.03)
    assert calls == [] and not any(t.name == "searchtrack-stop-watch"
                                   for t in threading.enumerate())


def test_first_sigint_stops_second_aborts() -> None:
    """Inside ``sigint_stops`` the first SIGINT only sets the flag; the second raises
    ``Aborted``; the previous handler comes back afterwards."""
    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(Aborted), sigint_stops():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(SAME_PRESS_S + 0.05)
        assert stop_requested()
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1.0)
    assert signal.getsignal(signal.SIGINT) is before


def test_one_press_delivered_twice_only_stops() -> None:
    """Two SIGINTs at once (``timeout -s INT`` signals the command, then its process group)
    are one press: a stop, no abort."""
    with sigint_stops():
        os.kill(os.getpid(), signal.SIGINT)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.5)
        assert stop_requested()


def test_interrupted_marks_only_unproven_answers() -> None:
    """After a stop request FEASIBLE and NO_SOLUTION become INTERRUPTED (the plan is kept);
    proven answers are untouched; nothing changes without a request."""
    feasible = Result(Status.FEASIBLE, 3.0, 5.0, 0.1, "x", "plan")
    optimal = Result(Status.OPTIMAL, 3.0, 3.0, 0.1, "x", "plan")
    assert interrupted(feasible) is feasible
    request_stop()
    marked = interrupted(feasible)
    assert marked.status is Status.INTERRUPTED and marked.plan == "plan" and marked.bound == 5.0
    assert interrupted(optimal) is optimal
    none = interrupted(Result(Status.NO_SOLUTION, None, None, 0.1, "x", None))
    assert none.status is Status.INTERRUPTED and none.plan is None
    with pytest.raises(ValueError, match="objective"):
        Result(Status.INTERRUPTED, None, None, 0.1, "x", "plan")
