"""The fixed-wing UAV as a Dubins car at fixed altitude (thesis 001 §5.1), vectorised over UAVs.

Kinematics (5.1): ``ẋ = S cos θ``, ``ẏ = S sin θ``, ``θ̇ = u``. A force ``F = [X, Y]`` on a unit
mass gives (5.2)–(5.3) ``θ̇ = (Y cos θ − X sin θ)/S`` and ``Ṡ = X cos θ + Y sin θ``; the turn rate
is saturated by ``sat(·, θ̇_max)`` (5.5) and the speed updated by an Euler step (5.4).

Erratum: (5.4) saturates the speed symmetrically, ``sat(S, S_max)``, which lets it fall to zero
or below, where (5.3) divides by ``S``. Here the speed is clamped to ``[S_min, S_max]`` with
``S_min > 0``. Over one step the turn rate and speed are held, and the state advances along the
resulting arc in closed form (``method="exact"``), by classical RK4 (``"rk4"``), or by the
thesis's explicit Euler step (``"euler"``: position from the heading at the start of the step,
with the commanded speed; reading (5.4) with the previous speed is the same thing for the
thesis's constant-speed UAV).

The kinematics (5.1) are written once, as
:class:`~searchtrack.models.vehicles.unicycle.UnicycleDynamics` (no wind here); the RK4 and Euler
steps integrate them, the closed-form arc solves them.

Turning back (this library's, beside the thesis's law): (5.3) turns the UAV by the force's
component across its heading only, and a constant-speed UAV loses the component along it. A
force pointing behind the UAV, as the spring of an anchor it has just overflown, then turns it
little (not at all when exactly behind): the UAV flies on away from its anchor until the small
lateral part grows, which with the weak loiter springs of a wide footprint takes it hundreds of
metres off the target it loiters over. For the UAVs selected by ``turn_back``, a force with a
negative along-heading component ``X cos θ + Y sin θ < 0`` commands the turn with its whole
magnitude, toward the side of its lateral component (left when exactly behind): ``θ̇ =
sat(±‖F‖/S, θ̇_max)``. Ahead of the UAV the two laws are the same, and they meet at 90° (there
the lateral component is the whole force). The speed law (5.4) is the same for both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles.model import VehicleModel, rk4_step
from searchtrack.models.vehicles.namespace import NUMPY
from searchtrack.models.vehicles.unicycle import UnicycleDynamics, unicycle

Method = Literal["exact", "rk4", "euler"]
MPS_PER_MPH = 0.44704


def sat(x: ArrayLike, x_max: float) -> FloatArray:
    """The saturation function (5.5): ``x`` clipped to ``[−x_max, x_max]``."""
    limit = checks.non_negative("x_max", x_max)
    return np.clip(np.asarray(x, dtype=np.float64), -limit, limit)


@dataclass(frozen=True)
class DubinsLimits:
    """Speed and turn-rate limits of a UAV; defaults are Table 6.4's (80 mph, 70 °/s).

    Parameters
    ----------
    speed_max_mps
        ``S_max`` (m/s).
    speed_min_mps
        ``S_min`` (m/s), ``0 < S_min ≤ S_max``; equal to ``S_max`` for a constant-speed UAV.
    turn_rate_max_rps
        ``θ̇_max`` (rad/s), > 0. Table 6.2 uses 50 °/s.
    """

    speed_max_mps: float = 80.0 * MPS_PER_MPH
    speed_min_mps: float = 80.0 * MPS_PER_MPH
    turn_rate_max_rps: float = math.radians(70.0)

    def __post_init__(self) -> None:
        hi = checks.positive("speed_max_mps", self.speed_max_mps)
        lo = checks.positive("speed_min_mps", self.speed_min_mps)
        if lo > hi:
            raise InvalidInputError("speed_min_mps", self.speed_min_mps,
                                    f"must not exceed speed_max_mps={hi!r}")
        object.__setattr__(self, "speed_max_mps", hi)
        object.__setattr__(self, "speed_min_mps", lo)
        object.__setattr__(self, "turn_rate_max_rps",
                           checks.positive("turn_rate_max_rps", self.turn_rate_max_rps))

    def turn_radius_m(self, speed_mps: ArrayLike) -> FloatArray:
        """The tightest turn radius ``S/θ̇_max`` (m) at ``speed_mps``."""
        return np.asarray(speed_mps, dtype=np.float64) / self.turn_rate_max_rps

    def clamp_speed(self, speed_mps: ArrayLike) -> FloatArray:
        """``speed_mps`` clamped to ``[S_min, S_max]``."""
        return np.clip(np.asarray(speed_mps, dtype=np.float64), self.speed_min_mps,
                       self.speed_max_mps)


@dataclass(frozen=True)
class UavState:
    """Positions, headings and speeds of ``n`` UAVs (read-only arrays, shape ``(n,)``).

    ``heading_rad`` is measured from the x axis (east) anticlockwise; it is kept in
    ``[−π, π)`` after each step. Speeds must be positive.
    """

    x_m: FloatArray
    y_m: FloatArray
    heading_rad: FloatArray
    speed_mps: FloatArray

    def __post_init__(self) -> None:
        x = checks.finite_array("x_m", np.atleast_1d(np.asarray(self.x_m, dtype=float)), (None,))
        shape = (x.shape[0],)
        set_ = object.__setattr__
        set_(self, "x_m", x)
        for name in ("y_m", "heading_rad", "speed_mps"):
            value = np.atleast_1d(np.asarray(getattr(self, name), dtype=float))
            set_(self, name, checks.finite_array(name, value, shape))
        if np.any(self.speed_mps <= 0):
            raise InvalidInputError("speed_mps", self.speed_mps, "speeds must be > 0 (m/s)")

    @property
    def n(self) -> int:
        """Number of UAVs."""
        return int(self.x_m.shape[0])

    @property
    def xy_m(self) -> FloatArray:
        """``(n, 2)`` positions (m)."""
        return np.column_stack([self.x_m, self.y_m])

    @property
    def velocity_mps(self) -> FloatArray:
        """``(n, 2)`` velocities (m/s)."""
        heading = np.column_stack([np.cos(self.heading_rad), np.sin(self.heading_rad)])
        return np.asarray(self.speed_mps[:, None] * heading, dtype=np.float64)


def force_to_controls(
    state: UavState, force: ArrayLike, dt_s: float, limits: DubinsLimits, *,
    turn_back: ArrayLike = False,
) -> tuple[FloatArray, FloatArray]:
    """The turn rate (rad/s) and speed (m/s) a unit-mass force ``(n, 2)`` commands for one step.

    Turn rate ``sat((Y cos θ − X sin θ)/S, θ̇_max)`` ((5.3)–(5.5)); for the UAVs ``turn_back``
    selects (one boolean, or one per UAV), ``sat(±‖F‖/S, θ̇_max)`` where the force points
    behind the UAV (module docstring). Speed ``S + (X cos θ + Y sin θ)Δt`` (5.4), clamped to
    ``[S_min, S_max]``.
    """
    f = checks.points("force", force)
    if f.shape[0] != state.n:
        raise InvalidInputError("force", force, f"must have shape ({state.n}, 2), one per UAV")
    dt = checks.positive("dt_s", dt_s)
    c, s = np.cos(state.heading_rad), np.sin(state.heading_rad)
    chosen = np.asarray(turn_back)
    if chosen.dtype != np.bool_ or chosen.shape not in ((), (state.n,)):
        raise InvalidInputError("turn_back", turn_back,
                                f"must be one boolean or {state.n} booleans, one per UAV")
    lateral = f[:, 1] * c - f[:, 0] * s
    accel = f[:, 0] * c + f[:, 1] * s
    if chosen.any():
        back = chosen & (accel < 0.0)
        side = np.where(lateral >= 0.0, 1.0, -1.0)
        lateral = np.where(back, side * np.hypot(f[:, 0], f[:, 1]), lateral)
    turn = lateral / state.speed_mps
    return sat(turn, limits.turn_rate_max_rps), limits.clamp_speed(state.speed_mps + accel * dt)


_KINEMATICS = UnicycleDynamics()
_NO_WIND = np.zeros(2)


def propagate(
    state: UavState,
    turn_rate_rps: ArrayLike,
    speed_mps: ArrayLike,
    dt_s: float,
    limits: DubinsLimits,
    *,
    method: Method = "exact",
) -> UavState:
    """Advance the UAVs ``dt_s`` seconds under (5.1) with held turn rate and speed.

    Parameters
    ----------
    state
        UAVs at the start of the step.
    turn_rate_rps
        Commanded turn rate ``u`` (rad/s), one or one per UAV; saturated by (5.5).
    speed_mps
        Commanded speed (m/s), one or one per UAV; clamped to ``[S_min, S_max]``.
    dt_s
        Step length ``Δt`` (s), > 0.
    limits
        Speed and turn-rate limits.
    method
        ``"exact"`` (closed-form arc), ``"rk4"`` or ``"euler"`` (the thesis's (5.4)).
    """
    dt = checks.positive("dt_s", dt_s)
    n = (state.n,)
    u = checks.finite_array("turn_rate_rps", np.broadcast_to(
        np.asarray(turn_rate_rps, dtype=float), n), n)
    v = checks.finite_array("speed_mps", np.broadcast_to(np.asarray(speed_mps, dtype=float), n), n)
    if np.any(v < 0):
        raise InvalidInputError("speed_mps", speed_mps, "must be ≥ 0 (m/s) before clamping")
    u, v = sat(u, limits.turn_rate_max_rps), limits.clamp_speed(v)
    x, y, th = state.x_m, state.y_m, state.heading_rad
    if method == "exact":
        half = 0.5 * u * dt
        chord = v * dt * np.sinc(half / np.pi)  # arc of angle 2·half: chord = S Δt sin(h)/h
        x_new, y_new = x + chord * np.cos(th + half), y + chord * np.sin(th + half)
        th_new = th + u * dt
    elif method in ("rk4", "euler"):
        pose, inputs = np.stack([x, y, th]), np.stack([v, u])
        if method == "rk4":
            pose = rk4_step(_KINEMATICS, pose, inputs, _NO_WIND, dt)
        else:
            pose = pose + dt * _KINEMATICS(pose, inputs, _NO_WIND, NUMPY)
        x_new, y_new, th_new = pose
    else:
        raise InvalidInputError("method", method, "must be 'exact', 'rk4' or 'euler'")
    return UavState(x_m=x_new, y_m=y_new, heading_rad=wrap_angle(np.asarray(th_new)), speed_mps=v)


def step_force(
    state: UavState,
    force: ArrayLike,
    dt_s: float,
    limits: DubinsLimits,
    *,
    method: Method = "exact",
    turn_back: ArrayLike = False,
) -> UavState:
    """One step of the UAVs under unit-mass forces ``(n, 2)`` (N/kg): (5.3)–(5.5) (the UAVs
    ``turn_back`` selects turn back by the whole force when it points behind them), then
    :func:`propagate`."""
    turn, speed = force_to_controls(state, force, dt_s, limits, turn_back=turn_back)
    return propagate(state, turn, speed, dt_s, limits, method=method)


def unicycle_from_limits(limits: DubinsLimits, *, accel_max_mps2: float = 5.0,
                         turn_accel_max_rps2: float = 4.0) -> VehicleModel:
    """The unicycle vehicle model (for the trajectory controllers) with the speed and turn-rate
    limits of a :class:`DubinsLimits`; a Dubins car when ``speed_min_mps == speed_max_mps``."""
    return unicycle(speed_min_mps=limits.speed_min_mps, speed_max_mps=limits.speed_max_mps,
                    turn_rate_max_rps=limits.turn_rate_max_rps, accel_max_mps2=accel_max_mps2,
                    turn_accel_max_rps2=turn_accel_max_rps2)
