"""Linear time-varying MPC as a sparse QP solved by OSQP (the fast mode for small problems).

The RK4 step is linearised about a nominal trajectory ``(x̄, ū)`` (the shifted previous plan, or
the nominal input rolled out from the state): ``x_{k+1} = A_k x_k + B_k u_k + c_k``. Stacking
``z = (x_0..x_N, u_0..u_{N−1})`` gives ``min ½ zᵀPz + qᵀz`` s.t. ``l ≤ Az ≤ u`` with rows
``x_0 = state``, the dynamics, the state and input boxes, the input-rate limits and, per stage and
obstacle, the half-space ``n_jkᵀ p_k + s_jk ≥ n_jkᵀ c_j + r_j + margin`` where ``n_jk`` points
from the obstacle centre to ``p̄_k`` (the linearised, conservative obstacle constraint). The slack
``s_jk ≥ 0`` carries an exact L1 penalty (:data:`SLACK_WEIGHT`), so a poor linearisation point
(normals pointing backwards) cannot make the QP infeasible; a plan whose final slacks exceed
the safety margin predicts a collision and is not returned. ``P`` is constant;
the OSQP object is set up once per problem shape and only ``q``, ``l``, ``u`` and the values of
``A`` (fixed sparsity) are updated between solves. A cold start re-linearises about the QP
solution a few times (sequential QP); a warm start takes one QP (the real-time iteration), and
OSQP starts it from the warm plan's own QP solution and step size ρ (kept as the plan's
``multipliers``), the primal moved one stage on (:func:`shifted_primal`), so that an answer
depends on the problem alone, not on earlier calls; a warm plan that would enter an obstacle
gets further rounds.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import osqp
import scipy.sparse as sp

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.trajectory.problem import (
    ControlPlan,
    TrackingProblem,
    TrackingWeights,
    initial_guess,
    project_inputs,
)
from searchtrack.plan.trajectory.symbolic import step_jacobians

log = logging.getLogger("searchtrack.plan.trajectory.ltv_mpc")

#: Linearise–solve rounds: on a cold start; at most with a warm plan.
COLD_ROUNDS, MAX_WARM_ROUNDS = 3, 3
_OSQP_RHO = 0.1   # OSQP's default initial ρ, restored before every solve
#: OSQP's settings for every LTV-MPC QP.
#: ρ is adapted every 75 iterations, not at OSQP's default interval, which it derives from the
#: measured set-up time: the iterates would then depend on the machine's load.
OSQP_SETTINGS: dict[str, Any] = {"verbose": False, "eps_abs": 1e-4, "eps_rel": 1e-4,
                                 "max_iter": 4000, "polishing": False, "warm_starting": True,
                                 "adaptive_rho": True, "adaptive_rho_interval": 75}
SLACK_WEIGHT = 1e4  # exact-penalty weight on the obstacle slacks (cost units per metre)


@dataclass
class _Layout:
    """Index bookkeeping of one QP shape (constraint COO pattern and its CSC permutation)."""

    model: VehicleModel
    horizon: int
    n_obstacles: int
    rows: IntArray
    cols: IntArray
    perm: IntArray
    n_rows: int
    bounded: IntArray  # states with a finite bound, boxed at stages 1..N


def _layout(model: VehicleModel, n: int, m_obs: int) -> _Layout:
    nx, nu, pos = model.nx, model.nu, np.asarray(model.position_indices)

    def xi(k: int, i: int) -> int:
        return int(k * nx + i)

    def ui(k: int, j: int) -> int:
        return int(nx * (n + 1) + k * nu + j)

    rows: list[IntArray] = []
    cols: list[IntArray] = []
    r = 0

    def add(rr: Any, cc: Any) -> None:
        rows.append(np.asarray(rr, dtype=np.int64).ravel())
        cols.append(np.asarray(cc, dtype=np.int64).ravel())

    add(np.arange(nx), [xi(0, i) for i in range(nx)])
    r = nx
    for k in range(n):  # x_{k+1} − A_k x_k − B_k u_k = c_k
        block = r + np.arange(nx)
        add(block, [xi(k + 1, i) for i in range(nx)])
        add(np.repeat(block, nx), np.tile([xi(k, a) for a in range(nx)], nx))
        add(np.repeat(block, nu), np.tile([ui(k, b) for b in range(nu)], nx))
        r += nx
    lo, hi = np.asarray(model.state_lower), np.asarray(model.state_upper)
    bounded = np.flatnonzero(np.isfinite(lo) | np.isfinite(hi))
    for k in range(1, n + 1):
        add(r + np.arange(bounded.size), [xi(k, int(i)) for i in bounded])
        r += bounded.size
    add(r + np.arange(nu * n), [ui(k, j) for k in range(n) for j in range(nu)])
    r += nu * n
    add(r + np.arange(nu), [ui(0, j) for j in range(nu)])  # rate at k = 0 (u_prev in bounds)
    r += nu
    for k in range(1, n):
        add(r + np.arange(nu), [ui(k, j) for j in range(nu)])
        add(r + np.arange(nu), [ui(k - 1, j) for j in range(nu)])
        r += nu
    slack0 = nx * (n + 1) + nu * n
    for k in range(1, n + 1):
        for j in range(m_obs):
            add(np.full(pos.size + 1, r), [*(xi(k, int(i)) for i in pos),
                                           slack0 + (k - 1) * m_obs + j])
            r += 1
    add(r + np.arange(n * m_obs), slack0 + np.arange(n * m_obs))  # slacks ≥ 0
    r += n * m_obs
    all_rows, all_cols = np.concatenate(rows), np.concatenate(cols)
    perm = np.lexsort((all_rows, all_cols)).astype(np.int64)
    return _Layout(model, n, m_obs, all_rows, all_cols, perm, r, bounded)


def _values(lay: _Layout, a: FloatArray, b: FloatArray, normals: FloatArray) -> FloatArray:
    """Constraint-matrix values in COO order: ``a`` (N, nx, nx), ``b`` (N, nx, nu),
    ``normals`` (N, M, dim)."""
    m, n = lay.model, lay.horizon
    nx, nu = m.nx, m.nu
    dyn = np.concatenate([np.ones((n, nx)), -a.reshape(n, nx * nx), -b.reshape(n, nx * nu)],
                         axis=1).ravel()
    rate = np.tile(np.concatenate([np.ones(nu), -np.ones(nu)]), n - 1)
    obstacle = np.concatenate([normals, np.ones((*normals.shape[:2], 1))], axis=2).ravel()
    return np.concatenate([np.ones(nx), dyn, np.ones(lay.bounded.size * n), np.ones(nu * n),
                           np.ones(nu), rate, obstacle, np.ones(n * lay.n_obstacles)])


def _stage_weights(problem: TrackingProblem) -> FloatArray:
    w = problem.weights
    return np.where(np.arange(1, problem.horizon + 1) == problem.horizon, w.terminal, w.position)


def _linear_cost(problem: TrackingProblem) -> FloatArray:
    """``q`` of the tracking cost: reference, nominal-input and previous-input terms."""
    m, n, w = problem.model, problem.horizon, problem.weights
    nx = m.nx
    qx = np.zeros((n + 1, nx))
    qx[1:, list(m.position_indices)] = -2.0 * _stage_weights(problem)[:, None] * (
        problem.reference_positions())
    s2 = 1.0 / problem.input_range() ** 2
    qu = np.tile(-2.0 * w.effort * s2 * np.asarray(m.nominal_input), (n, 1))
    qu[0] -= 2.0 * w.rate * s2 * problem.u_prev
    slack = np.full(n * problem.obstacles.k, SLACK_WEIGHT)
    return np.concatenate([qx.ravel(), qu.ravel(), slack])


def _hessian(problem: TrackingProblem) -> sp.csc_matrix:
    """Upper triangle of ``P`` (constant for a model, horizon and weights)."""
    m, n, w = problem.model, problem.horizon, problem.weights
    nx, nu = m.nx, m.nu
    dx = np.zeros((n + 1, nx))
    dx[1:, list(m.position_indices)] = 2.0 * _stage_weights(problem)[:, None]
    s2 = 1.0 / problem.input_range() ** 2
    count = np.where(np.arange(n) < n - 1, 2.0, 1.0)[:, None]
    du = 2.0 * w.effort * s2 + 2.0 * w.rate * s2 * count
    slack = np.full(n * problem.obstacles.k, 1.0)
    diag = np.concatenate([dx.ravel(), du.ravel(), slack]) + 1e-8  # strictly convex
    nz = diag.size
    upper = nx * (n + 1) + np.arange(nu * (n - 1))  # u_{k−1} rows, k = 1..N−1
    off = np.tile(-2.0 * w.rate * s2, n - 1)
    p = sp.coo_matrix((np.concatenate([diag, off]),
                       (np.concatenate([np.arange(nz), upper]),
                        np.concatenate([np.arange(nz), upper + nu]))), shape=(nz, nz))
    return sp.csc_matrix(p)


@dataclass
class _Workspace:
    layout: _Layout
    solver: Any
    weights: TrackingWeights
    dt_s: float


def _shift_stages(v: FloatArray, start: int, stages: int, width: int) -> None:
    """Shift ``stages`` blocks of ``width`` entries of ``v`` from ``start`` one stage earlier,
    in place; the last block is kept (repeated)."""
    if stages > 1 and width:
        end = start + stages * width
        v[start:end - width] = v[start + width:end].copy()


def _current_rho(solver: Any) -> float | None:
    """The ρ OSQP's workspace holds now (adapted during its last solve), if OSQP tells."""
    try:
        return float(solver._solver.get_settings().rho)
    except AttributeError:   # another OSQP interface: every solve then sets ρ afresh
        return None


