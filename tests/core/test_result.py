"""The one result type: gap, refused nonsense, merged answers."""

from __future__ import annotations

import math

import pytest

from searchtrack.core import Result, Sense, Status


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


def test_infeasible_may_carry_a_fallback_that_is_not_a_solution() -> None:
    """INFEASIBLE / NO_SOLUTION may carry a constraint-breaking fallback: it is exposed as
    ``fallback``, the status still has no plan, and merging ignores it."""
    from searchtrack.core.result import merge_answers

    proved = Result(Status.INFEASIBLE, None, None, 1.0, "x", plan=["least violating"])
    assert proved.fallback == ["least violating"] and not proved.status.has_plan
    assert Result(Status.FEASIBLE, 1.0, None, 1.0, "x", plan=[1]).fallback is None
    assert merge_answers(proved, Result(Status.NO_SOLUTION, None, None, 1.0, "y", [2]), 1.0,
                         1e-6) is None


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


def test_status_has_plan_only_when_it_always_carries_one() -> None:
    """OPTIMAL and FEASIBLE always carry a plan; INTERRUPTED may, the others never do."""
    assert {s for s in Status if s.has_plan} == {Status.OPTIMAL, Status.FEASIBLE}
    kept = Result(Status.INTERRUPTED, 2.0, 4.0, 0.0, "x", "plan")
    assert kept.gap == pytest.approx(1.0) and kept.plan == "plan"


def test_gap_is_never_negative_and_relative_to_at_least_one() -> None:
    """A bound on the wrong side of the objective gives gap 0; objectives below 1 divide by 1."""
    assert Result(Status.FEASIBLE, 5.0, 4.0, 0.0, "x", plan=[1]).gap == 0.0
    assert Result(Status.FEASIBLE, 0.5, 0.75, 0.0, "x", plan=[1]).gap == pytest.approx(0.25)
    assert Result(Status.NO_SOLUTION, None, 3.0, 0.0, "x", plan=None).gap is None


@pytest.mark.parametrize("runtime", [math.inf, math.nan])
def test_result_refuses_a_non_finite_runtime(runtime: float) -> None:
    """An infinite or NaN runtime is refused naming ``runtime_s``."""
    with pytest.raises(ValueError, match="runtime_s"):
        Result(Status.NO_SOLUTION, None, None, runtime, "x", plan=None)
