"""The shared solver vocabulary: result type, registry and deadline."""

from __future__ import annotations

import math

import pytest

from searchtrack.core import Backend, Deadline, Registry, Result, Sense, Status
from searchtrack.core.errors import InvalidInputError


def test_result_gap_for_max_and_min() -> None:
    """The gap is relative to the objective and signed by the sense; 0 when optimal."""
    r = Result(Status.FEASIBLE, 90.0, 100.0, 1.0, "x", plan=[1])
    assert r.gap == pytest.approx(10 / 90)
    r = Result(Status.FEASIBLE, 110.0, 100.0, 1.0, "x", plan=[1], sense=Sense.MINIMIZE)
    assert r.gap == pytest.approx(10 / 110)
    assert Result(Status.OPTIMAL, 5.0, 5.0, 0.0, "x", plan=[1]).gap == 0.0
    assert Result(Status.FEASIBLE, 5.0, None, 0.0, "x", plan=[1]).gap is None


def test_result_refuses_nonsense() -> None:
    """Negative runtimes, plans without objectives and failures with plans are refused."""
    with pytest.raises(ValueError, match="runtime_s"):
        Result(Status.FEASIBLE, 1.0, None, -1.0, "x", plan=[1])
    with pytest.raises(ValueError, match="needs a plan"):
        Result(Status.OPTIMAL, None, None, 1.0, "x", plan=None)
    with pytest.raises(ValueError, match="must not carry"):
        Result(Status.ERROR, None, None, 1.0, "x", plan=[1])


def test_registry_lookup_and_errors() -> None:
    """Backends are found by name; unknown names list the valid ones; duplicates are refused."""
    reg: Registry[int, int] = Registry("toy")

    def solve(problem: int, /, *, time_limit_s: float, seed: int) -> Result[int]:
        return Result(Status.OPTIMAL, float(problem), float(problem), 0.0, "double", plan=problem)

    reg.register(Backend("double", solve, True, "returns the input"))
    assert reg.get("double").solve(3, time_limit_s=1.0, seed=0).objective == 3.0
    with pytest.raises(InvalidInputError, match=r"\['double'\]"):
        reg.get("nope")
    with pytest.raises(ValueError, match="already"):
        reg.register(Backend("double", solve, True, "again"))


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


def test_merge_answers_takes_the_better_plan_and_the_tighter_bound() -> None:
    """merge_answers: best plan of the two, smallest bound, OPTIMAL once they meet; None
    without any plan."""
    from searchtrack.core.result import merge_answers

    heuristic = Result(Status.FEASIBLE, 9.0, 12.0, 0.1, "h", "plan-h")
    exact = Result(Status.FEASIBLE, 8.0, 10.0, 0.2, "x", "plan-x")
    merged = merge_answers(heuristic, exact, 0.3, 1e-6, {"k": 1.0})
    assert merged is not None
    assert (merged.plan, merged.objective, merged.bound, merged.backend) == ("plan-h", 9.0, 10.0,
                                                                            "h")
    assert merged.status is Status.FEASIBLE and merged.stats == {"k": 1.0}
    proved = Result(Status.OPTIMAL, 9.0, 9.0, 0.2, "x", "plan-x")
    done = merge_answers(heuristic, proved, 0.3, 1e-6)
    assert done is not None and done.status is Status.OPTIMAL and done.bound == 9.0
    none = Result(Status.NO_SOLUTION, None, None, 0.1, "x", None)
    assert merge_answers(none, none, 0.2, 1e-6) is None
