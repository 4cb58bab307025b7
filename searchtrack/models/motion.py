"""Single-target motion models for particle filters: random walk, constant velocity, static.

Each model satisfies :class:`searchtrack.models.particle_models.MotionModel`: a state row holds the
position (``position_dim`` columns, metres) first, then any velocities (m/s).

- :class:`RandomWalk` (the GRW of paper 003): ``x' = x + Δt·v`` with ``v ~ N(0, σ² I)``, so the
  position step has standard deviation ``σ·Δt`` per axis.
- :class:`ConstantVelocity` (nearly constant velocity, white-noise acceleration of spectral density
  ``q``, the same as Stone Soup's ``ConstantVelocity(noise_diff_coeff=q)``): per axis
  ``F = [[1, Δt], [0, 1]]`` and ``Q = q [[Δt³/3, Δt²/2], [Δt²/2, Δt]]`` (Bar-Shalom et al. 2001,
  §6.2.2). The state row is ``[x, y, (z,) vx, vy, (vz)]``.
- :class:`Static`: the identity map (paper 004's static targets).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def _position_dim(value: object) -> int:
    dim = checks.count("position_dim", value, least=1)
    if dim not in (1, 2, 3):
        raise InvalidInputError("position_dim", value, "must be 1, 2 or 3")
    return dim


def _dt(dt_s: float) -> float:
    return checks.non_negative("dt_s", dt_s)


def _states(states: FloatArray, state_dim: int) -> FloatArray:
    arr = np.asarray(states, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != state_dim:
        raise InvalidInputError("states", arr.shape, f"must have shape (N, {state_dim})")
    return arr


@dataclass(frozen=True)
class RandomWalk:
    """Gaussian random walk: each step adds ``Δt·v``, ``v ~ N(0, sigma_mps² I)``.

    Parameters
    ----------
    sigma_mps
        Standard deviation of the random velocity per axis (m/s), ``> 0``.
    position_dim
        2 on the ground plane, 3 in the air.
    """

    sigma_mps: float
    position_dim: int = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "sigma_mps", checks.positive("sigma_mps", self.sigma_mps))
        object.__setattr__(self, "position_dim", _position_dim(self.position_dim))

    @property
    def state_dim(self) -> int:
        """The state is the position only."""
        return self.position_dim

    def propagate(self, states: FloatArray, dt_s: float, rng: np.random.Generator) -> FloatArray:
        """New ``(N, d)`` states ``x + Δt·v``."""
        x = _states(states, self.state_dim)
        step = self.sigma_mps * _dt(dt_s)
        return x + step * rng.standard_normal(x.shape)


@dataclass(frozen=True)
class ConstantVelocity:
    """Nearly constant velocity with white-noise acceleration of spectral density ``q``.

    Parameters
    ----------
    q
        Acceleration noise spectral density (m²/s³) per axis, ``> 0``; Stone Soup's
        ``noise_diff_coeff``.
    position_dim
        2 on the ground plane (state ``[x, y, vx, vy]``), 3 in the air.
    """

    q: float
    position_dim: int = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", checks.positive("q", self.q))
        object.__setattr__(self, "position_dim", _position_dim(self.position_dim))

    @property
    def state_dim(self) -> int:
        """Position then velocity: ``2 · position_dim``."""
        return 2 * self.position_dim

    def transition_matrix(self, dt_s: float) -> FloatArray:
        """``(d, d)`` matrix ``F`` with ``x' = F x + noise``."""
        p, dt = self.position_dim, _dt(dt_s)
        f = np.eye(2 * p)
        f[:p, p:] = dt * np.eye(p)
        return f

    def noise_covariance(self, dt_s: float) -> FloatArray:
        """``(d, d)`` process noise covariance ``Q`` of one step of ``dt_s`` seconds."""
        p, dt = self.position_dim, _dt(dt_s)
        eye = np.eye(p)
        q = np.empty((2 * p, 2 * p))
        q[:p, :p] = dt**3 / 3.0 * eye
        q[:p, p:] = q[p:, :p] = dt**2 / 2.0 * eye
        q[p:, p:] = dt * eye
        return self.q * q

    def propagate(self, states: FloatArray, dt_s: float, rng: np.random.Generator) -> FloatArray:
        """New ``(N, d)`` states ``F x + w``, ``w ~ N(0, Q)`` (per-axis 2×2 Cholesky factor)."""
        p = self.position_dim
        x = _states(states, self.state_dim)
        dt = _dt(dt_s)
        out = np.empty_like(x)
        out[:, :p] = x[:, :p] + dt * x[:, p:]
        out[:, p:] = x[:, p:]
        if dt == 0.0:
            return out
        # Cholesky of q·[[dt³/3, dt²/2], [dt²/2, dt]]: [[a, 0], [b, c]].
        a = math.sqrt(self.q * dt**3 / 3.0)
        b = math.sqrt(3.0 * self.q * dt) / 2.0
        c = math.sqrt(self.q * dt / 4.0)
        e = rng.standard_normal((x.shape[0], 2 * p))
        out[:, :p] += a * e[:, :p]
        out[:, p:] += b * e[:, :p] + c * e[:, p:]
        return out


@dataclass(frozen=True)
class Static:
    """Targets that do not move: ``f(x' | x) = δ(x' − x)``."""

    position_dim: int = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "position_dim", _position_dim(self.position_dim))

    @property
    def state_dim(self) -> int:
        """The state is the position only."""
        return self.position_dim

    def propagate(self, states: FloatArray, dt_s: float, rng: np.random.Generator) -> FloatArray:
        """A copy of ``states``."""
        _dt(dt_s)
        return _states(states, self.state_dim).copy()
