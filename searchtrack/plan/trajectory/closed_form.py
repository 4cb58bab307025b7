"""Closed-form tracking laws: the fallback that always answers, in microseconds.

* ``uav7``: the backstepping / feedback-linearising law of paper 004 eq. (13) with the obstacle
  term of eqs. (14)–(15). Since ``q̈ = S_y (f + δ̄ u)`` (constant wind), choosing
  ``u = (S_y δ̄)⁻¹ (a − S_y f)`` with ``a = −(K₁+K₂+K₃)(q̇ − ṙ) − (1 + K₁K₂K₃)(q − r)`` gives
  the linear closed loop of the paper; with a piecewise-constant reference (``ṙ = 0``, the
  paper's use) it is eq. (13) exactly. ``u_φ`` is left free by (13) (``δ̄`` has no roll input);
  here it levels the wings, ``u_φ = −k_φ φ``. Eq. (14): ``O = 1`` when the nearest obstacle
  surface is closer than ``d_l``; eq. (15): ``ũ_β = u_β − k_obs O``, turning away from the
  obstacle's side (``obstacle_turn="bearing"``) or always the same way as printed (``"printed"``).
* ``unicycle`` / ``fixed_wing``: pure pursuit of the reference a lookahead ahead, the heading
  command bent away from obstacles closer than ``d_l`` (a repulsive potential), a speed loop on
  the along-track error and, for the fixed wing, a pitch loop towards the target's altitude.

All inputs are clipped to the rate limits and the input box. The law is rolled out over the
horizon to give a predicted trajectory (used to warm-start the optimisers afterwards).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from searchtrack.core import checks
from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import Uav7Dynamics
from searchtrack.plan.trajectory.problem import ControlPlan, TrackingProblem

MODELS = ("unicycle", "fixed_wing", "uav7")


@dataclass(frozen=True)
class ClosedFormGains:
    """Gains of the closed-form laws (SI units).

    ``backstepping`` are ``(K_g1, K_g2, K_g3)`` of eq. (13) (the paper uses 9, 9, 9, which
    saturates every input of a realistic UAV); ``avoid_distance_m`` is ``d_l`` and ``avoid_gain``
    ``k_obs`` of eqs. (14)–(15) (paper: 6 m, 5); ``repulsion_gain`` scales the pursuit laws'
    obstacle push; ``guard_time_s`` is how fast the 7-state law's state-box guard brings the
    airspeed and flight-path angle back inside their bounds.
    """

    lookahead_s: float = 1.0
    heading_gain: float = 2.0
    speed_gain: float = 0.5
    pitch_gain: float = 2.0
    roll_gain: float = 2.0
    backstepping: tuple[float, float, float] = (1.0, 1.0, 1.0)
    avoid_distance_m: float = 6.0
    avoid_gain: float = 5.0
    repulsion_gain: float = 2.5
    obstacle_turn: Literal["bearing", "printed"] = "bearing"
    guard_time_s: float = 1.0

    def __post_init__(self) -> None:
        for name in ("lookahead_s", "heading_gain", "speed_gain", "pitch_gain", "roll_gain",
                     "avoid_distance_m", "repulsion_gain", "guard_time_s"):
            checks.positive(name, getattr(self, name))
        checks.non_negative("avoid_gain", self.avoid_gain)
        if len(self.backstepping) != 3:
            raise InvalidInputError("backstepping", self.backstepping, "needs K_g1, K_g2, K_g3")
        for k in self.backstepping:
            checks.positive("backstepping", k)
        if self.obstacle_turn not in ("bearing", "printed"):
            raise InvalidInputError("obstacle_turn", self.obstacle_turn,
                                    "must be 'bearing' or 'printed'")


def _repulsion(problem: TrackingProblem, p: FloatArray, gains: ClosedFormGains) -> FloatArray:
    """Sum over obstacles closer than ``d`` of ``k_rep (1 − clearance/d)`` times the unit vector
    away from the obstacle (horizontal for cylinders); ``d`` is ``d_l`` or, if larger, 1.5 turn
    radii at cruise speed, so a vehicle can still turn away in time."""
    obs = problem.obstacles
    dim = p.shape[0]
    out = np.zeros(dim)
    if obs.k == 0:
        return out
    m = problem.model
    radius = m.nominal_input[0] / max(m.input_upper[1], 1e-9)
    reach = max(gains.avoid_distance_m, 1.5 * radius)
    clear = obs.distance_m(p[None, :])[0] - problem.safety_margin_m
    for j in np.flatnonzero(clear < reach):
        away = p - obs.centers_m[j, :dim]
        if dim == 3 and obs.is_cylinder[j]:
            away[2] = 0.0
        norm = float(np.linalg.norm(away))
        if norm > 1e-9:
            out += gains.repulsion_gain * max(0.0, 1.0 - clear[j] / reach) * away / norm
    return out


def _pursuit(problem: TrackingProblem, x: FloatArray, t: float, gains: ClosedFormGains
             ) -> FloatArray:
    m = problem.model
    p = m.position(x)
    target = problem.reference.positions([t + gains.lookahead_s])[0]
    here = problem.reference.positions([t])[0]
    to = target - p
    dist = float(np.linalg.norm(to[:2]))
    direction = to[:2] / max(dist, 1e-9) + _repulsion(problem, p, gains)[:2]
    heading = x[m.angle_indices[0]]
    turn = gains.heading_gain * wrap_angle(math.atan2(direction[1], direction[0]) - heading)
    forward = np.array([math.cos(heading), math.sin(heading)])
    speed = m.nominal_input[0] + gains.speed_gain * float((here - p)[:2] @ forward)
    if m.name == "unicycle":
        return np.array([speed, turn])
    pitch_target = math.atan2(float(to[2]), max(dist, 1e-3))
    return np.array([speed, turn, gains.pitch_gain * (pitch_target - x[4])])


def _guarded_rates(problem: TrackingProblem, rates: FloatArray, va: float, gamma: float,
                   gains: ClosedFormGains) -> FloatArray:
    """``(V̇_a, β̇, γ̇)`` demands limited by the state box and the turn authority."""
    m = problem.model
    lo, hi = np.asarray(m.state_lower), np.asarray(m.state_upper)
    tau = gains.guard_time_s
    out = np.array(rates, dtype=np.float64)
    out[0] = np.clip(out[0], (lo[3] - va) / tau, (hi[3] - va) / tau)
    out[2] = np.clip(out[2], (lo[5] - gamma) / tau, (hi[5] - gamma) / tau)
    dyn = m.dynamics
    assert isinstance(dyn, Uav7Dynamics)
    turn_max = dyn.lift / (dyn.mass_kg * va * math.cos(gamma)) * float(m.input_upper[1])
    out[1] = np.clip(out[1], -turn_max, turn_max)
    return out


def _backstepping(problem: TrackingProblem, x: FloatArray, t: float, gains: ClosedFormGains
                  ) -> FloatArray:
    """Eq. (13) with (14)–(15) for the 7-state UAV (NED)."""
    dyn = problem.model.dynamics
    assert isinstance(dyn, Uav7Dynamics)
    q, va, beta, gamma, phi = x[:3], x[3], x[4], x[5], x[6]
    cb, sb, cg, sg = math.cos(beta), math.sin(beta), math.cos(gamma), math.sin(gamma)
    m, g = dyn.mass_kg, dyn.gravity_mps2
    s_y = np.array([[cb * cg, -va * sb * cg, -va * cb * sg],
                    [sb * cg, va * cb * cg, -va * sb * sg],
                    [-sg, 0.0, -va * cg]])
    delta = np.diag([1.0 / m, dyn.lift / (m * va * cg), g * math.cos(phi) / va])
    f = np.array([-dyn.drag_n / m - g * sg, 0.0, -g / va * cg])
    qdot = va * np.array([cb * cg, sb * cg, -sg]) + problem.wind
    r_now, r_next = problem.reference.positions([t, t + problem.dt_s])
    rdot = (r_next - r_now) / problem.dt_s
    k1, k2, k3 = gains.backstepping
    accel = -(k1 + k2 + k3) * (qdot - rdot) - (1.0 + k1 * k2 * k3) * (q - r_now)
    # (13) solves S_y (δ̄ u + f) = a: δ̄ u + f are the rates of (V_a, β, γ) that the law wants.
    # The state-box guard (ours; the paper has none) limits those rates so that V_a and γ head
    # back inside their bounds within guard_time_s and the turn rate stays within the lift the
    # aircraft has; without it a reversal of the reference makes the law loop the aircraft.
    rates = np.linalg.solve(s_y, accel)
    obs = problem.obstacles
    if obs.k:
        clear = obs.distance_m(q[None, :])[0]
        j = int(np.argmin(clear))
        if clear[j] < gains.avoid_distance_m:  # eq. (14)
            side = 1.0
            if gains.obstacle_turn == "bearing":
                rel = obs.centers_m[j, :2] - q[:2]
                side = 1.0 if wrap_angle(math.atan2(rel[1], rel[0]) - beta) >= 0.0 else -1.0
            push = np.zeros(3)
            push[1] = -gains.avoid_gain * side  # eq. (15): −k_obs on the turn input u_β
            if not obs.is_cylinder[j]:
                # a sphere is also cleared vertically (ours): climb if above its centre (NED)
                push[2] = gains.avoid_gain * (1.0 if q[2] <= obs.centers_m[j, 2] else -1.0)
            rates = rates + np.diag(delta) * push
    u3 = (_guarded_rates(problem, rates, va, gamma, gains) - f) / np.diag(delta)
    return np.array([u3[0], u3[1], u3[2], -gains.roll_gain * phi])


def control_law(problem: TrackingProblem, x: FloatArray, t: float, u_prev: FloatArray,
                gains: ClosedFormGains) -> FloatArray:
    """The closed-form input at state ``x`` and time ``t``, rate- and box-limited."""
    m = problem.model
    raw = _backstepping(problem, x, t, gains) if m.name == "uav7" else _pursuit(
        problem, x, t, gains)
    step = np.asarray(m.input_rate_max) * problem.dt_s
    limited = np.clip(raw, u_prev - step, u_prev + step)
    return m.clip_input(np.where(np.isfinite(limited), limited, u_prev))


def solve_closed_form(problem: TrackingProblem, *, gains: ClosedFormGains | None = None
                      ) -> Result[ControlPlan]:
    """Roll the closed-form law out over the horizon; always answers (``FEASIBLE``)."""
    m = problem.model
    if m.name not in MODELS:
        raise InvalidInputError("model", m.name, f"closed form exists for {MODELS}")
    law = ClosedFormGains() if gains is None else gains
    started = time.perf_counter()
    n, dt = problem.horizon, problem.dt_s
    states = np.empty((n + 1, m.nx))
    inputs = np.empty((n, m.nu))
    states[0], u = problem.state, problem.u_prev
    lo, hi = np.asarray(m.state_lower), np.asarray(m.state_upper)
    for k in range(n):
        u = control_law(problem, states[k], problem.time_s + k * dt, u, law)
        inputs[k] = u
        states[k + 1] = np.clip(m.step(states[k], u, dt, problem.wind), lo, hi)
    plan = ControlPlan(inputs=inputs, states=states, dt_s=dt, controller="closed_form")
    ref = problem.reference_positions()
    err = float(np.sum((states[1:, list(m.position_indices)] - ref) ** 2))
    return Result(Status.FEASIBLE, err, None, time.perf_counter() - started, "closed_form", plan,
                  Sense.MINIMIZE, f"closed form ({m.name})")