def _warm_start(problem: TrackingProblem, lay: _Layout
                ) -> tuple[FloatArray, FloatArray, float]:
    """OSQP's start ``(x, y, ρ)``: the warm plan's QP solution and final ρ (an ``ltv_mpc`` plan
    keeps its primal and its dual with ρ appended as its ``multipliers``), the primal shifted
    one stage; else zeros and OSQP's initial ρ."""
    m, n = lay.model, lay.horizon
    n_var = m.nx * (n + 1) + m.nu * n + n * lay.n_obstacles
    warm = problem.warm
    if (warm is not None and warm.controller == "ltv_mpc" and warm.multipliers is not None
            and warm.multipliers[0].shape == (n_var,)
            and warm.multipliers[1].shape == (lay.n_rows + 1,)):
        dual = warm.multipliers[1]
        return shifted_primal(lay, warm.multipliers[0]), dual[:-1], float(dual[-1])
    return np.zeros(n_var), np.zeros(lay.n_rows), float(OSQP_SETTINGS.get("rho", _OSQP_RHO))


def shifted_primal(lay: _Layout, x: FloatArray) -> FloatArray:
    """The previous QP's primal solution ``x`` moved one stage on (the receding horizon's
    shift: states, inputs and obstacle slacks), the last stage repeated: OSQP's primal warm
    start for the next instant. (The dual is not shifted: shifted duals start some QPs of the
    7-state UAV so far off that ADMM does not converge.)"""
    m, n, k_obs = lay.model, lay.horizon, lay.n_obstacles
    x = x.copy()
    _shift_stages(x, 0, n + 1, m.nx)
    _shift_stages(x, m.nx * (n + 1), n, m.nu)
    _shift_stages(x, m.nx * (n + 1) + m.nu * n, n, k_obs)
    return x


