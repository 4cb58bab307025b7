"""Nonlinear MPC: multiple shooting with RK4, CasADi ``nlpsol`` (Ipopt by default).

Decision variables ``X = (x_0..x_N)``, ``U = (u_0..u_{N−1})``; ``x_0`` is pinned to the state
through its bounds. Constraints: ``x_{k+1} = F_RK4(x_k, u_k, wind)``, state and input boxes,
``|u_k − u_{k−1}| ≤ u̇_max Δt`` (``u_{−1}`` the applied input) and, for every stage ``k ≥ 1`` and
obstacle ``j``, ``‖p_k − c_j‖² ≥ (r_j + margin)²`` (the ``z`` term dropped for cylinders). The
cost is the one of :class:`~searchtrack.plan.trajectory.problem.TrackingWeights`. Ipopt's
``max_wall_time`` is the time budget, and an iteration callback ends the solve at the next
iteration once a stop is requested (:mod:`searchtrack.core.interrupt`): the answer is then
``INTERRUPTED``, with the iterate as its plan if it is feasible. The solver is built once
per problem shape and options (:func:`build`, cached) with the state, previous input, reference,
wind and obstacles as parameters, and warm-started from the shifted previous plan.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import math
import tempfile
import time
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from searchtrack.core.deadline import check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.trajectory.options import NmpcOptions
from searchtrack.plan.trajectory.problem import (
    ControlPlan,
    TrackingProblem,
    TrackingWeights,
    initial_guess,
    project_inputs,
)
from searchtrack.plan.trajectory.symbolic import step_function

log = logging.getLogger("searchtrack.plan.trajectory.nmpc")

_FEAS_TOL = 1e-5
_OK = {"Solve_Succeeded": "locally optimal", "Solved_To_Acceptable_Level": "acceptable"}


class StopCallback(ca.Callback):
    """The NLP solver's iteration callback: returns 1, which ends the solve
    (``User_Requested_Stop``), once a stop is requested."""

    def __init__(self, n_x: int, n_g: int, n_p: int) -> None:
        ca.Callback.__init__(self)
        self._sizes = {"x": n_x, "lam_x": n_x, "g": n_g, "lam_g": n_g, "lam_p": n_p, "f": 1}
        self.construct("searchtrack_stop", {})

    def get_n_in(self) -> int:
        return int(ca.nlpsol_n_out())

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return str(ca.nlpsol_out(i))

    def get_name_out(self, i: int) -> str:
        return "ret"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self._sizes[ca.nlpsol_out(i)], 1)

    def eval(self, arg: Sequence[ca.DM]) -> list[float]:
        return [1.0 if stop_requested() else 0.0]


@dataclass(frozen=True)
class NmpcSolver:
    """A built NLP and the layout needed to fill its parameters and read its solution
    (``callback`` is kept alive with the solver that calls it)."""

    solver: ca.Function
    model: VehicleModel
    horizon: int
    n_obstacles: int
    n_g: int
    options: NmpcOptions
    callback: StopCallback


def _nlp_options(options: NmpcOptions, budget_s: float,
                 callback: StopCallback) -> dict[str, Any]:
    opts: dict[str, Any] = {"expand": options.expand, "print_time": False,
                            "error_on_fail": False, "iteration_callback": callback}
    if options.jit:
        opts.update({"jit": True, "compiler": "shell",
                     "jit_options": {"flags": ["-O1"], "verbose": False}})
    if options.solver == "ipopt":
        opts["ipopt"] = {
            "print_level": 0, "sb": "yes", "max_iter": options.max_iter,
            "max_wall_time": budget_s, "max_cpu_time": 4.0 * budget_s,
            "hessian_approximation": options.hessian,
            "linear_solver": options.linear_solver, "tol": options.tol,
            "acceptable_tol": 100.0 * options.tol,
            "mu_init": options.mu_init,
            "warm_start_init_point": "yes", "mu_strategy": options.mu_strategy,
            "warm_start_bound_push": 1e-6, "warm_start_mult_bound_push": 1e-6,
        }
    else:
        opts.update({"qpsol": options.qpsol, "print_header": False, "print_iteration": False,
                     "print_status": False, "max_iter": options.max_iter, "tol_du": 1e-6,
                     "tol_pr": 1e-6, "hessian_approximation": options.hessian})
        opts["qpsol_options"] = ({"print_iter": False, "print_header": False,
                                  "print_info": False, "error_on_fail": False}
                                 if options.qpsol == "qrqp" else
                                 {"osqp": {"verbose": False}, "error_on_fail": False})
    return opts


def _rows(model: VehicleModel) -> tuple[list[int], int]:
    return list(model.position_indices), len(model.position_indices)


def _cost_and_constraints(model: VehicleModel, n: int, m_obs: int, weights: TrackingWeights,
                          dt_s: float, w_x: Any, w_u: Any, par: Any) -> tuple[Any, Any]:
    pos, dim = _rows(model)
    nu = model.nu
    u_prev, ref = par[:nu], ca.reshape(par[nu:nu + dim * n], dim, n)
    wind = par[nu + dim * n: nu + dim * n + dim]
    obs = ca.reshape(par[nu + dim * n + dim:], 5, m_obs) if m_obs else None
    width = np.asarray(model.input_upper) - np.asarray(model.input_lower)
    scale = 1.0 / np.where(np.isfinite(width) & (width > 0), width, 1.0)
    nominal = np.asarray(model.nominal_input)
    step = step_function(model)
    cost, g = 0, []
    last = u_prev
    for k in range(n):
        xk, uk, xn = w_x[:, k], w_u[:, k], w_x[:, k + 1]
        g.append(xn - step(xk, uk, wind, dt_s))
        g.append(uk - last)
        err = xn[pos] - ref[:, k]
        weight = weights.terminal if k == n - 1 else weights.position
        cost += weight * ca.sumsqr(err)
        cost += weights.effort * ca.sumsqr((uk - nominal) * scale)
        cost += weights.rate * ca.sumsqr((uk - last) * scale)
        last = uk
        for j in range(m_obs):
            assert obs is not None
            d = xn[pos] - obs[:dim, j]
            sq = d[0] ** 2 + d[1] ** 2 + (obs[4, j] * d[2] ** 2 if dim == 3 else 0)
            g.append(sq - obs[3, j] ** 2)
    return cost, ca.vertcat(*g)


_CACHE: OrderedDict[tuple[Any, ...], NmpcSolver] = OrderedDict()
_CACHE_SIZE = 32  # built solvers kept (least recently used dropped first)
_LADDER = 1.25  # Ipopt wall-time limits are rounded down to 1 ms · 1.25^k


def wall_time_limit(budget_s: float) -> float:
    """Ipopt's ``max_wall_time`` for a budget: the largest ``1 ms · 1.25^k`` not above it (at
    least 1 ms). Rounding down keeps Ipopt inside the budget; the ladder keeps the number of
    distinct solvers small when callers pass a different budget every step."""
    k = math.floor(math.log(max(budget_s, 1e-3) / 1e-3, _LADDER) + 1e-9)
    return float(1e-3 * _LADDER**k)


@functools.cache
def _linear_solver_loads(name: str) -> bool:
    """Whether Ipopt can load linear solver ``name`` (a one-variable NLP, solved once)."""
    x = ca.SX.sym("x")
    try:
        probe = ca.nlpsol("probe", "ipopt", {"x": x, "f": (x - 1) ** 2},
                          {"print_time": False, "error_on_fail": False,
                           "ipopt": {"print_level": 0, "sb": "yes", "linear_solver": name}})
        probe(x0=0.0)
    except RuntimeError:  # not an Ipopt linear solver at all
        return False
    return str(probe.stats().get("return_status")) != "Invalid_Option"


def build(model: VehicleModel, horizon: int, n_obstacles: int, dt_s: float,
          weights: TrackingWeights, options: NmpcOptions, budget_s: float) -> NmpcSolver:
    """The NLP for this problem shape (cached: the same arguments return the same solver).

    ``budget_s`` becomes Ipopt's ``max_wall_time``, rounded down by :func:`wall_time_limit`.
    """
    budget = wall_time_limit(budget_s)
    key = (model, horizon, n_obstacles, round(dt_s, 9), weights, options, budget)
    cached = _CACHE.get(key)
    if cached is not None:
        _CACHE.move_to_end(key)
        return cached
    if options.solver == "ipopt" and not _linear_solver_loads(options.linear_solver):
        raise InvalidInputError("linear_solver", options.linear_solver,
                                "Ipopt cannot load it here (HSL solvers need the HSL library); "
                                "use 'mumps'")
    started = time.perf_counter()
    dim = len(model.position_indices)
    w_x = ca.MX.sym("X", model.nx, horizon + 1)
    w_u = ca.MX.sym("U", model.nu, horizon)
    par = ca.MX.sym("P", model.nu + dim * horizon + dim + 5 * n_obstacles)
    cost, g = _cost_and_constraints(model, horizon, n_obstacles, weights, dt_s, w_x, w_u, par)
    nlp = {"x": ca.vertcat(ca.vec(w_x), ca.vec(w_u)), "f": cost, "g": g, "p": par}
    callback = StopCallback(int(nlp["x"].shape[0]), int(g.shape[0]), int(par.shape[0]))
    # CasADi's JIT writes its C source and objects to the working directory: build in the
    # system temp directory instead (the loaded solver does not need them afterwards)
    with contextlib.chdir(tempfile.gettempdir()) if options.jit else contextlib.nullcontext():
        solver = ca.nlpsol("nmpc", options.solver, nlp, _nlp_options(options, budget, callback))
    built = NmpcSolver(solver, model, horizon, n_obstacles, int(g.shape[0]), options, callback)
    _CACHE[key] = built
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    log.info("built %s NMPC (N=%d, %d obstacles, %s) in %.2f s", model.name, horizon,
             n_obstacles, options.solver, time.perf_counter() - started)
    return built


def _bounds(problem: TrackingProblem, nlp: NmpcSolver) -> dict[str, FloatArray]:
    m, n = problem.model, problem.horizon
    lbx = np.concatenate([np.tile(m.state_lower, n + 1), np.tile(m.input_lower, n)])
    ubx = np.concatenate([np.tile(m.state_upper, n + 1), np.tile(m.input_upper, n)])
    lbx[:m.nx] = ubx[:m.nx] = problem.state
    rate = np.asarray(m.input_rate_max) * problem.dt_s
    per_stage_lo = np.concatenate([np.zeros(m.nx), -rate, np.zeros(nlp.n_obstacles)])
    per_stage_hi = np.concatenate([np.zeros(m.nx), rate, np.full(nlp.n_obstacles, np.inf)])
    return {"lbx": lbx, "ubx": ubx, "lbg": np.tile(per_stage_lo, n),
            "ubg": np.tile(per_stage_hi, n)}


def _parameters(problem: TrackingProblem) -> FloatArray:
    dim = problem.model.n_wind
    obs = problem.obstacles.parameters(dim, problem.safety_margin_m)
    return np.concatenate([problem.u_prev, problem.reference_positions().T.ravel(order="F"),
                           problem.wind, obs.T.ravel(order="F")])


def _violation(sol_x: FloatArray, sol_g: FloatArray, b: dict[str, FloatArray]) -> float:
    over = [np.maximum(b["lbx"] - sol_x, 0.0), np.maximum(sol_x - b["ubx"], 0.0),
            np.maximum(b["lbg"] - sol_g, 0.0), np.maximum(sol_g - b["ubg"], 0.0)]
    return float(max(np.max(v, initial=0.0) for v in over))


def _shift(blocks: FloatArray) -> FloatArray:
    """Rows (one per stage) moved up one stage, the last repeated."""
    return np.concatenate([blocks[1:], blocks[-1:]]).ravel()


def _shifted_multipliers(lam: tuple[FloatArray, FloatArray], nlp: NmpcSolver
                         ) -> tuple[FloatArray, FloatArray] | None:
    """The previous multipliers shifted one stage, or ``None`` if their layout differs."""
    m, n = nlp.model, nlp.horizon
    lam_x, lam_g = lam
    if lam_x.shape[0] != m.nx * (n + 1) + m.nu * n or lam_g.shape[0] != nlp.n_g:
        return None
    lx = lam_x[:m.nx * (n + 1)].reshape(n + 1, m.nx)
    lu = lam_x[m.nx * (n + 1):].reshape(n, m.nu)
    lx_new = _shift(lx)
    lx_new[:m.nx] = 0.0  # x_0 is pinned by its bounds: its multiplier starts afresh
    return (np.concatenate([lx_new, _shift(lu)]), _shift(lam_g.reshape(n, -1)))


def prepare(problem: TrackingProblem, time_limit_s: float,
            options: NmpcOptions | None = None) -> NmpcSolver:
    """Build (or fetch) the solver :func:`solve_nmpc` will use for ``problem`` and this limit,
    so that a caller can keep the one-off build out of its own clock."""
    opts = options or problem.nmpc_options or NmpcOptions()
    return build(problem.model, problem.horizon, problem.obstacles.k, problem.dt_s,
                 problem.weights, opts, min(check_time_limit(time_limit_s), 3600.0))


def solve_nmpc(problem: TrackingProblem, *, time_limit_s: float = 0.05,
               options: NmpcOptions | None = None) -> Result[ControlPlan]:
    """Solve the NMPC problem within ``time_limit_s`` (Ipopt's wall-time limit; a solve that
    still runs over, or ends infeasible, returns ``NO_SOLUTION``). ``options`` default to the
    problem's ``nmpc_options``, else :class:`NmpcOptions` (). Building the solver on the first
    call of a shape is not counted."""
    budget = check_time_limit(time_limit_s)
    opts = options or problem.nmpc_options or NmpcOptions()
    nlp = prepare(problem, budget, opts)
    started = time.perf_counter()
    x_guess, u_guess = initial_guess(problem)
    b = _bounds(problem, nlp)
    args: dict[str, Any] = {"x0": np.concatenate([x_guess.ravel(), u_guess.ravel()]),
                            "p": _parameters(problem), **b}
    if (problem.warm is not None and problem.warm.controller == "nmpc"
            and problem.warm.multipliers is not None):
        lam = _shifted_multipliers(problem.warm.multipliers, nlp)
        if lam is not None:
            args["lam_x0"], args["lam_g0"] = lam
    sol = nlp.solver(**args)
    stats = nlp.solver.stats()
    runtime = time.perf_counter() - started
    native = str(stats.get("return_status", "unknown"))
    w = np.asarray(sol["x"]).ravel()
    violation = _violation(w, np.asarray(sol["g"]).ravel(), b)
    info = {"iterations": float(stats.get("iter_count", -1)), "violation": violation,
            "solver_s": runtime}
    ok = bool(stats.get("success", False)) or native in _OK
    if native == "User_Requested_Stop" or (stop_requested() and not ok):
        return _interrupted(problem, w, sol, violation, runtime, opts, info)
    if not ok or violation > _FEAS_TOL or runtime > budget:
        reason = (f"over budget ({runtime * 1e3:.1f} ms > {budget * 1e3:.1f} ms)"
                  if runtime > budget else f"{native}, violation {violation:.1e}")
        bad = native in ("Invalid_Number_Detected", "Invalid_Option", "Internal_Error")
        return Result(Status.ERROR if bad else Status.NO_SOLUTION,
                      None, None, runtime, "nmpc", None, Sense.MINIMIZE,
                      f"nmpc ({opts.solver}): {reason}", info)
    plan = _plan(problem, w, sol)
    return Result(Status.FEASIBLE, float(sol["f"]), None, runtime, "nmpc", plan, Sense.MINIMIZE,
                  f"nmpc ({opts.solver}): {_OK.get(native, native)}", info)


def _plan(problem: TrackingProblem, w: FloatArray, sol: dict[str, Any]) -> ControlPlan:
    """The plan of the NLP variables ``w`` (inputs moved into their boxes: Ipopt relaxes them
    by about 1e-8), with the multipliers for a warm start."""
    m, n = problem.model, problem.horizon
    states = w[:m.nx * (n + 1)].reshape(n + 1, m.nx)
    inputs = project_inputs(problem, w[m.nx * (n + 1):].reshape(n, m.nu))
    lam = (np.asarray(sol["lam_x"]).ravel(), np.asarray(sol["lam_g"]).ravel())
    return ControlPlan(inputs=inputs, states=states, dt_s=problem.dt_s, controller="nmpc",
                       multipliers=lam)


def _interrupted(problem: TrackingProblem, w: FloatArray, sol: dict[str, Any], violation: float,
                 runtime: float, opts: NmpcOptions, info: dict[str, float]
                 ) -> Result[ControlPlan]:
    """The answer of a solve a stop request ended: ``INTERRUPTED``, with the last iterate as
    its plan when it is feasible and finite (else without a plan)."""
    usable = violation <= _FEAS_TOL and bool(np.all(np.isfinite(w)))
    plan = _plan(problem, w, sol) if usable else None
    note = "feasible iterate kept" if usable else f"no feasible iterate (violation {violation:.1e})"
    return Result(Status.INTERRUPTED, float(sol["f"]) if usable else None, None, runtime, "nmpc",
                  plan, Sense.MINIMIZE, f"nmpc ({opts.solver}): stopped on request, {note}",
                  info)
