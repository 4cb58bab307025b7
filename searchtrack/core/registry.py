"""Backends looked up by name, each declaring whether it is exact and what it can solve, and the
two ways an ``auto`` backend composes them: :func:`heuristic_then_exact` (answer at once, then
improve or prove within the time left) and :func:`fallback_chain` (try each in turn until one
answers)."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status, interrupted, merge_answers, rejected

ProblemT = TypeVar("ProblemT", contravariant=True)
PlanT = TypeVar("PlanT")
P = TypeVar("P")
Q = TypeVar("Q")

log = logging.getLogger("searchtrack.core.registry")


#: Largest seed a solve takes: every backend's native seed (CP-SAT's and SCIP's are 32-bit signed
#: integers) can hold it, so a seed means the same run whichever backend answers.
MAX_SEED = 2**31 - 1


def check_seed(seed: object) -> int:
    """``seed`` if it is an integer in ``[0, MAX_SEED]``, else :class:`InvalidInputError`."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise InvalidInputError("seed", seed, f"must be an integer in [0, {MAX_SEED}]")
    return seed


class SolveFn(Protocol[ProblemT, PlanT]):
    """Signature every backend implements."""

    def __call__(
        self, problem: ProblemT, /, *, time_limit_s: float, seed: int
    ) -> Result[PlanT]: ...


@dataclass(frozen=True)
class Backend(Generic[P, Q]):
    """One way of solving a problem.

    Parameters
    ----------
    name
        Registry key, e.g. ``"ils"``.
    solve
        ``solve(problem, time_limit_s=..., seed=...) -> Result``.
    exact
        Whether the backend can prove optimality.
    description
        One line for ``--help`` texts.
    supports
        Returns ``None`` when the backend can take ``problem``, else the reason it cannot.
    kernels
        The numba kernel sets (``searchtrack warm-up`` names) the backend compiles on first use.
    """

    name: str
    solve: SolveFn[P, Q]
    exact: bool
    description: str
    supports: Callable[[P], str | None] = lambda _problem: None
    kernels: tuple[str, ...] = ()


#: ``validator(problem, result, seed)``: what an independent check finds wrong with the answer
#: (its plan, objective and bound) solved with ``seed``; empty when the answer holds.
Validator = Callable[[P, Result[Q], int], Sequence[str]]


class Named(Protocol):
    """An entry of a :class:`NameTable`: anything with a name."""

    @property
    def name(self) -> str: ...


EntryT = TypeVar("EntryT", bound=Named)


class NameTable(Generic[EntryT]):
    """A name → entry table in registration order, whose unknown names are a one-line
    :class:`~searchtrack.core.errors.InvalidInputError` listing the known ones.

    Parameters
    ----------
    noun
        What an entry is, in messages (``"OPTW backend"``, ``"road mission filter"``).
    field
        The input field an unknown name is reported against.
    """

    def __init__(self, noun: str, field: str) -> None:
        self.noun, self.field = noun, field
        self._entries: dict[str, EntryT] = {}

    def register(self, entry: EntryT) -> EntryT:
        """Add ``entry``; names are unique."""
        if entry.name in self._entries:
            raise ValueError(f"{self.noun} {entry.name!r} is already registered")
        self._entries[entry.name] = entry
        return entry

    def unregister(self, name: str) -> EntryT:
        """Remove and return the entry called ``name``."""
        entry = self.get(name)
        del self._entries[name]
        return entry

    def names(self) -> list[str]:
        """Registered names, in registration order."""
        return list(self._entries)

    def get(self, name: str) -> EntryT:
        """The entry called ``name``; an error lists the registered names."""
        try:
            return self._entries[name]
        except KeyError:
            raise InvalidInputError(self.field, name, f"unknown {self.noun}; choose one of "
                                    f"{self.names()}") from None


class Registry(NameTable[Backend[P, Q]]):
    """A name → backend table for one problem type.

    Parameters
    ----------
    problem
        The problem's name in messages.
    validator
        The family's independent checker, sharing no logic with the backends: :meth:`solve`
        turns an answer it rejects into ``ERROR`` (no plan), naming what it found.
    """

    def __init__(self, problem: str, validator: Validator[P, Q] | None = None) -> None:
        super().__init__(f"{problem} backend", "backend")
        self.problem = problem
        self.validator = validator

    def checked(self, name: str, problem: P, time_limit_s: float, seed: int) -> Backend[P, Q]:
        """The backend called ``name`` after the checks every ``solve()`` makes: a valid time
        limit, an integer seed in ``[0, MAX_SEED]``, a known backend that can take ``problem``."""
        check_time_limit(time_limit_s)
        check_seed(seed)
        chosen = self.get(name)
        reason = chosen.supports(problem)
        if reason is not None:
            raise InvalidInputError("backend", name, reason)
        return chosen

    def solve(self, name: str, problem: P, *, time_limit_s: float, seed: int) -> Result[Q]:
        """What a family's ``solve()`` does: :meth:`checked`, then the backend's answer, marked
        ``INTERRUPTED`` if a stop request cut it short (:func:`~searchtrack.core.result.
        interrupted`), logged at debug level, and checked by :meth:`validated`.

        Raises
        ------
        InvalidInputError
            As :meth:`checked`.
        """
        chosen = self.checked(name, problem, time_limit_s, seed)
        result = interrupted(chosen.solve(problem, time_limit_s=time_limit_s, seed=seed))
        log.debug("%s via %s: %s %s in %.3f s", self.problem, name, result.status.name,
                  result.objective, result.runtime_s)
        return self.validated(problem, result, seed)

    def validated(self, problem: P, result: Result[Q], seed: int = 0) -> Result[Q]:
        """``result`` (solved with ``seed``) if the family's validator accepts its answer (or
        there is no validator or no plan), else an ``ERROR`` result naming what it found."""
        if self.validator is None or result.plan is None:
            return result
        problems = list(self.validator(problem, result, seed))
        if problems:
            log.error("%s: %s returned an invalid answer: %s", self.problem, result.backend,
                      problems)
        return rejected(result, problems)


