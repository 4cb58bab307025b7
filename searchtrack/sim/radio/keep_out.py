"""The void-region keep-out of paper 002 enforced in the flown trajectory.

Paper 002 keeps the UAV safe through the planner: a primitive is feasible when the void
probability of the ground disc of radius ``r_min`` around the UAV stays above ``P_vmin`` (eq. 44
and the constraint after eq. 45). Here a trajectory controller (:mod:`searchtrack.plan.trajectory`)
also flies each step of the chosen primitive out of a disc of radius ``r_min`` (a vertical
cylinder: ground distance) around every object estimate.

* Vehicle: the unicycle with ``v_min = v_max = v`` (the input box fixes the speed) and a turn
  slew of ``2 ω_max`` per stage (turns switch at once, as in :mod:`searchtrack.models.radio.uav`).
  It flies arcs of length ``v t``; the primitives step along chords of length ``v T0``: under
  1 m apart per step at the maximum turn rate, equal on straight legs.
* One solve per call: ``horizon`` stages of ``dt_s`` planned from the pose, the first
  ``duration_s / dt_s`` inputs flown (noise-free: re-planning inside a step adds little). The
  reference is the primitive, extended along its last segment over the look-ahead. The warm
  start is the best of the closed-form roll-out and :data:`GUESS_HEADINGS` turn-then-straight
  roll-outs (a cold start with a disc dead ahead leaves Ipopt locally infeasible).
* Only stage points are constrained, so each disc is inflated to ``√((r + s)² + h²)``, ``h =
  v dt / 2``, ``s`` the sagitta of a ``2h`` chord on the tightest turn: the whole path keeps
  ``r``. ``margin_m`` is the controllers' safety margin on top (NMPC keeps it; the QP may spend
  it as slack); it should cover the objects' motion in one call, as discs are re-centred every
  call and held still over a horizon.
* Discs the UAV cannot keep out of (an estimate appears on or next to it): the *escape floor*
  is the smallest stage-point distance to the centre when turning away at ``ω_max`` while the
  centre is ahead, then flying straight. The disc is shrunk until its constraint is the floor
  less :data:`FLOOR_SLACK_M` and its radius is under the current distance: the UAV gets no
  closer than it must (no closer than now if the centre is abeam or behind) and the margin
  pushes it back out. Below :data:`MIN_DISC_M` (the UAV is on the estimate) it is left out.
* No plan (``NO_SOLUTION``/``ERROR``; ``auto`` ends in the closed-form law, so only a single
  backend fails): :func:`~searchtrack.models.radio.uav.fly_heading` flies the primitive toward
  the heading of the reference's last segment, and the result's message says so.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.models.radio.uav import UavModel, fly_heading
from searchtrack.models.vehicles import VehicleModel, unicycle
from searchtrack.plan.trajectory import (
    BACKENDS,
    ControlPlan,
    NmpcOptions,
    Obstacles,
    SampledPath,
    TrackingProblem,
    solve,
    solve_closed_form,
)

log = logging.getLogger("searchtrack.sim.radio.keep_out")

FLOOR_SLACK_M = 0.1
"""Clearance (m) left under the escape floor of a shrunk disc (strict feasibility)."""
GUESS_HEADINGS = 16
"""Turn-then-straight roll-outs among which the warm start is chosen."""
MIN_DISC_M = 0.1
"""Smallest shrunk disc radius (m) kept in a solve."""
NMPC_OPTIONS = NmpcOptions(tol=1e-6)
"""Ipopt's ``tol`` set below the 1e-5 violation above which NMPC rejects its answer."""


