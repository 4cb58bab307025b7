"""Plan families of ``searchtrack plan FAMILY PROBLEM.json``: one module per family, each a
:class:`PlanJob`.

A family is a module of this package; its name is the module's name (``assign``, ``associate``,
``route``, ``search``, ``trajectory``). :func:`families` lists them, :func:`load` imports one and
checks that it has the interface :mod:`searchtrack.cli.plan` calls (one member,
``geo_projection``, is optional: :func:`geo_projection`). Adding a family is one module
here (and its solver family under :mod:`searchtrack.plan`): the command line, its ``--help`` and
backend choices follow from the module.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol, cast, runtime_checkable

from searchtrack.core.registry import Registry
from searchtrack.core.result import Result
from searchtrack.models.projection import LocalProjection
from searchtrack.sim.export.plans import VehiclePaths


@runtime_checkable
class PlanJob(Protocol):
    """What a ``plan`` family module provides (a module satisfies this protocol).

    A module whose problems carry a geographic frame (a map read from OpenStreetMap) also
    defines ``geo_projection(problem) -> LocalProjection | None``, the projection of the
    problem's planar frame; the others leave it out (:func:`geo_projection`).

    Attributes
    ----------
    DESCRIPTION
        One line for ``--help``.
    BACKENDS
        The family's solver registry (its validator checks every answer).
    KERNELS
        The compiled kernel sets a solve may need (:mod:`searchtrack.sim.kernels`), warmed up
        before solving.
    """

    DESCRIPTION: str
    BACKENDS: Registry[Any, Any]
    KERNELS: tuple[str, ...]

    def backends(self) -> list[str]:
        """The backend names of :attr:`BACKENDS` as ``--backend`` offers them, ``"auto"`` first."""
        ...

    def read_problem(self, path: str | Path) -> Any:
        """The validated problem, or a :class:`~searchtrack.core.errors.ParseError` naming the
        file and the dotted JSON key."""
        ...

    def solve(self, problem: Any, *, backend: str, time_limit_s: float,
              seed: int) -> Result[Any]:
        """The problem solved by ``backend`` within ``time_limit_s``."""
        ...

    def plan_json(self, problem: Any, result: Result[Any]) -> dict[str, Any]:
        """The family's ``"plan"`` object of PLAN.json (called only when there is a plan)."""
        ...

    def figure(self, problem: Any, result: Result[Any], path: Path) -> Path | None:
        """A PNG of the plan at ``path``, or ``None`` when there is nothing to draw."""
        ...

    def vehicle_paths(self, problem: Any, result: Result[Any]) -> VehiclePaths:
        """The positions each vehicle of the plan flies through, for ``--export`` (none for a
        plan that moves no vehicle; called only when there is a plan)."""
        ...


def geo_projection(job: PlanJob, problem: Any) -> LocalProjection | None:
    """The projection of ``problem``'s planar frame from the optional
    ``geo_projection(problem)`` of the family module ``job``; ``None`` when the module defines
    none or the problem has no geographic frame (``--export`` then needs ``--origin``)."""
    project: Callable[[Any], LocalProjection | None] | None = getattr(job, "geo_projection",
                                                                      None)
    return None if project is None else project(problem)


def families() -> list[str]:
    """The family names: the modules of this package, sorted."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))


def load(name: str) -> PlanJob:
    """The module of family ``name``, imported now.

    Raises
    ------
    KeyError
        ``name`` is not a family.
    TypeError
        The module lacks part of the :class:`PlanJob` interface.
    """
    if name not in families():
        raise KeyError(name)
    module: ModuleType = importlib.import_module(f"{__name__}.{name}")
    if not isinstance(module, PlanJob):
        members = [*PlanJob.__annotations__,
                   *(n for n, v in vars(PlanJob).items() if callable(v) and n[0] != "_")]
        missing = [n for n in members if not hasattr(module, n)]
        raise TypeError(f"plan family module {module.__name__} lacks {missing}")
    return cast(PlanJob, module)
