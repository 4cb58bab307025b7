"""Backends looked up by name, each declaring whether it is exact and what it can solve."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, Protocol, TypeVar

from searchtrack.errors import InvalidInputError
from searchtrack.plan.result import Result
from searchtrack.plan.stop import check_time_limit

ProblemT = TypeVar("ProblemT", contravariant=True)
PlanT = TypeVar("PlanT")
P = TypeVar("P")
Q = TypeVar("Q")


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
    """

    name: str
    solve: SolveFn[P, Q]
    exact: bool
    description: str
    supports: Callable[[P], str | None] = lambda _problem: None


class Registry(Generic[P, Q]):
    """A name → backend table for one problem type."""

    def __init__(self, problem: str) -> None:
        self.problem = problem
        self._backends: dict[str, Backend[P, Q]] = {}

    def register(self, backend: Backend[P, Q]) -> Backend[P, Q]:
        """Add ``backend``; names are unique."""
        if backend.name in self._backends:
            raise ValueError(f"{self.problem} backend {backend.name!r} is already registered")
        self._backends[backend.name] = backend
        return backend

    def names(self) -> list[str]:
        """Registered names, in registration order."""
        return list(self._backends)

    def get(self, name: str) -> Backend[P, Q]:
        """The backend called ``name``; an error lists the valid names."""
        try:
            return self._backends[name]
        except KeyError:
            raise InvalidInputError(
                "backend", name, f"unknown {self.problem} backend; choose one of {self.names()}"
            ) from None

    def checked(self, name: str, problem: P, time_limit_s: float, seed: int) -> Backend[P, Q]:
        """The backend called ``name`` after the checks every ``solve()`` makes: a valid time
        limit, a non-negative integer seed, a known backend that can take ``problem``."""
        check_time_limit(time_limit_s)
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise InvalidInputError("seed", seed, "must be a non-negative integer")
        chosen = self.get(name)
        reason = chosen.supports(problem)
        if reason is not None:
            raise InvalidInputError("backend", name, reason)
        return chosen