@dataclass(frozen=True)
class KeepOut:
    """How the keep-out discs are flown.

    Parameters
    ----------
    radius_m
        ``r_min`` (m), the ground radius kept around each object estimate; 0 disables the discs.
    backend
        Trajectory controller (:data:`searchtrack.plan.trajectory.BACKENDS`): ``"auto"`` (NMPC,
        then the LTV-MPC QP, then the closed form), ``"nmpc"``, ``"ltv_mpc"``, ``"closed_form"``.
    horizon
        Controller stages ``N``; ``N dt_s`` should cover a turn around a disc (≥ 5 s for 50 m).
    dt_s
        Stage length (s).
    time_limit_s
        Wall-clock budget of each solve (s).
    margin_m
        Safety margin (m) kept beyond the inflated disc; > 0 (the QP's slack allowance, and the
        room that lets a shrunk disc push the UAV back out).
    """

    radius_m: float = 50.0
    backend: str = "auto"
    horizon: int = 12
    dt_s: float = 0.5
    time_limit_s: float = 0.1
    margin_m: float = 2.0

    def __post_init__(self) -> None:
        checks.non_negative("radius_m", self.radius_m)
        checks.choice("backend", self.backend, BACKENDS.names())
        checks.count("horizon", self.horizon, least=1)
        for name in ("dt_s", "time_limit_s", "margin_m"):
            checks.positive(name, getattr(self, name))


def vehicle_model(uav: UavModel, dt_s: float) -> VehicleModel:
    """The unicycle at exactly ``uav.speed_mps``, ``|ω| ≤ ω_max``, any ``ω`` within a stage."""
    rate = uav.max_turn_rate
    return unicycle(speed_min_mps=uav.speed_mps, speed_max_mps=uav.speed_mps,
                    turn_rate_max_rps=rate, accel_max_mps2=1.0,
                    turn_accel_max_rps2=2.0 * rate / checks.positive("dt_s", dt_s),
                    cruise_speed_mps=uav.speed_mps)


def escape_floor_m(keep_out: KeepOut, uav: UavModel, pose: FloatArray, centres: FloatArray
                   ) -> FloatArray:
    """``(k,)`` smallest ground distance to each centre at stages ``1..N`` of the escape from it
    (per stage: turn away at ``ω_max`` while the centre is ahead, else straight)."""
    rel = centres - pose[None, :2]
    pos = np.zeros_like(rel)
    heading = np.full(rel.shape[0], float(pose[2]))
    floor = np.full(rel.shape[0], np.inf)
    for _ in range(keep_out.horizon):
        bearing = np.arctan2(rel[:, 1] - pos[:, 1], rel[:, 0] - pos[:, 0]) - heading
        rate = np.where(np.cos(bearing) > 0.0,
                        np.where(np.sin(bearing) >= 0.0, -1.0, 1.0) * uav.max_turn_rate, 0.0)
        turned = heading + rate * keep_out.dt_s
        arc = np.column_stack([np.sin(turned) - np.sin(heading), np.cos(heading) - np.cos(turned)])
        line = np.column_stack([np.cos(heading), np.sin(heading)]) * keep_out.dt_s
        straight = (rate == 0.0)[:, None]
        pos = pos + uav.speed_mps * np.where(straight, line, arc / np.where(straight, 1.0,
                                                                          rate[:, None]))
        heading = turned
        floor = np.minimum(floor, np.hypot(*(rel - pos).T))
    return floor


def inflated_radius_m(keep_out: KeepOut, uav: UavModel) -> float:
    """Stage-point radius keeping the whole path (bent by the tightest turn) at ``radius_m``."""
    half = 0.5 * uav.speed_mps * keep_out.dt_s
    rho = uav.speed_mps / uav.max_turn_rate
    sagitta = rho - math.sqrt(rho**2 - half**2) if half < rho else rho
    return math.hypot(keep_out.radius_m + sagitta, half)


def disc_radii_m(keep_out: KeepOut, uav: UavModel, pose: FloatArray, centres: FloatArray
                 ) -> FloatArray:
    """``(k,)`` radius of each disc in the solve: the inflated radius, shrunk to the escape floor
    less ``margin_m`` and :data:`FLOOR_SLACK_M` and to under the current distance; 0 (left out)
    below :data:`MIN_DISC_M`."""
    avail = escape_floor_m(keep_out, uav, pose, centres) - keep_out.margin_m - FLOOR_SLACK_M
    now = np.hypot(*(centres - pose[None, :2]).T) - 1e-3  # the UAV must start outside
    radii = np.minimum(inflated_radius_m(keep_out, uav), np.minimum(avail, now))
    return np.asarray(np.where(radii >= MIN_DISC_M, radii, 0.0), dtype=np.float64)


