"""Deadlines: checked time limits, counting down from a start, sub-deadlines for stages."""

from __future__ import annotations

import math
import time

import pytest

from searchtrack.core import Deadline
from searchtrack.core.deadline import check_time_limit
from searchtrack.core.errors import InvalidInputError


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan])
def test_deadline_rejects_bad_limits(bad: float) -> None:
    """Zero, negative and NaN time limits are rejected with the field named."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        Deadline(bad)


def test_deadline_counts_down() -> None:
    """A deadline reports elapsed and remaining time, and sub-deadlines fit inside it."""
    d = Deadline(10.0)
    assert 0.0 <= d.elapsed() < 1.0 and 9.0 < d.remaining() <= 10.0 and not d.expired()
    assert d.sub(0.5).time_limit_s <= 5.0
    assert Deadline(1e-9).expired() or Deadline(1e-9).remaining() < 1e-6


@pytest.mark.parametrize(("given", "expected"), [(2, 2.0), (0.25, 0.25), (math.inf, math.inf)])
def test_check_time_limit_returns_positive_seconds(given: float, expected: float) -> None:
    """Positive ints and floats come back as floats; an infinite limit is allowed."""
    out = check_time_limit(given)
    assert out == expected and isinstance(out, float)


@pytest.mark.parametrize("bad", ["5", None, [1.0], -math.inf])
def test_check_time_limit_refuses_non_numbers(bad: object) -> None:
    """Text, None, lists and −inf are refused with the field and the value in the message."""
    with pytest.raises(InvalidInputError) as err:
        check_time_limit(bad)  # type: ignore[arg-type]
    assert err.value.field == "time_limit_s" and "must be positive seconds" in str(err.value)


def test_end_is_start_plus_limit() -> None:
    """``end`` is the perf_counter value ``started + time_limit_s``."""
    assert Deadline(2.5, started=100.0).end == 102.5


def test_a_deadline_started_in_the_past_has_expired() -> None:
    """A deadline whose whole limit already lies behind it is expired with nothing remaining,
    and its elapsed time counts from its start."""
    past = Deadline(1.0, started=time.perf_counter() - 5.0)
    assert past.expired() and past.remaining() == 0.0 and past.elapsed() >= 5.0


def test_sub_deadline_gets_a_fraction_but_at_least_a_millisecond() -> None:
    """sub(f) takes at most f of the time left; once nothing is left it still gets 1 ms."""
    live = Deadline(100.0)
    assert 0.0 < live.sub(0.1).time_limit_s <= 10.0
    spent = Deadline(1.0, started=time.perf_counter() - 5.0)
    assert spent.sub(0.5).time_limit_s == 1e-3


@pytest.mark.parametrize("flag", [True, False])
def test_check_time_limit_refuses_bools(flag: bool) -> None:
    """True and False are not seconds: both are refused naming time_limit_s, as seeds are."""
    with pytest.raises(InvalidInputError) as err:
        check_time_limit(flag)
    assert err.value.field == "time_limit_s" and err.value.value is flag
