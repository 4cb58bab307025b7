"""Solve an OPTW by backend name; ``auto`` answers with the heuristic, then improves or proves it.

Every plan a backend returns is re-checked by the independent validator; a plan it rejects turns
the result into ``ERROR`` (never a silent wrong answer). The backends on OR-Tools (``cpsat``,
``bp``, ``mip``, and ``auto`` with two or more vehicles) import it within their time
(:func:`~searchtrack.core.loading.loaded_within`): a first call whose limit runs out while it
loads answers without it (``auto``: the ILS's answer).
"""

from __future__ import annotations

import importlib
import logging
import time

from searchtrack.core.deadline import Deadline
from searchtrack.core.loading import loaded_within, still_loading
from searchtrack.core.registry import Backend, Registry, heuristic_then_exact
from searchtrack.core.result import Result, interrupted
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.validate import validate

log = logging.getLogger("searchtrack.plan.optw")

_TOL = 1e-6


def _ils(inst: OPTWInstance, *, time_limit_s: float, seed: int) -> Result[Routes]:
    from searchtrack.plan.optw.ils import solve_ils

    return solve_ils(inst, time_limit_s=time_limit_s, seed=seed)


def _labelling(inst: OPTWInstance, *, time_limit_s: float, seed: int) -> Result[Routes]:
    from searchtrack.plan.optw.labelling import solve_labelling

    return solve_labelling(inst, time_limit_s=time_limit_s, seed=seed)


def _cpsat(inst: OPTWInstance, *, time_limit_s: float, seed: int) -> Result[Routes]:
    deadline = Deadline(time_limit_s)
    if not loaded_within("searchtrack.plan.optw.cpsat", deadline):
        return still_loading("cpsat", "OR-Tools", deadline)
    from searchtrack.plan.optw.cpsat import solve_cpsat

    return solve_cpsat(inst, time_limit_s=max(1e-3, deadline.remaining()), seed=seed)


def _bp(inst: OPTWInstance, *, time_limit_s: float, seed: int,
        initial: Routes | None = None) -> Result[Routes]:
    deadline = Deadline(time_limit_s)
    if not loaded_within("searchtrack.plan.optw.bp", deadline):
        return still_loading("bp", "OR-Tools", deadline)
    from searchtrack.plan.optw.bp import solve_bp

    return solve_bp(inst, time_limit_s=max(1e-3, deadline.remaining()), seed=seed,
                    initial=initial)


def _mip(inst: OPTWInstance, *, time_limit_s: float, seed: int) -> Result[Routes]:
    deadline = Deadline(time_limit_s)
    if not loaded_within("searchtrack.plan.optw.mip", deadline):
        return still_loading("mip", "OR-Tools", deadline)
    from searchtrack.plan.optw.mip import solve_mip

    return solve_mip(inst, time_limit_s=max(1e-3, deadline.remaining()), seed=seed)


def heuristic_share(time_limit_s: float) -> float:
    """Seconds ``auto`` gives the heuristic before the exact solver: 10 % of the limit (at least
    20 ms, but never more than half the limit), ≤ 1 s."""
    return min(1.0, 0.5 * time_limit_s, max(0.02, 0.1 * time_limit_s))


def _prover(inst: OPTWInstance) -> str:
    """The backend ``auto`` proves ``inst`` with: the labelling DP on one vehicle, else
    branch-and-price."""
    return "labelling" if inst.vehicles == 1 else "bp"


def _auto(inst: OPTWInstance, *, time_limit_s: float, seed: int) -> Result[Routes]:
    from searchtrack.plan.optw.ils import solve_ils
    from searchtrack.plan.optw.labelling import solve_labelling

    def exact(problem: OPTWInstance, first: Result[Routes], limit_s: float,
              seed: int) -> Result[Routes]:
        if _prover(problem) == "labelling":
            return solve_labelling(problem, time_limit_s=limit_s, seed=seed, initial=first.plan)
        return _bp(problem, time_limit_s=limit_s, seed=seed, initial=first.plan)

    return heuristic_then_exact(inst, solve_ils, exact, time_limit_s=time_limit_s, seed=seed,
                                heuristic_limit_s=heuristic_share(time_limit_s), tol=_TOL)


#: The kernel sets of the ILS, the labelling DP and branch-and-price (``searchtrack warm-up``
#: names).
ILS_KERNELS, LABELLING_KERNELS, BP_KERNELS = "optw-ils", "optw-labelling", "optw-bp"

_WARMED: set[str] = set()


def warm_set(kernel: str) -> None:
    """Compile (or load from numba's cache) the kernel set ``kernel`` (one of the names above)
    through its module's ``warm_up``, which solves a small instance."""
    module = {ILS_KERNELS: "ils", LABELLING_KERNELS: "labelling", BP_KERNELS: "bp_warm_up"}[kernel]
    importlib.import_module(f"searchtrack.plan.optw.{module}").warm_up()