def _reference(pose: FloatArray, reference_xy: FloatArray, step_s: float, until_s: float
               ) -> SampledPath:
    """The primitive from the pose (``t = 0``), extended along its last segment to ``until_s``."""
    pts = np.vstack([pose[None, :2], reference_xy])
    times = step_s * np.arange(pts.shape[0])
    if until_s > times[-1]:
        pts = np.vstack([pts, pts[-1] + (pts[-1] - pts[-2]) * (until_s - times[-1]) / step_s])
        times = np.append(times, until_s)
    return SampledPath(times_s=times, positions_m=pts)


def _stages(keep_out: KeepOut, uav: UavModel, duration_s: float | None) -> tuple[float, int]:
    """``(duration, stages flown)``: whole ``uav.step_s``, whole ``dt_s``, within the horizon."""
    duration = uav.step_s if duration_s is None else checks.positive("duration_s", duration_s)
    for unit, name in ((uav.step_s, "uav.step_s"), (keep_out.dt_s, "keep_out.dt_s")):
        ratio = duration / unit
        if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-9:
            raise InvalidInputError("duration_s", duration_s,
                                    f"must be a whole multiple of {name} = {unit:g} s")
    stages = round(duration / keep_out.dt_s)
    if stages > keep_out.horizon:
        raise InvalidInputError("duration_s", duration_s, "longer than the controller horizon")
    return duration, stages


def _heading_rollouts(problem: TrackingProblem) -> tuple[FloatArray, FloatArray]:
    """Inputs ``(C, N, 2)`` and states ``(C, N + 1, 3)``: turns at the maximum rate toward
    :data:`GUESS_HEADINGS` evenly spread headings, then straight (the primitives' shape)."""
    m = problem.model
    targets = problem.state[2] + np.linspace(-np.pi, np.pi, GUESS_HEADINGS, endpoint=False)
    x = np.tile(problem.state[:, None], (1, GUESS_HEADINGS))
    states, inputs = [x.T], []
    for _ in range(problem.horizon):
        rate = np.clip(wrap_angle(targets - x[2]) / problem.dt_s, m.input_lower[1],
                       m.input_upper[1])
        u = np.vstack([np.full(GUESS_HEADINGS, m.nominal_input[0]), rate])
        x = m.step(x, u, problem.dt_s)
        states.append(x.T)
        inputs.append(u.T)
    return np.stack(inputs, axis=1), np.stack(states, axis=1)


def _first_guess(problem: TrackingProblem) -> ControlPlan:
    """The warm start: of the closed-form roll-out and the heading roll-outs, the cheapest to
    track that clears the discs (else the one that comes closest to), behind a dummy stage
    that the controllers' one-stage shift drops."""
    closed = solve_closed_form(problem).plan
    assert closed is not None  # the closed form always answers
    inputs, states = _heading_rollouts(problem)
    inputs = np.concatenate([closed.inputs[None], inputs])
    states = np.concatenate([closed.states[None], states])
    pos = states[:, 1:, :2]
    clear = problem.obstacles.clearance_m(pos.reshape(-1, 2)).reshape(pos.shape[:2])
    clear = clear.min(axis=1) - problem.safety_margin_m  # inf without discs
    w = np.full(problem.horizon, problem.weights.position)
    w[-1] = problem.weights.terminal
    cost = np.sum(w * np.sum((pos - problem.reference_positions()[None]) ** 2, axis=2), axis=1)
    ok = clear >= 0.0
    best = int(np.argmin(np.where(ok, cost, np.inf))) if ok.any() else int(np.argmax(clear))
    return ControlPlan(inputs=np.vstack([inputs[best, :1], inputs[best]]),
                       states=np.vstack([states[best, :1], states[best]]), dt_s=problem.dt_s,
                       controller="warm start")