def relabel(result: Result[Q], deadline: Deadline, message: str,
            stats: dict[str, float] | None = None) -> Result[Q]:
    """``result`` as the answer of a composed backend: its runtime is the composite's
    (``deadline.elapsed()``), ``message`` replaces the message, ``stats`` are added."""
    return dataclasses.replace(result, runtime_s=deadline.elapsed(), message=message,
                               stats={**result.stats, **(stats or {})})


#: ``exact(problem, heuristic_answer, time_limit_s, seed)``: the exact stage of
#: :func:`heuristic_then_exact`, which may warm-start from the heuristic's plan; ``None`` when no
#: exact solver applies to this problem.
ExactStage = Callable[[P, Result[Q], float, int], Result[Q]]


def heuristic_then_exact(
    problem: P, heuristic: SolveFn[P, Q], exact: ExactStage[P, Q] | None, *,
    time_limit_s: float, seed: int, heuristic_limit_s: float, tol: float = 1e-6,
) -> Result[Q]:
    """``auto`` for a maximisation: the heuristic answers within ``heuristic_limit_s``, then the
    exact stage gets the rest of ``time_limit_s`` to improve or prove it.

    The answer carries the better plan, the tighter bound and ``OPTIMAL`` once they meet within
    ``tol`` (relative to ``max(1, objective)``); ``backend`` names the stage whose plan it is,
    ``stats`` hold ``heuristic_objective`` and ``heuristic_s``. The heuristic's answer is
    returned alone when it is already optimal, when ``exact`` is ``None`` or when no time is
    left.
    """
    deadline = Deadline(time_limit_s)
    first = heuristic(problem, time_limit_s=min(heuristic_limit_s, time_limit_s), seed=seed)
    if first.status is Status.OPTIMAL or exact is None or deadline.remaining() < 1e-3:
        said = f" ({first.message})" if first.message else ""
        return relabel(first, deadline, f"auto: {first.backend} answered{said}")
    second = exact(problem, first, max(1e-3, deadline.remaining()), seed)
    merged = merge_answers(first, second, deadline.elapsed(), tol,
                           {"heuristic_objective": first.objective or 0.0,
                            "heuristic_s": first.runtime_s})
    if merged is None:
        return relabel(second, deadline, f"auto: no plan ({second.message})")
    note = (f"auto: {first.backend} {first.objective:g} in {first.runtime_s:.2f} s; "
            f"{second.backend} {second.status.name}"
            + (f" {second.objective:g}" if second.objective is not None else "")
            + f"; {merged.backend} answered")
    return dataclasses.replace(merged, message=note)


def _has_plan(result: Result[Any]) -> bool:
    return result.status.has_plan


@dataclass(frozen=True)
class Stage(Generic[P, Q]):
    """One link of a :func:`fallback_chain`.

    Parameters
    ----------
    name
        Shown in the composite's message.
    solve
        The backend.
    share
        Fraction of the chain's whole time limit this stage may use; ``None``: what is left.
    min_s
        Least time limit the stage is given, even when the chain's time is nearly spent.
    supports
        ``None`` when the stage can take the problem, else the reason it is skipped.
    """

    name: str
    solve: SolveFn[P, Q]
    share: float | None = None
    min_s: float = 1e-3
    supports: Callable[[P], str | None] = lambda _problem: None


def fallback_chain(
    problem: P, stages: Sequence[Stage[P, Q]], *, time_limit_s: float, seed: int,
    accept: Callable[[Result[Q]], bool] = _has_plan,
) -> Result[Q]:
    """``auto`` as a chain: each stage in turn until one's answer is accepted (by default, one
    with a plan), all within ``time_limit_s``.

    The answer is the accepted stage's, relabelled: ``message`` says which stages failed and
    why, ``stats["fallbacks"]`` counts them. When no stage is accepted, the last answer comes
    back with every reason. Every stage gets at least its ``min_s``, so a last-resort stage
    (a closed-form law) answers even when the earlier ones spent the whole limit.
    """
    if not stages:
        raise ValueError("fallback_chain needs at least one stage")
    deadline = Deadline(time_limit_s)
    notes: list[str] = []
    last: Result[Q] | None = None
    tried = 0
    for stage in stages:
        reason = stage.supports(problem)
        if reason is not None:
            notes.append(f"{stage.name} skipped ({reason})")
            continue
        limit = deadline.remaining() if stage.share is None else stage.share * time_limit_s
        answer = stage.solve(problem, time_limit_s=max(stage.min_s, limit), seed=seed)
        if accept(answer):
            return relabel(answer, deadline, "auto: " + "".join(f"{n}; " for n in notes)
                           + f"{stage.name} answered", {"fallbacks": float(tried)})
        notes.append(f"{stage.name} failed ({answer.message})")
        last = answer
        tried += 1
    if last is None:
        raise InvalidInputError("backend", "auto", "; ".join(notes))
    log.warning("auto: no stage answered: %s", "; ".join(notes))
    return relabel(last, deadline, "auto: " + "; ".join(notes),
                   {"fallbacks": float(max(0, tried - 1))})
