"""Candidate actions of paper 003 (§2.3): fixed-wing motion primitives.

The kinematics are the fixed-wing model of :mod:`searchtrack.models.vehicles.fixed_wing`
(state ``[x, y, z, ψ, θ]``, inputs ``[v, u_ψ, u_θ]``)::

    ẋ = v cos θ cos ψ,  ẏ = v cos θ sin ψ,  ż = v sin θ,  ψ̇ = u_ψ,  θ̇ = u_θ

For every combination of forward speed, yaw rate and pitch rate the state is integrated with
Euler steps of ``euler_dt_s`` (10 ms in the paper) over ``steps × step_s`` seconds, the pitch
clipped to the model's pitch limit after each step; the pose at the end of each step is one
measurement pose. Trajectories that leave the model's altitude band at any Euler step are
discarded. Collisions between UAVs are pruned by the assignment problem's ``min_separation_m``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from searchtrack.core.angles import wrap_angle
from searchtrack.core.checks import positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import VehicleModel, fixed_wing

_Z, _YAW, _PITCH = 2, 3, 4


def _values(name: str, values: tuple[float, ...], strictly_positive: bool = False) -> None:
    if not isinstance(values, tuple) or not values or not all(
            isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise InvalidInputError(name, values, "must be a non-empty tuple of finite numbers")
    if strictly_positive and min(values) <= 0.0:
        raise InvalidInputError(name, values, "must all be > 0")


@dataclass(frozen=True)
class FixedWingPrimitives:
    """The control grid and limits of the fixed-wing motion primitives.

    Parameters
    ----------
    speeds_mps, yaw_rates_rps, pitch_rates_rps
        Values of each control input; every combination is one primitive.
    steps
        Measurement poses per action ``T`` (one per step).
    step_s
        Seconds per step ``D`` (5 s in 003).
    euler_dt_s
        Euler integration step (10 ms in 003).
    z_min_m, z_max_m
        Altitude band (003 uses a 50 m ceiling); trajectories leaving it are dropped.
    max_pitch_rad
        Pitch is clipped to ``±max_pitch_rad`` (below π/2) during integration.
    """

    speeds_mps: tuple[float, ...] = (1.5,)
    yaw_rates_rps: tuple[float, ...] = (-0.3, -0.15, 0.0, 0.15, 0.3)
    pitch_rates_rps: tuple[float, ...] = (-0.1, 0.0, 0.1)
    steps: int = 1
    step_s: float = 5.0
    euler_dt_s: float = 0.01
    z_min_m: float = 2.0
    z_max_m: float = 50.0
    max_pitch_rad: float = 0.6

    def __post_init__(self) -> None:
        _values("speeds_mps", self.speeds_mps, strictly_positive=True)
        _values("yaw_rates_rps", self.yaw_rates_rps)
        _values("pitch_rates_rps", self.pitch_rates_rps)
        if not isinstance(self.steps, int) or self.steps < 1:
            raise InvalidInputError("steps", self.steps, "must be a positive integer")
        positive("step_s", self.step_s)
        positive("euler_dt_s", self.euler_dt_s)
        real("max_pitch_rad", self.max_pitch_rad, low=0.0, high=0.5 * math.pi, low_open=True,
             high_open=True)
        if self.euler_dt_s > self.step_s:
            raise InvalidInputError("euler_dt_s", self.euler_dt_s, "must be <= step_s")
        if not (math.isfinite(self.z_min_m) and math.isfinite(self.z_max_m)
                and self.z_min_m < self.z_max_m):
            raise InvalidInputError("z_max_m", self.z_max_m, "must exceed z_min_m (finite)")

    @property
    def controls(self) -> FloatArray:
        """``(C, 3)`` combinations ``[v, u_ψ, u_θ]``."""
        return np.array(list(itertools.product(self.speeds_mps, self.yaw_rates_rps,
                                               self.pitch_rates_rps)), dtype=np.float64)

    @cached_property
    def vehicle(self) -> VehicleModel:
        """The fixed-wing model the primitives fly: its kinematics, the altitude band and the
        pitch limit as its state box, the range of the control grid as its input box."""
        base = fixed_wing(pitch_max_rad=self.max_pitch_rad, altitude_min_m=self.z_min_m,
                          altitude_max_m=self.z_max_m)
        u = self.controls
        lo, hi = u.min(axis=0), u.max(axis=0)
        cruise = np.clip([0.5 * (lo[0] + hi[0]), 0.0, 0.0], lo, hi)
        return dataclasses.replace(base, input_lower=tuple(lo.tolist()),
                                   input_upper=tuple(hi.tolist()),
                                   nominal_input=tuple(cruise.tolist()))


def fixed_wing_actions(state: FloatArray, primitives: FixedWingPrimitives) -> FloatArray:
    """``(A, T, 5)`` poses ``[x, y, z, ψ, θ]`` of the primitives from ``state`` that stay in
    the altitude band (``A`` may be 0); ``ψ`` wrapped into ``[−π, π)``."""
    s0 = np.asarray(state, dtype=np.float64).reshape(-1)
    if s0.shape != (5,) or not np.all(np.isfinite(s0)):
        raise InvalidInputError("state", state, "must be finite [x, y, z, yaw, pitch]")
    model = primitives.vehicle
    u = primitives.controls.T  # (3, C)
    n = u.shape[1]
    sub = max(1, round(primitives.step_s / primitives.euler_dt_s))
    dt = primitives.step_s / sub
    z_lo, z_hi = model.state_lower[_Z], model.state_upper[_Z]
    pitch_lo, pitch_hi = model.state_lower[_PITCH], model.state_upper[_PITCH]
    # Without wind the kinematics are driftless and linear in the inputs, so the Euler increment
    # dt·f(x, u) is f(x, dt·u); evaluated this way its rounding is that of 003's primitives.
    du = dt * u
    x = np.tile(s0[:, None], (1, n))  # (5, C)
    ok = np.ones(n, dtype=bool)
    poses = np.empty((n, primitives.steps, 5))
    for t in range(primitives.steps):
        for _ in range(sub):
            x = x + model.f(x, du)
            x[_PITCH] = np.clip(x[_PITCH], pitch_lo, pitch_hi)
            ok &= (x[_Z] >= z_lo) & (x[_Z] <= z_hi)
        poses[:, t] = x.T
    poses[:, :, _YAW] = wrap_angle(poses[:, :, _YAW])
    return poses[ok]