def fly_with_keep_out(
    keep_out: KeepOut,
    uav: UavModel,
    pose: ArrayLike,
    reference_xy: ArrayLike,
    centres: ArrayLike,
    duration_s: float | None = None,
) -> tuple[FloatArray, Result[ControlPlan]]:
    """Fly ``duration_s`` (default ``uav.step_s``) along a primitive, kept out of the discs.

    Parameters
    ----------
    keep_out
        Disc radius and controller settings.
    uav
        The UAV (speed, turn-rate limit, step).
    pose
        ``(3,)`` current ``(x, y, heading)`` (m, m, rad).
    reference_xy
        ``(n, 2)`` positions of the chosen primitive at ``step_s, 2 step_s, …, n step_s``.
    centres
        ``(k, 2)`` ground positions of the current object estimates (``k`` may be 0).
    duration_s
        Flight time (s): whole steps, whole stages, at most the horizon.

    Returns
    -------
    The ``(3,)`` pose afterwards (heading in ``[−π, π)``) and the controller's result:
    ``backend`` the controller that answered, ``stats["fallbacks"]`` the ``auto`` stages that
    failed, ``stats["heading_fallback"]`` 1 when no controller answered and the primitive was
    flown (``plan`` is then ``None``), ``stats["shrunk_discs"]`` the discs too shrunk to
    guarantee ``radius_m`` and ``stats["dropped_discs"]`` those left out.

    Raises
    ------
    InvalidInputError
        A bad pose, reference, centres (NaN, wrong shape) or duration, naming it.
    """
    state, ref = checks.finite_array("pose", pose, (3,)), checks.finite_array(
        "reference_xy", reference_xy, (None, 2))
    if ref.shape[0] < 1:
        raise InvalidInputError("reference_xy", reference_xy, "needs at least one position")
    objects = checks.points("centres", centres)
    if keep_out.radius_m == 0.0:
        objects = objects[:0]  # discs disabled
    duration, stages = _stages(keep_out, uav, duration_s)
    radii = disc_radii_m(keep_out, uav, state, objects)
    kept = radii > 0.0
    model = vehicle_model(uav, keep_out.dt_s)
    problem = TrackingProblem(
        model, state, _reference(state, ref, uav.step_s, (keep_out.horizon + 1) * keep_out.dt_s),
        obstacles=Obstacles(centers_m=objects[kept].reshape(-1, 2), radii_m=radii[kept]),
        horizon=keep_out.horizon, dt_s=keep_out.dt_s, safety_margin_m=keep_out.margin_m,
        nmpc_options=NMPC_OPTIONS)
    problem = dataclasses.replace(problem, warm=_first_guess(problem))
    result = solve(problem, backend=keep_out.backend, time_limit_s=keep_out.time_limit_s)
    lost = kept & (radii + keep_out.margin_m < inflated_radius_m(keep_out, uav))
    stats = {**result.stats, "shrunk_discs": float(np.count_nonzero(lost)),
             "dropped_discs": float(radii.size - np.count_nonzero(kept)),
             "heading_fallback": float(result.plan is None)}
    message = result.message
    if result.plan is not None:
        flown = np.array(state, dtype=float)
        for u in result.plan.inputs[:stages]:
            flown = model.step(flown, model.clip_input(u), keep_out.dt_s, substeps=4)
    else:
        d = np.diff(np.vstack([state[None, :2], ref])[-2:], axis=0)[0]
        target = math.atan2(d[1], d[0]) if np.hypot(d[0], d[1]) > 1e-9 else float(state[2])
        flown = np.array(fly_heading(uav, state, target, duration)[-1], dtype=float)
        message += (f"; no controller answered: flew the reference primitive "
                    f"(fly_heading to {target:.3f} rad)")
        log.warning("keep-out: %s", message)
    flown[2] = wrap_angle(float(flown[2]))
    return flown, dataclasses.replace(result, message=message, stats=stats)
