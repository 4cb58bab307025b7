"""The one result type every solver returns: status, objective, bound, gap, runtime, plan."""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Generic, TypeVar

from searchtrack.core.interrupt import stop_requested

PlanT = TypeVar("PlanT")


class Status(enum.Enum):
    """Outcome of a solve, shared by every backend (each native status is mapped explicitly)."""

    OPTIMAL = "OPTIMAL"  # the plan is proven optimal
    FEASIBLE = "FEASIBLE"  # a valid plan, optimality not proven
    INFEASIBLE = "INFEASIBLE"  # proven that no valid plan exists
    NO_SOLUTION = "NO_SOLUTION"  # no plan found within the limits, nothing proven
    INTERRUPTED = "INTERRUPTED"  # stopped on request; may carry the best plan and bound so far
    ERROR = "ERROR"  # the backend failed; see the message

    @property
    def has_plan(self) -> bool:
        """True for the statuses that always carry a plan (an ``INTERRUPTED`` result may)."""
        return self in (Status.OPTIMAL, Status.FEASIBLE)


class Sense(enum.Enum):
    """Whether the objective is maximised or minimised."""

    MAXIMIZE = "max"
    MINIMIZE = "min"


@dataclass(frozen=True)
class Result(Generic[PlanT]):
    """What a solver returns.

    Parameters
    ----------
    status
        The outcome.
    objective
        Objective value of ``plan``; ``None`` when there is no plan.
    bound
        Proven bound on the optimum (upper for maximisation), ``None`` when the backend proves none.
    runtime_s
        Wall-clock seconds spent.
    backend
        Name of the backend that produced ``plan`` (for ``auto``, the one that answered).
    plan
        The solution, or ``None``. An ``INFEASIBLE`` or ``NO_SOLUTION`` result may carry a
        *fallback* instead: a plan that breaks a constraint (e.g. the least-violating one), which
        the caller may use at its own risk; ``has_plan`` stays False for these statuses, so no
        composition mistakes a fallback for a solution.
    sense
        Maximise or minimise (sets the sign convention of ``gap``).
    message
        Free text: the native status, why a fallback fired, what was proven.
    """

    status: Status
    objective: float | None
    bound: float | None
    runtime_s: float
    backend: str
    plan: PlanT | None
    sense: Sense = Sense.MAXIMIZE
    message: str = ""
    stats: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not (self.runtime_s >= 0.0 and math.isfinite(self.runtime_s)):
            raise ValueError(f"runtime_s={self.runtime_s!r}: must be finite and non-negative")
        if self.status.has_plan and (self.plan is None or self.objective is None):
            raise ValueError(f"status={self.status.name} needs a plan and an objective")
        if self.status is Status.INTERRUPTED:
            if self.plan is not None and self.objective is None:
                raise ValueError("an INTERRUPTED result with a plan needs its objective")
        elif self.status is Status.ERROR and self.plan is not None:
            raise ValueError(f"status={self.status.name} must not carry a plan")

    @property
    def fallback(self) -> PlanT | None:
        """The plan of an ``INFEASIBLE`` or ``NO_SOLUTION`` result that breaks a constraint
        (``None`` for the other statuses, whose plan is a solution)."""
        if self.status in (Status.INFEASIBLE, Status.NO_SOLUTION):
            return self.plan
        return None

    @property
    def gap(self) -> float | None:
        """Relative optimality gap ``|bound − objective| / max(|objective|, 1)``; 0 when optimal."""
        if self.status is Status.OPTIMAL:
            return 0.0
        if self.objective is None or self.bound is None:
            return None
        diff = self.bound - self.objective
        if self.sense is Sense.MINIMIZE:
            diff = -diff
        return max(0.0, diff) / max(abs(self.objective), 1.0)


def merge_answers(heuristic: Result[PlanT], exact: Result[PlanT], runtime_s: float,
                  tol: float, stats: dict[str, float] | None = None) -> Result[PlanT] | None:
    """One maximisation answer from a heuristic run and an exact run: the better plan, the
    tighter bound, ``OPTIMAL`` once the plan meets the bound within ``tol`` (relative to
    ``max(1, objective)``); ``None`` when neither has a plan. The caller sets the message."""
    candidates = [r for r in (exact, heuristic) if r.status.has_plan]
    if not candidates:
        return None
    best = max(candidates, key=lambda r: r.objective or 0.0)
    bounds = [r.bound for r in (heuristic, exact) if r.bound is not None]
    bound = min(bounds) if bounds else None
    objective = best.objective if best.objective is not None else 0.0
    optimal = bound is not None and bound - objective <= tol * max(1.0, objective)
    return Result(Status.OPTIMAL if optimal else best.status, objective, bound, runtime_s,
                  best.backend, best.plan, stats=dict(stats or {}))


def interrupted(result: Result[PlanT]) -> Result[PlanT]:
    """``result`` marked ``INTERRUPTED`` when a stop was requested and it is not proven:
    a ``FEASIBLE`` answer keeps its plan and bound, a ``NO_SOLUTION`` has none (one with a
    fallback keeps its status and fallback, with the note). Proven answers
    (``OPTIMAL``, ``INFEASIBLE``) and errors are returned as they are."""
    if not stop_requested() or result.status not in (Status.FEASIBLE, Status.NO_SOLUTION):
        return result
    note = "interrupted" + (f": {result.message}" if result.message else "")
    if result.fallback is not None:  # keep the fallback: it is not a solution to report
        return dataclasses.replace(result, message=note)
    return dataclasses.replace(result, status=Status.INTERRUPTED, message=note)


def rejected(result: Result[PlanT], problems: Sequence[str]) -> Result[PlanT]:
    """``result`` as an ``ERROR`` without plan, objective or bound when an independent check
    found ``problems`` in its answer; ``result`` itself when there are none."""
    if not problems:
        return result
    return dataclasses.replace(result, status=Status.ERROR, objective=None, bound=None,
                               plan=None, message="validator rejected the plan: "
                               + "; ".join(problems))