_CACHE: dict[tuple[Any, ...], _Workspace] = {}


@lru_cache(maxsize=32)
def _mapped_jacobians(model: VehicleModel, horizon: int) -> Any:
    return step_jacobians(model).map(horizon)


def _linearise(problem: TrackingProblem, xbar: FloatArray, ubar: FloatArray
               ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(A (N, nx, nx), B (N, nx, nu), c (N, nx))`` of the RK4 step about ``(x̄, ū)``."""
    m, n = problem.model, problem.horizon
    jac = _mapped_jacobians(m, n)
    x_next, a, b = jac(xbar[:n].T, ubar.T, np.tile(problem.wind[:, None], (1, n)), problem.dt_s)
    a = np.asarray(a).reshape(m.nx, n, m.nx).transpose(1, 0, 2)
    b = np.asarray(b).reshape(m.nx, n, m.nu).transpose(1, 0, 2)
    c = np.asarray(x_next).T - np.einsum("kij,kj->ki", a, xbar[:n]) - np.einsum(
        "kij,kj->ki", b, ubar)
    return a, b, c


def _obstacle_rows(problem: TrackingProblem, xbar: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Normals ``(N, M, dim)`` and right-hand sides ``(N, M)`` of the half-spaces."""
    m, dim = problem.model, problem.model.n_wind
    par = problem.obstacles.parameters(dim, problem.safety_margin_m)
    pbar = xbar[1:, list(m.position_indices)]
    d = pbar[:, None, :] - par[None, :, :dim]
    if dim == 3:
        d[:, :, 2] *= par[None, :, 4]
    norm = np.linalg.norm(d, axis=2, keepdims=True)
    normals = np.where(norm > 1e-9, d / np.maximum(norm, 1e-9), np.eye(dim)[0])
    rhs = np.einsum("kjd,jd->kj", normals, par[:, :dim]) + par[None, :, 3]
    return normals, rhs


def _bounds(problem: TrackingProblem, lay: _Layout, c: FloatArray, rhs: FloatArray
            ) -> tuple[FloatArray, FloatArray]:
    m, n = problem.model, problem.horizon
    rate = np.asarray(m.input_rate_max) * problem.dt_s
    lo_x, hi_x = np.asarray(m.state_lower)[lay.bounded], np.asarray(m.state_upper)[lay.bounded]
    lower = [problem.state, c.ravel(), np.tile(lo_x, n), np.tile(m.input_lower, n),
             problem.u_prev - rate, np.tile(-rate, n - 1), rhs.ravel(), np.zeros(rhs.size)]
    upper = [problem.state, c.ravel(), np.tile(hi_x, n), np.tile(m.input_upper, n),
             problem.u_prev + rate, np.tile(rate, n - 1), np.full(2 * rhs.size, np.inf)]
    return np.concatenate(lower), np.concatenate(upper)


def _workspace(problem: TrackingProblem, q: FloatArray, vals: FloatArray,
               lower: FloatArray, upper: FloatArray) -> _Workspace:
    m, n = problem.model, problem.horizon
    key = (m, n, problem.obstacles.k, round(problem.dt_s, 9), problem.weights)
    ws = _CACHE.get(key)
    if ws is not None:
        return ws
    lay = _layout(m, n, problem.obstacles.k)
    p = _hessian(problem)
    a = _csc(lay, vals, nz=p.shape[0])
    solver = osqp.OSQP()
    solver.setup(P=sp.triu(p, format="csc"), q=q, A=a, l=lower, u=upper, **OSQP_SETTINGS)
    ws = _Workspace(lay, solver, problem.weights, problem.dt_s)
    _CACHE[key] = ws
    return ws


def _csc(lay: _Layout, vals: FloatArray, nz: int) -> sp.csc_matrix:
    cols = lay.cols[lay.perm]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=nz))])
    return sp.csc_matrix((vals[lay.perm], lay.rows[lay.perm], indptr), shape=(lay.n_rows, nz))


