"""A vehicle model: named states and inputs, box bounds, input-rate limits and dynamics ``ẋ = f``.

The dynamics ``f(x, u, p, ns)`` are written once against an :class:`ArrayNamespace` and evaluated
from NumPy (here) or from CasADi (``searchtrack.plan.trajectory.symbolic``); ``p`` is the wind
vector (one component per position axis, m/s). :func:`rk4_step` is generic in the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles.namespace import NUMPY, ArrayNamespace


class Dynamics(Protocol):
    """``ẋ = f(x, u, p)`` over an array namespace (hashable, so models can key solver caches)."""

    def __call__(self, x: Any, u: Any, p: Any, ns: ArrayNamespace) -> Any: ...


def rk4_step(dynamics: Dynamics, x: Any, u: Any, p: Any, dt_s: float | Any,
             ns: ArrayNamespace = NUMPY) -> Any:
    """One classical Runge–Kutta step of ``dt_s`` seconds with ``u`` and ``p`` held."""
    k1 = dynamics(x, u, p, ns)
    k2 = dynamics(x + 0.5 * dt_s * k1, u, p, ns)
    k3 = dynamics(x + 0.5 * dt_s * k2, u, p, ns)
    k4 = dynamics(x + dt_s * k3, u, p, ns)
    return x + dt_s / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _bounds(name: str, value: tuple[float, ...], size: int) -> tuple[float, ...]:
    if len(value) != size or any(not isinstance(v, (int, float)) or math.isnan(v) for v in value):
        raise InvalidInputError(name, value, f"must be {size} numbers (±inf allowed, no NaN)")
    return tuple(float(v) for v in value)


@dataclass(frozen=True)
class VehicleModel:
    """A controlled vehicle ``ẋ = f(x, u, wind)`` with box bounds (SI units, angles in radians).

    Parameters
    ----------
    name
        Short name, e.g. ``"unicycle"``.
    state_names, input_names
        One name (with unit) per state and per input.
    dynamics
        ``f(x, u, p, ns)``; ``p`` is the wind vector, one entry per position axis.
    state_lower, state_upper
        Box on the states (``±inf`` for none); the controllers keep predictions inside it.
    input_lower, input_upper
        Box on the inputs.
    input_rate_max
        Largest ``|u̇|`` per input (units/s), ``inf`` for none.
    nominal_input
        The input of steady cruise, used as the effort reference and the first guess.
    position_indices
        The states that are the position (2 or 3 of them, in x, y[, z] order).
    angle_indices
        The states that are angles which may wrap (headings).
    """

    name: str
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    dynamics: Dynamics
    state_lower: tuple[float, ...]
    state_upper: tuple[float, ...]
    input_lower: tuple[float, ...]
    input_upper: tuple[float, ...]
    input_rate_max: tuple[float, ...]
    nominal_input: tuple[float, ...]
    position_indices: tuple[int, ...]
    angle_indices: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        nx, nu = len(self.state_names), len(self.input_names)
        if nx == 0 or nu == 0:
            raise InvalidInputError("state_names", self.state_names, "needs states and inputs")
        set_ = object.__setattr__
        for field, size in (("state_lower", nx), ("state_upper", nx), ("input_lower", nu),
                            ("input_upper", nu), ("input_rate_max", nu)):
            set_(self, field, _bounds(field, getattr(self, field), size))
        for lo, hi in (("state_lower", "state_upper"), ("input_lower", "input_upper")):
            if any(a > b for a, b in zip(getattr(self, lo), getattr(self, hi), strict=True)):
                raise InvalidInputError(lo, getattr(self, lo), f"must not exceed {hi}")
        if any(r <= 0 for r in self.input_rate_max):
            raise InvalidInputError("input_rate_max", self.input_rate_max, "must be > 0")
        nominal = _bounds("nominal_input", self.nominal_input, nu)
        if not np.all(self.clip_input(nominal) == np.asarray(nominal)):
            raise InvalidInputError("nominal_input", nominal, "must lie within the input bounds")
        set_(self, "nominal_input", nominal)
        if len(self.position_indices) not in (2, 3) or not set(self.position_indices) <= set(
                range(nx)):
            raise InvalidInputError("position_indices", self.position_indices,
                                    f"must be 2 or 3 state indices in [0, {nx})")
        if not set(self.angle_indices) <= set(range(nx)):
            raise InvalidInputError("angle_indices", self.angle_indices, "must be state indices")

    @property
    def nx(self) -> int:
        """Number of states."""
        return len(self.state_names)

    @property
    def nu(self) -> int:
        """Number of inputs."""
        return len(self.input_names)

    @property
    def n_wind(self) -> int:
        """Length of the wind vector ``p`` (the number of position axes)."""
        return len(self.position_indices)

    def f(self, x: ArrayLike, u: ArrayLike, wind_mps: ArrayLike | None = None) -> FloatArray:
        """``ẋ`` (NumPy) for states ``(nx,)`` or ``(nx, batch)`` and matching inputs."""
        p = np.zeros(self.n_wind) if wind_mps is None else np.asarray(wind_mps, dtype=float)
        out = self.dynamics(np.asarray(x, dtype=float), np.asarray(u, dtype=float), p, NUMPY)
        return np.asarray(out, dtype=np.float64)

    def step(self, x: ArrayLike, u: ArrayLike, dt_s: float, wind_mps: ArrayLike | None = None,
             *, substeps: int = 1) -> FloatArray:
        """``x`` advanced ``dt_s`` s by ``substeps`` RK4 steps with ``u`` held (not clipped)."""
        n = checks.count("substeps", substeps, least=1)
        h = checks.positive("dt_s", dt_s) / n
        p = np.zeros(self.n_wind) if wind_mps is None else np.asarray(wind_mps, dtype=float)
        state, inp = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        for _ in range(n):
            state = rk4_step(self.dynamics, state, inp, p, h)
        return np.asarray(state, dtype=np.float64)

    def clip_input(self, u: ArrayLike) -> FloatArray:
        """``u`` clipped to the input box."""
        return np.asarray(np.clip(np.asarray(u, dtype=float), self.input_lower, self.input_upper),
                          dtype=np.float64)

    def position(self, x: ArrayLike) -> FloatArray:
        """The position entries of state(s) ``x`` (rows ``position_indices``)."""
        return np.asarray(np.asarray(x, dtype=float)[list(self.position_indices)])

    def check_state(self, field: str, x: ArrayLike) -> FloatArray:
        """``x`` as a read-only ``(nx,)`` array, or :class:`InvalidInputError` when it is not finite
        or lies outside the state box."""
        arr = checks.finite_array(field, x, (self.nx,))
        bad = [self.state_names[i] for i in range(self.nx)
               if not self.state_lower[i] <= arr[i] <= self.state_upper[i]]
        if bad:
            raise InvalidInputError(field, arr.tolist(), f"outside the state bounds in {bad}")
        return arr

    def check_input(self, field: str, u: ArrayLike) -> FloatArray:
        """``u`` as a read-only ``(nu,)`` array, or :class:`InvalidInputError` when not finite or
        outside the input box."""
        arr = checks.finite_array(field, u, (self.nu,))
        if np.any(arr < np.asarray(self.input_lower) - 1e-9) or np.any(
                arr > np.asarray(self.input_upper) + 1e-9):
            raise InvalidInputError(field, arr.tolist(), "outside the input bounds")
        return arr
