"""do-mpc on searchtrack's tracking problem, for the solve benchmark's peer row.

The same NLP as :mod:`searchtrack.plan.trajectory.nmpc` written in do-mpc 5: a discrete model
whose step is the vehicle's own RK4 step (multiple shooting), the stage cost
``w_k ‖p_k − r_k‖² + effort ‖(u_k − u_nom)/range‖²`` (``w_N`` = terminal), do-mpc's ``rterm``
for ``rate ‖(u_k − u_{k−1})/range‖²``, the input box, and ``‖p_k − c_j‖² ≥ (r_j + margin)²`` per
stage and obstacle as hard nonlinear constraints; Ipopt with MUMPS at the tolerance and
``mu_init`` of searchtrack's default. do-mpc has no input-rate limits (searchtrack's NMPC keeps
``|u_k − u_{k−1}| ≤ u̇_max Δt``): do-mpc's problem is the easier one. do-mpc warm-starts from its
own previous solution. The time is the wall time of ``make_step`` (what a do-mpc user waits).

Needs ``pip install do-mpc`` (the bench extra).
"""

from __future__ import annotations

import time
from types import SimpleNamespace
from typing import Any

import casadi as ca
import numpy as np

from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.trajectory import ControlPlan, Obstacles, Reference, TrackingProblem
from searchtrack.plan.trajectory.symbolic import step_function


def available() -> str | None:
    """``None`` when do-mpc imports, else why not."""
    try:
        import do_mpc  # noqa: F401
    except ImportError as err:
        return f"do-mpc not installed ({err.name}): pip install do-mpc"
    return None


class DoMpcTracker:
    """A do-mpc MPC for one model, course and horizon, called like a searchtrack solver:
    ``tracker(problem)`` answers the problem's state (its time must advance by ``dt_s`` per
    call, as do-mpc's clock does)."""

    def __init__(self, model: VehicleModel, ref: Reference, obs: Obstacles, *, horizon: int = 20,
                 dt_s: float = 0.1, margin_m: float = 1.0,
                 weights: Any = None, wind: np.ndarray | None = None) -> None:
        import do_mpc

        from searchtrack.plan.trajectory import TrackingWeights

        w = weights or TrackingWeights()
        pos = list(model.position_indices)
        dim = len(pos)
        wind = np.zeros(model.n_wind) if wind is None else wind
        dm = do_mpc.model.Model("discrete", "SX")
        x = dm.set_variable("_x", "x", shape=(model.nx, 1))
        u = dm.set_variable("_u", "u", shape=(model.nu, 1))
        r = dm.set_variable("_tvp", "ref", shape=(dim, 1))
        dm.set_rhs("x", step_function(model)(x, u, wind, dt_s))
        dm.setup()
        mpc = do_mpc.controller.MPC(dm)
        mpc.settings.n_horizon = horizon
        mpc.settings.t_step = dt_s
        mpc.settings.store_full_solution = False
        mpc.settings.nlpsol_opts = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": 0,
                                    "ipopt.tol": 1e-4, "ipopt.mu_init": 1e-2}
        width = np.asarray(model.input_upper) - np.asarray(model.input_lower)
        scale = 1.0 / np.where(np.isfinite(width) & (width > 0), width, 1.0)
        err = x[pos] - r
        lterm = w.position * ca.sumsqr(err) + w.effort * ca.sumsqr(
            (u - np.asarray(model.nominal_input)) * scale)
        mpc.set_objective(lterm=lterm, mterm=w.terminal * ca.sumsqr(err))
        mpc.set_rterm(u=w.rate * scale ** 2)
        mpc.bounds["lower", "_u", "u"] = np.asarray(model.input_lower)
        mpc.bounds["upper", "_u", "u"] = np.asarray(model.input_upper)
        for j, (centre, radius) in enumerate(zip(obs.centers_m, obs.radii_m, strict=True)):
            d = x[pos][:2] - centre[:2]
            mpc.set_nl_cons(f"obstacle_{j}", (radius + margin_m) ** 2 - ca.sumsqr(d), ub=0.0)
        template = mpc.get_tvp_template()

        def tvp(t_now: float) -> Any:
            times = t_now + dt_s * np.arange(horizon + 1)
            for k, point in enumerate(ref.positions(times)):
                template["_tvp", k, "ref"] = point
            return template

        mpc.set_tvp_fun(tvp)
        mpc.setup()
        self._mpc, self._started, self._horizon = mpc, False, horizon

    def __call__(self, problem: TrackingProblem) -> Any:
        x0 = np.asarray(problem.state, dtype=float).reshape(-1, 1)
        if not self._started:
            self._mpc.x0 = x0
            self._mpc.set_initial_guess()
            self._started = True
        t0 = time.perf_counter()
        u0 = self._mpc.make_step(x0)
        runtime = time.perf_counter() - t0
        stats = self._mpc.solver_stats
        ok = bool(stats.get("success", False))
        plan = None
        if ok:
            opt, n = self._mpc.opt_x_num, self._horizon
            inputs = np.array([np.asarray(opt["_u", k, 0]).ravel() for k in range(n)])
            states = np.array([np.asarray(opt["_x", k, 0, -1]).ravel() for k in range(n + 1)])
            inputs[0] = np.asarray(u0, dtype=float).ravel()
            plan = ControlPlan(inputs, states, problem.dt_s, "do-mpc")
        return SimpleNamespace(runtime_s=runtime, plan=plan,
                               stats={"iterations": float(stats.get("iter_count", 0))},
                               message=f"do-mpc: {stats.get('return_status')}")
