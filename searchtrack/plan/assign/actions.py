"""Candidate actions: fixed-wing motion primitives (paper 003 §2.3) and the 3-D lattice of 004.

Fixed-wing kinematics (003 digest §2.3, state ``[x, y, z, ψ, θ]``)::

    ẋ = v cos θ cos ψ,  ẏ = v cos θ sin ψ,  ż = v sin θ,  ψ̇ = u_ψ,  θ̇ = u_θ

For every combination of forward speed, yaw rate and pitch rate the state is integrated with
Euler steps of ``euler_dt_s`` (10 ms in the paper) over ``steps × step_s`` seconds; the pose at
the end of each step is one measurement pose. Trajectories that leave the altitude band at any
Euler step are discarded. Collisions between UAVs are pruned by the assignment problem's
``min_separation_m``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def _values(name: str, values: tuple[float, ...], positive: bool = False) -> None:
    if not isinstance(values, tuple) or not values or not all(
            isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise InvalidInputError(name, values, "must be a non-empty tuple of finite numbers")
    if positive and min(values) <= 0.0:
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
        Pitch is clipped to ``±max_pitch_rad`` during integration.
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
        _values("speeds_mps", self.speeds_mps, positive=True)
        _values("yaw_rates_rps", self.yaw_rates_rps)
        _values("pitch_rates_rps", self.pitch_rates_rps)
        if not isinstance(self.steps, int) or self.steps < 1:
            raise InvalidInputError("steps", self.steps, "must be a positive integer")
        for name in ("step_s", "euler_dt_s", "max_pitch_rad"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise InvalidInputError(name, v, "must be finite and > 0")
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


def fixed_wing_actions(state: FloatArray, primitives: FixedWingPrimitives) -> FloatArray:
    """``(A, T, 5)`` poses ``[x, y, z, ψ, θ]`` of the primitives from ``state`` that stay in
    the altitude band (``A`` may be 0)."""
    s0 = np.asarray(state, dtype=np.float64).reshape(-1)
    if s0.shape != (5,) or not np.all(np.isfinite(s0)):
        raise InvalidInputError("state", state, "must be finite [x, y, z, yaw, pitch]")
    u = primitives.controls
    n = u.shape[0]
    sub = max(1, round(primitives.step_s / primitives.euler_dt_s))
    dt = primitives.step_s / sub
    x = np.tile(s0, (n, 1))
    ok = np.ones(n, dtype=bool)
    poses = np.empty((n, primitives.steps, 5))
    for t in range(primitives.steps):
        for _ in range(sub):
            v, yaw, pitch = u[:, 0], x[:, 3], x[:, 4]
            x[:, 0] += dt * v * np.cos(pitch) * np.cos(yaw)
            x[:, 1] += dt * v * np.cos(pitch) * np.sin(yaw)
            x[:, 2] += dt * v * np.sin(pitch)
            x[:, 3] += dt * u[:, 1]
            x[:, 4] = np.clip(pitch + dt * u[:, 2], -primitives.max_pitch_rad,
                              primitives.max_pitch_rad)
            ok &= (x[:, 2] >= primitives.z_min_m) & (x[:, 2] <= primitives.z_max_m)
        poses[:, t] = x
    poses[:, :, 3] = np.mod(poses[:, :, 3] + np.pi, 2.0 * np.pi) - np.pi
    return poses[ok]


def lattice_moves(step_m: float, dims: int = 3) -> FloatArray:
    """The ``2·dims`` axis moves ``±step_m`` of paper 004 (Fig. 4: six moves of 12 m in 3-D)."""
    if not (math.isfinite(step_m) and step_m > 0.0):
        raise InvalidInputError("step_m", step_m, "must be finite and > 0")
    if dims not in (2, 3):
        raise InvalidInputError("dims", dims, "must be 2 or 3")
    eye = np.eye(3)[:dims]
    return np.concatenate([eye, -eye]) * step_m


def lattice_sequences(start: FloatArray, moves: FloatArray, horizon: int,
                      bounds: FloatArray) -> FloatArray:
    """``(S, horizon, 3)`` position sequences ``q_{k+1..k+τ}`` (004 eq. 7): every sequence of
    ``moves`` from ``start`` that stays inside ``bounds`` ``(3, 2)``, in lexicographic move
    order (``S ≤ |moves|^τ``)."""
    q0 = np.asarray(start, dtype=np.float64).reshape(-1)[:3]
    if not isinstance(horizon, int) or horizon < 1:
        raise InvalidInputError("horizon", horizon, "must be a positive integer")
    combos = np.array(list(itertools.product(range(moves.shape[0]), repeat=horizon)))
    steps = moves[combos]  # (S, τ, 3)
    seqs = q0 + np.cumsum(steps, axis=1)
    inside = np.all((seqs >= bounds[:, 0]) & (seqs <= bounds[:, 1]), axis=(1, 2))
    out: FloatArray = seqs[inside]
    return out