_STATUS = {"solved": Status.OPTIMAL, "solved inaccurate": Status.FEASIBLE,
           "primal infeasible": Status.INFEASIBLE,
           "primal infeasible inaccurate": Status.NO_SOLUTION,
           "maximum iterations reached": Status.NO_SOLUTION,
           "run time limit reached": Status.NO_SOLUTION, "time limit reached": Status.NO_SOLUTION}


def solve_ltv_mpc(problem: TrackingProblem, *, time_limit_s: float = 0.05,
                  iterations: int | None = None) -> Result[ControlPlan]:
    """Solve the LTV-MPC QP within ``time_limit_s``; ``iterations`` linearise–solve rounds.

    By default a cold start takes :data:`COLD_ROUNDS` rounds; with a warm plan (the real-time
    iteration) one round, and further ones (up to :data:`MAX_WARM_ROUNDS`, re-linearised about
    the last plan) only while the plan would be refused for entering an obstacle. The first call
    of a shape also sets up OSQP."""
    deadline = Deadline(check_time_limit(time_limit_s))
    adaptive = iterations is None and problem.warm is not None
    rounds = iterations if iterations is not None else (
        MAX_WARM_ROUNDS if adaptive else COLD_ROUNDS)
    m, n = problem.model, problem.horizon
    xbar, ubar = initial_guess(problem)
    q = _linear_cost(problem)
    native, objective, z, slack, qp_iterations = "unsolved", 0.0, None, 0.0, 0
    solved_native, done = native, 0
    nxs, nus = m.nx * (n + 1), m.nu * n
    a, b, c = _linearise(problem, xbar, ubar)
    lay = _layout_of(problem)
    for _ in range(max(1, rounds)):
        normals, rhs = _obstacle_rows(problem, xbar)
        lower, upper = _bounds(problem, lay, c, rhs)
        vals = _values(lay, a, b, normals)
        ws = _workspace(problem, q, vals, lower, upper)
        ws.solver.update(q=q, l=lower, u=upper, Ax=vals[ws.layout.perm])
        ws.solver.update_settings(time_limit=max(1e-4, deadline.remaining()))
        if done == 0:   # from the problem alone: the answer does not depend on earlier calls
            x0, y0, rho = _warm_start(problem, ws.layout)
            if rho != _current_rho(ws.solver):   # a new ρ costs a factorisation
                ws.solver.update_settings(rho=rho)
            ws.solver.warm_start(x=x0, y=y0)
        res = ws.solver.solve(raise_error=False)
        qp_iterations += int(res.info.iter)
        native = str(res.info.status).lower()
        if _STATUS.get(native, Status.ERROR) not in (Status.OPTIMAL, Status.FEASIBLE):
            break  # a later round that fails keeps the earlier round's plan
        solved_native, done = native, done + 1
        z, res_y = np.asarray(res.x, dtype=float), res.y
        rho_out = _current_rho(ws.solver) or float(OSQP_SETTINGS.get("rho", _OSQP_RHO))
        objective = float(res.info.obj_val)
        xbar = z[:m.nx * (n + 1)].reshape(n + 1, m.nx).copy()
        xbar[0] = problem.state  # pinned; OSQP meets it to its tolerance only
        ubar = project_inputs(problem, z[nxs:nxs + nus].reshape(n, m.nu))
        slack = float(np.max(z[nxs + nus:], initial=0.0))
        if done >= rounds or deadline.expired() or (
                adaptive and slack <= problem.safety_margin_m):
            break
        a, b, c = _linearise(problem, xbar, ubar)
    runtime = deadline.elapsed()
    if z is None:
        status = _STATUS.get(native, Status.ERROR)
        return Result(status if status is not Status.OPTIMAL else Status.NO_SOLUTION, None, None,
                      runtime, "ltv_mpc", None, Sense.MINIMIZE, f"ltv_mpc (osqp): {native}")
    # the QP's optimum is the linearised problem's, not the nonlinear tracking problem's
    status = Status.FEASIBLE
    info = {"qp_rounds": float(done), "qp_iterations": float(qp_iterations),
            "max_slack_m": slack}
    if slack > problem.safety_margin_m:
        return Result(Status.NO_SOLUTION, None, None, runtime, "ltv_mpc", None, Sense.MINIMIZE,
                      f"ltv_mpc (osqp): {native} but the plan enters an obstacle by "
                      f"{slack - problem.safety_margin_m:.2f} m", info)
    plan = ControlPlan(inputs=ubar, states=xbar, dt_s=problem.dt_s, controller="ltv_mpc",
                       multipliers=(z, np.append(np.asarray(res_y, dtype=float), rho_out)))
    note = f"; obstacle margin relaxed by {slack:.3f} m" if slack > 1e-3 else ""
    later = f"; round {done + 1}: {native}" if native != solved_native else ""
    return Result(status, objective, None, runtime, "ltv_mpc", plan, Sense.MINIMIZE,
                  f"ltv_mpc (osqp): {solved_native} after {done} round(s){later}{note}", info)


def _layout_of(problem: TrackingProblem) -> _Layout:
    key = (problem.model, problem.horizon, problem.obstacles.k, round(problem.dt_s, 9),
           problem.weights)
    ws = _CACHE.get(key)
    return ws.layout if ws is not None else _layout(problem.model, problem.horizon,
                                                    problem.obstacles.k)
