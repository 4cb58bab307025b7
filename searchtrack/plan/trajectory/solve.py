"""Trajectory controllers by name; ``auto`` tries NMPC, then the QP, then the closed form.

``auto`` gives NMPC :data:`NMPC_SHARE` of the time limit (Ipopt's wall-time limit); if NMPC
fails or overruns it, the LTV-MPC QP gets the rest, and if that fails too the closed-form law
answers (it always does). The result names the controller that answered in ``backend`` and the
fallbacks that fired in ``message`` and ``stats["fallbacks"]``.
"""

from __future__ import annotations

import logging

from searchtrack.plan.registry import Backend, Registry
from searchtrack.plan.result import Result
from searchtrack.plan.stop import Deadline
from searchtrack.plan.trajectory.closed_form import MODELS, solve_closed_form
from searchtrack.plan.trajectory.ltv_mpc import solve_ltv_mpc
from searchtrack.plan.trajectory.nmpc import prepare, solve_nmpc
from searchtrack.plan.trajectory.problem import ControlPlan, TrackingProblem

log = logging.getLogger("searchtrack.plan.trajectory")

NMPC_SHARE = 0.6
_MIN_QP_S = 2e-3


def _nmpc(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_nmpc(problem, time_limit_s=time_limit_s)


def _ltv(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_ltv_mpc(problem, time_limit_s=time_limit_s)


def _closed(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_closed_form(problem)


def _auto(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    nmpc_s = max(1e-3, NMPC_SHARE * time_limit_s)
    prepare(problem, nmpc_s)  # a new shape's one-off build stays outside the clock
    deadline = Deadline(time_limit_s)
    notes: list[str] = []
    first = solve_nmpc(problem, time_limit_s=nmpc_s)
    if first.status.has_plan:
        return _relabel(first, deadline, "auto: nmpc answered", 0)
    notes.append(f"nmpc failed ({first.message})")
    second = solve_ltv_mpc(problem, time_limit_s=max(_MIN_QP_S, deadline.remaining()))
    if second.status.has_plan:
        return _relabel(second, deadline, "auto: " + "; ".join(notes) + "; ltv_mpc answered", 1)
    notes.append(f"ltv_mpc failed ({second.message})")
    if _closed_form_models(problem) is not None:
        log.warning("trajectory auto: no controller answered: %s", "; ".join(notes))
        return _relabel(second, deadline, "auto: " + "; ".join(notes)
                        + f"; no closed-form law for model {problem.model.name!r}", 1)
    third = solve_closed_form(problem)
    log.info("trajectory auto fell back to the closed form: %s", "; ".join(notes))
    return _relabel(third, deadline, "auto: " + "; ".join(notes) + "; closed_form answered", 2)


def _relabel(result: Result[ControlPlan], deadline: Deadline, message: str, fallbacks: int
             ) -> Result[ControlPlan]:
    return Result(status=result.status, objective=result.objective, bound=result.bound,
                  runtime_s=deadline.elapsed(), backend=result.backend, plan=result.plan,
                  sense=result.sense, message=message,
                  stats={**result.stats, "fallbacks": float(fallbacks)})


def _closed_form_models(problem: TrackingProblem) -> str | None:
    name = problem.model.name
    return None if name in MODELS else f"no closed-form law for model {name!r}"


BACKENDS: Registry[TrackingProblem, ControlPlan] = Registry("trajectory")
BACKENDS.register(Backend("auto", _auto, False,
                          "NMPC, falling back to the LTV-MPC QP, then to the closed form "
                          "(for models that have one)"))
BACKENDS.register(Backend("nmpc", _nmpc, False, "multiple-shooting NMPC, CasADi + Ipopt"))
BACKENDS.register(Backend("ltv_mpc", _ltv, False, "linear time-varying MPC QP with OSQP"))
BACKENDS.register(Backend("closed_form", _closed, False,
                          "backstepping (004 eq. 13–15) / pure-pursuit law",
                          supports=_closed_form_models))


def solve(problem: TrackingProblem, *, backend: str = "auto", time_limit_s: float = 0.05,
          seed: int = 0) -> Result[ControlPlan]:
    """Answer ``problem`` with the named controller within ``time_limit_s`` seconds.

    Parameters
    ----------
    problem
        The tracking problem (validated on construction).
    backend
        ``"auto"``, ``"nmpc"``, ``"ltv_mpc"`` or ``"closed_form"``.
    time_limit_s
        Wall-clock budget of this solve (the one-off solver build of a new problem shape is
        not counted).
    seed
        Unused (every controller is deterministic); kept for the registry signature.

    Raises
    ------
    InvalidInputError
        Unknown backend, a backend that cannot take this model, or a bad time limit.
    """
    chosen = BACKENDS.checked(backend, problem, time_limit_s, seed)
    return chosen.solve(problem, time_limit_s=time_limit_s, seed=seed)
