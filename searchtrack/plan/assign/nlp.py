"""Multi-UAV assignment as a nonlinear program: move the waypoints continuously (CasADi + Ipopt).

Decision variables: the ``T`` waypoint positions ``q_{r,t} ∈ R³`` of every UAV. Maximise the
smooth END ``Σ_j w_j (1 − Π_{r,t} (1 − p_d(x_j | q_{r,t})))`` (003 eq. 13) with a differentiable
sensor (e.g. :class:`~searchtrack.models.footprint.GaussianFieldOfView`) subject to::

    ‖q_{r,t} − q_{r,t−1}‖² ≤ s²        (speed: max step length; q_{r,0} = origin when given)
    z_min ≤ q_{r,t,z} ≤ z_max          (altitude band)
    ‖q_{r,t} − q_{u,t}‖² ≥ d²          (pairwise separation at every step, r < u)

started from the greedy answer. Non-convex: Ipopt returns a local optimum at best, so the status
is FEASIBLE (never OPTIMAL); a solve that fails or ends infeasible returns the greedy plan.
Orientation entries of the poses (yaw, pitch) are kept from the greedy plan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray
from searchtrack.plan.assign.greedy import solve_lazy_greedy
from searchtrack.plan.assign.objectives import coverage_only, expected_detections_of_poses
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

_FEAS_TOL = 1e-6


@dataclass(frozen=True)
class NLPLimits:
    """Limits of the continuous program; ``None`` takes the value from the candidate actions
    (largest step between consecutive candidate poses, their altitude range) and the separation
    from ``problem.min_separation_m``."""

    max_step_m: float | None = None
    z_min_m: float | None = None
    z_max_m: float | None = None
    separation_m: float | None = None

    def __post_init__(self) -> None:
        for name in ("max_step_m", "z_min_m", "z_max_m", "separation_m"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise InvalidInputError(name, v, "must be finite or None")
        if self.max_step_m is not None and self.max_step_m <= 0.0:
            raise InvalidInputError("max_step_m", self.max_step_m, "must be > 0")
        if self.separation_m is not None and self.separation_m < 0.0:
            raise InvalidInputError("separation_m", self.separation_m, "must be >= 0")


def nlp_supports(problem: AssignmentProblem) -> str | None:
    """``None`` if the NLP can take ``problem`` (END with a differentiable sensor)."""
    reason = coverage_only(problem)
    if reason is not None:
        return reason
    if not callable(getattr(problem.sensor, "casadi_detection", None)):
        return "needs a sensor with casadi_detection (e.g. GaussianFieldOfView)"
    return None


def _resolve(problem: AssignmentProblem, limits: NLPLimits) -> tuple[float, float, float, float]:
    xyz = [a[:, :, :3] for a in problem.actions]
    step = limits.max_step_m
    if step is None:
        steps = [np.linalg.norm(np.diff(a, axis=1), axis=2).ravel() for a in xyz]
        if problem.origins is not None:
            steps += [np.linalg.norm(a[:, 0] - problem.origins[r, :3], axis=1)
                      for r, a in enumerate(xyz)]
        flat = np.concatenate(steps) if steps else np.zeros(0)
        step = float(flat.max()) if flat.size and flat.max() > 0 else math.inf
    zs = np.concatenate([a[:, :, 2].ravel() for a in xyz])
    z_lo = float(zs.min()) if limits.z_min_m is None else limits.z_min_m
    z_hi = float(zs.max()) if limits.z_max_m is None else limits.z_max_m
    if z_hi < z_lo:
        raise InvalidInputError("z_max_m", z_hi, f"must be >= z_min_m={z_lo}")
    sep = problem.min_separation_m if limits.separation_m is None else limits.separation_m
    return step, z_lo, z_hi, sep


def _violation(q: FloatArray, origins: FloatArray | None, step: float, z_lo: float,
               z_hi: float, sep: float) -> float:
    """Largest constraint violation of waypoints ``q`` ``(R, T, 3)`` (metres)."""
    worst = max(0.0, float(np.max(z_lo - q[:, :, 2])), float(np.max(q[:, :, 2] - z_hi)))
    chain = q if origins is None else np.concatenate([origins[:, None, :3], q], axis=1)
    if math.isfinite(step) and chain.shape[1] > 1:
        worst = max(worst, float(np.max(np.linalg.norm(np.diff(chain, axis=1), axis=2))) - step)
    r = q.shape[0]
    for a in range(r):
        for b in range(a + 1, r):
            gap = float(np.min(np.linalg.norm(q[a] - q[b], axis=1)))
            worst = max(worst, sep - gap)
    return worst


def solve_nlp(problem: AssignmentProblem, limits: NLPLimits | None = None, *,
              time_limit_s: float = 5.0, seed: int = 0) -> Result[Assignment]:
    """Improve the greedy plan by moving every waypoint continuously (module docstring).

    The greedy start takes at most a tenth of the limit; Ipopt gets the rest as
    ``max_cpu_time``. ``seed`` is unused. Returns FEASIBLE with the true END of the poses.
    """
    import casadi as ca

    reason = nlp_supports(problem)
    if reason is not None:
        raise InvalidInputError("problem", problem.name, reason)
    limits = NLPLimits() if limits is None else limits
    deadline = Deadline(time_limit_s)
    start = solve_lazy_greedy(problem, time_limit_s=max(1e-3, 0.1 * time_limit_s), seed=seed)
    if start.plan is None or start.objective is None:
        return Result(start.status, None, None, deadline.elapsed(), "nlp", None,
                      message=f"nlp: no greedy start ({start.message})")
    step, z_lo, z_hi, sep = _resolve(problem, limits)
    r_count, t_count = problem.robots, problem.horizon
    q0 = start.plan.poses[:, :, :3]
    origins = None if problem.origins is None else problem.origins[:, :3]
    sensor: Any = problem.sensor
    one = ca.SX.sym("q", 3)
    miss_of = ca.Function("miss", [one], [1.0 - sensor.casadi_detection(one, problem.positions)])
    k_count = r_count * t_count
    z = ca.MX.sym("q", k_count * 3)
    qs = [[z[3 * (r * t_count + t):3 * (r * t_count + t) + 3] for t in range(t_count)]
          for r in range(r_count)]
    misses = miss_of.map(k_count)(ca.reshape(z, 3, k_count))  # (N, R·T)
    miss = misses[:, 0]
    for k in range(1, k_count):
        miss = miss * misses[:, k]
    objective = ca.dot(ca.DM(problem.weights), 1.0 - miss)
    g: list[Any] = []
    ubg: list[float] = []
    lbg: list[float] = []
    if math.isfinite(step):
        for r in range(r_count):
            for t in range(t_count):
                if t == 0 and origins is None:
                    continue
                prev = ca.DM(origins[r]) if t == 0 and origins is not None else qs[r][t - 1]
                g.append(ca.sumsqr(qs[r][t] - prev))
                lbg.append(0.0)
                ubg.append(step**2)
    if sep > 0.0:
        for a in range(r_count):
            for b in range(a + 1, r_count):
                for t in range(t_count):
                    g.append(ca.sumsqr(qs[a][t] - qs[b][t]))
                    lbg.append(sep**2)
                    ubg.append(math.inf)
    lbx = np.tile([-math.inf, -math.inf, z_lo], r_count * t_count)
    ubx = np.tile([math.inf, math.inf, z_hi], r_count * t_count)
    nlp = {"x": z, "f": -objective, "g": ca.vertcat(*g) if g else ca.MX(0, 1)}
    remaining = max(1e-2, deadline.remaining() - 0.02)
    opts: dict[str, Any] = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
            "ipopt.max_cpu_time": remaining, "ipopt.max_wall_time": remaining,
            "ipopt.max_iter": 500, "ipopt.hessian_approximation": "limited-memory"}
    solver = ca.nlpsol("assign_nlp", "ipopt", nlp, opts)
    sol = solver(x0=q0.reshape(-1), lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    native = str(solver.stats().get("return_status", "unknown"))
    q = np.asarray(sol["x"]).reshape(r_count, t_count, 3)
    poses = start.plan.poses.copy()
    poses[:, :, :3] = q
    value = expected_detections_of_poses(problem, poses)
    viol = _violation(q, origins, step, z_lo, z_hi, sep)
    stats = {"greedy_objective": start.objective, "violation_m": viol}
    if viol > _FEAS_TOL * max(1.0, step if math.isfinite(step) else 1.0) or \
            value < start.objective:
        return Result(Status.FEASIBLE, start.objective, None, deadline.elapsed(), "nlp",
                      start.plan, message=f"nlp: Ipopt {native} did not improve feasibly "
                      f"(violation {viol:.3g} m); greedy plan kept", stats=stats)
    return Result(Status.FEASIBLE, value, None, deadline.elapsed(), "nlp",
                  Assignment(start.plan.actions, poses),
                  message=f"nlp: Ipopt {native}, END {start.objective:.6g} -> {value:.6g}",
                  stats=stats)