def warm_up(backend: str, instance: OPTWInstance | None = None) -> None:
    """Compile (or load from numba's cache) the kernels ``backend`` needs, once per process;
    for ``auto`` given the ``instance``, only those of the ILS and of the backend that proves it.

    ``solve`` calls it before starting the clock, so a time limit measures solving, not
    just-in-time compilation (about 20 s per kernel set on a cold cache, under 1 s warm).
    """
    kernels = BACKENDS.get(backend).kernels
    if backend == "auto" and instance is not None:
        kernels = (ILS_KERNELS, *BACKENDS.get(_prover(instance)).kernels)
    for kernel in dict.fromkeys(kernels):
        if kernel in _WARMED:
            continue
        started = time.perf_counter()
        warm_set(kernel)
        _WARMED.add(kernel)
        log.info("%s kernels ready in %.2f s", kernel, time.perf_counter() - started)


def _single_vehicle(inst: OPTWInstance) -> str | None:
    return None if inst.vehicles == 1 else "solves single-vehicle instances only (vehicles=1)"


BACKENDS: Registry[OPTWInstance, Routes] = Registry(
    "optw", validator=lambda instance, result, seed: answer_problems(instance, result))
BACKENDS.register(Backend("auto", _auto, True,
                          "ILS answer at once, then labelling (m = 1) or branch-and-price "
                          "(m ≥ 2) to prove it",
                          kernels=(ILS_KERNELS, LABELLING_KERNELS, BP_KERNELS)))
BACKENDS.register(Backend("ils", _ils, False, "iterated local search (Vansteenwegen et al. 2009+)",
                          kernels=(ILS_KERNELS,)))
BACKENDS.register(Backend("labelling", _labelling, True,
                          "labelling DP with decremental state-space relaxation (m = 1)",
                          supports=_single_vehicle, kernels=(LABELLING_KERNELS,)))
BACKENDS.register(Backend("cpsat", _cpsat, True, "OR-Tools CP-SAT circuit model"))
BACKENDS.register(Backend("bp", _bp, True,
                          "branch-and-price on route columns (Boussier, Feillet & Gendreau 2007)",
                          kernels=(ILS_KERNELS, LABELLING_KERNELS, BP_KERNELS)))
BACKENDS.register(Backend("mip", _mip, True, "integer program (5.17)–(5.26) with OR-Tools SCIP"))


def solve(
    instance: OPTWInstance, *, backend: str = "auto", time_limit_s: float = 10.0, seed: int = 0
) -> Result[Routes]:
    """Solve ``instance`` with the named backend within ``time_limit_s`` seconds.

    The first call in a process first readies the backend's numba kernels (see :func:`warm_up`);
    that one-off cost is outside ``time_limit_s`` and ``runtime_s``.

    Parameters
    ----------
    instance
        The (team) OPTW.
    backend
        ``"auto"``, ``"ils"``, ``"labelling"``, ``"cpsat"``, ``"bp"`` or ``"mip"``.
    time_limit_s
        Wall-clock limit, honoured by every backend.
    seed
        Seed of the heuristic's random choices and of the solvers that take one.

    Raises
    ------
    InvalidInputError
        Unknown backend, a backend that cannot take this instance, or a bad time limit.
    """
    chosen = BACKENDS.checked(backend, instance, time_limit_s, seed)
    warm_up(backend, instance)
    started = time.perf_counter()
    result = interrupted(chosen.solve(instance, time_limit_s=time_limit_s, seed=seed))
    log.info("optw %s via %s: %s %s in %.3f s", instance.name, backend, result.status.name,
             result.objective, time.perf_counter() - started)
    return checked(instance, result)


def answer_problems(instance: OPTWInstance, result: Result[Routes],
                    seed: int = 0) -> list[str]:
    """What the independent validator finds wrong with ``result``'s routes, objective and
    bound (empty when they hold)."""
    del seed  # the check draws nothing
    assert result.plan is not None
    report = validate(instance, result.plan)
    problems = list(report.violations)
    if result.objective is not None and abs(report.profit - result.objective) > _TOL:
        problems.append(f"reported profit {result.objective} but the routes collect "
                        f"{report.profit}")
    if result.bound is not None and report.profit > result.bound + _TOL:
        problems.append(f"profit {report.profit} exceeds the claimed bound {result.bound}")
    return problems


def checked(instance: OPTWInstance, result: Result[Routes]) -> Result[Routes]:
    """``result`` if the validator accepts its plan and objective, else an ``ERROR`` result."""
    return BACKENDS.validated(instance, result)


def solve_ils_capped(instance: OPTWInstance, *, time_limit_s: float, seed: int,
                     max_iterations: int) -> Result[Routes]:
    """The ILS within ``time_limit_s`` and at most ``max_iterations`` iterations (the same
    answer on any machine that reaches the cap in time), its kernels readied first and its
    answer checked by the validator as :func:`solve` checks every backend's."""
    from searchtrack.plan.optw.ils import solve_ils

    warm_up("ils")
    return checked(instance, solve_ils(instance, time_limit_s=time_limit_s, seed=seed,
                                       max_iterations=max_iterations))
