"""Trajectory controllers by name; ``auto`` tries the real-time iteration, then NMPC, then the
closed form.

The real-time iteration (``ltv_mpc``, after Diehl et al.'s RTI scheme) answers each control
step with one QP of the problem linearised about the shifted previous plan (a few
linearise–solve rounds on a cold start), warm-started from the previous QP's shifted primal and
dual solution. ``auto`` gives it :data:`RTI_SHARE` of the time limit; if it fails (OSQP gives no
solution, or its plan would enter an obstacle by more than the safety margin) the full NMPC
(CasADi + Ipopt) gets the rest, and if that fails too the closed-form law answers (it always
does). The result names the controller that answered in ``backend`` and the fallbacks that fired
in ``message`` and ``stats["fallbacks"]``.
"""

from __future__ import annotations

from searchtrack.core.registry import Backend, Registry, Stage, fallback_chain
from searchtrack.core.result import Result
from searchtrack.plan.trajectory.closed_form import MODELS, solve_closed_form
from searchtrack.plan.trajectory.ltv_mpc import solve_ltv_mpc
from searchtrack.plan.trajectory.nmpc import prepare, solve_nmpc
from searchtrack.plan.trajectory.problem import ControlPlan, TrackingProblem
from searchtrack.plan.trajectory.validate import answer_problems

RTI_SHARE = 0.4
_MIN_QP_S = 2e-3


def _nmpc(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_nmpc(problem, time_limit_s=time_limit_s)


def _ltv(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_ltv_mpc(problem, time_limit_s=time_limit_s)


def _closed(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    return solve_closed_form(problem)


def _auto(problem: TrackingProblem, *, time_limit_s: float, seed: int) -> Result[ControlPlan]:
    prepare(problem, max(1e-3, (1.0 - RTI_SHARE) * time_limit_s))  # a new shape: off the clock
    return fallback_chain(problem, _STAGES, time_limit_s=time_limit_s, seed=seed)


def _closed_form_models(problem: TrackingProblem) -> str | None:
    name = problem.model.name
    return None if name in MODELS else f"no closed-form law for model {name!r}"


_STAGES: tuple[Stage[TrackingProblem, ControlPlan], ...] = (
    Stage("ltv_mpc", _ltv, share=RTI_SHARE, min_s=_MIN_QP_S),
    Stage("nmpc", _nmpc),
    Stage("closed_form", _closed, supports=_closed_form_models),
)

BACKENDS: Registry[TrackingProblem, ControlPlan] = Registry("trajectory",
                                                            validator=answer_problems)
BACKENDS.register(Backend("auto", _auto, False,
                          "the real-time iteration (one QP per step), falling back to NMPC, "
                          "then to the closed form (for models that have one)"))
BACKENDS.register(Backend("nmpc", _nmpc, False, "multiple-shooting NMPC, CasADi + Ipopt"))
BACKENDS.register(Backend("ltv_mpc", _ltv, False, "real-time iteration: the linear time-varying "
                          "MPC QP about the shifted plan, OSQP"))
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
    return BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
