"""One tracking problem: a vehicle at a state, a reference, obstacles, a horizon; and its plan."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.trajectory.obstacles import Obstacles
from searchtrack.plan.trajectory.options import NmpcOptions
from searchtrack.plan.trajectory.reference import Reference


@dataclass(frozen=True)
class TrackingWeights:
    """Cost weights shared by NMPC and the QP.

    ``position`` (1/m²) weighs ``‖p_k − r_k‖²`` at stages 1..N−1, ``terminal`` at stage N;
    ``effort`` weighs ``‖(u − u_nom)/range‖²`` and ``rate`` ``‖(u_k − u_{k−1})/range‖²``.
    """

    position: float = 1.0
    terminal: float = 5.0
    effort: float = 0.5
    rate: float = 2.0

    def __post_init__(self) -> None:
        for name in ("position", "terminal", "effort", "rate"):
            checks.non_negative(name, getattr(self, name))


@dataclass(frozen=True)
class TrackingProblem:
    """What a trajectory controller is asked at one instant.

    Parameters
    ----------
    model
        The vehicle.
    state
        Current state ``(nx,)``; must be finite, inside the state box and outside every obstacle.
    reference
        The reference position ``r(t)`` (same number of axes as the model's position).
    time_s
        Current time; stage ``k`` tracks ``r(time_s + k dt_s)``.
    obstacles
        Obstacles kept at ``safety_margin_m`` or more.
    horizon
        Number of stages ``N`` ≥ 1.
    dt_s
        Stage length (s).
    previous_input
        The input applied last step (for rate limits); default the nominal input.
    wind_mps
        The wind the controller assumes (m/s), one per position axis; default zero.
    safety_margin_m
        Extra clearance required around each obstacle (m).
    weights
        Cost weights.
    warm
        The previous plan, shifted by one stage for a warm start (``None``: cold start).
    nmpc_options
        How NMPC builds and solves its NLP (``None``: the defaults); ignored by the others.
    """

    model: VehicleModel
    state: FloatArray
    reference: Reference
    time_s: float = 0.0
    obstacles: Obstacles = field(default_factory=Obstacles)
    horizon: int = 20
    dt_s: float = 0.1
    previous_input: FloatArray | None = None
    wind_mps: FloatArray | None = None
    safety_margin_m: float = 1.0
    weights: TrackingWeights = field(default_factory=TrackingWeights)
    warm: ControlPlan | None = None
    nmpc_options: NmpcOptions | None = None

    def __post_init__(self) -> None:
        m = self.model
        set_ = object.__setattr__
        state = m.check_state("state", self.state)
        set_(self, "state", state)
        set_(self, "horizon", checks.count("horizon", self.horizon, least=1))
        set_(self, "dt_s", checks.positive("dt_s", self.dt_s))
        set_(self, "time_s", checks.real("time_s", self.time_s))
        set_(self, "safety_margin_m", checks.non_negative("safety_margin_m",
                                                           self.safety_margin_m))
        if self.reference.dim != m.n_wind:
            raise InvalidInputError("reference", self.reference.dim,
                                    f"must have {m.n_wind} position axes like model {m.name!r}")
        prev = m.nominal_input if self.previous_input is None else self.previous_input
        set_(self, "previous_input", m.check_input("previous_input", prev))
        wind = np.zeros(m.n_wind) if self.wind_mps is None else self.wind_mps
        set_(self, "wind_mps", checks.finite_array("wind_mps", wind, (m.n_wind,)))
        self.obstacles.check_outside("state", m.position(state))
        if self.warm is not None and (self.warm.inputs.shape[1] != m.nu
                                      or self.warm.states.shape[1] != m.nx):
            raise InvalidInputError("warm", self.warm.inputs.shape, f"not a plan for {m.name!r}")

    @property
    def u_prev(self) -> FloatArray:
        """The previous input (validated)."""
        assert self.previous_input is not None
        return self.previous_input

    @property
    def wind(self) -> FloatArray:
        """The assumed wind (validated)."""
        assert self.wind_mps is not None
        return self.wind_mps

    def reference_positions(self) -> FloatArray:
        """``(N, dim)`` reference positions of stages 1..N."""
        times = self.time_s + self.dt_s * np.arange(1, self.horizon + 1)
        return self.reference.positions(times)

    def input_range(self) -> FloatArray:
        """Width of each input's box (1 where unbounded), the effort normaliser."""
        width = np.asarray(self.model.input_upper) - np.asarray(self.model.input_lower)
        return np.where(np.isfinite(width) & (width > 0), width, 1.0)


@dataclass(frozen=True)
class ControlPlan:
    """A controller's answer: the inputs of the next ``N`` stages and the predicted states.

    ``inputs`` is ``(N, nu)``; ``states`` is ``(N + 1, nx)`` starting at the problem's state.
    ``multipliers`` warm-start the controller that made the plan: NMPC's ``(λ_x, λ_g)``, the
    QP's ``(primal, dual)`` of ``ltv_mpc`` (``None`` from the closed form).
    """

    inputs: FloatArray
    states: FloatArray
    dt_s: float
    controller: str
    multipliers: tuple[FloatArray, FloatArray] | None = None

    def __post_init__(self) -> None:
        u = np.asarray(self.inputs, dtype=float)
        x = np.asarray(self.states, dtype=float)
        if u.ndim != 2 or x.ndim != 2 or x.shape[0] != u.shape[0] + 1 or u.shape[0] < 1:
            raise InvalidInputError("inputs", (u.shape, x.shape),
                                    "need inputs (N, nu) and states (N + 1, nx), N ≥ 1")
        if not (np.all(np.isfinite(u)) and np.all(np.isfinite(x))):
            raise InvalidInputError("inputs", "non-finite", "plans must be finite")
        u.setflags(write=False)
        x.setflags(write=False)
        object.__setattr__(self, "inputs", u)
        object.__setattr__(self, "states", x)
        object.__setattr__(self, "dt_s", checks.positive("dt_s", self.dt_s))

    @property
    def first_input(self) -> FloatArray:
        """The input to apply now."""
        return np.asarray(self.inputs[0])


def initial_guess(problem: TrackingProblem) -> tuple[FloatArray, FloatArray]:
    """``(X (N+1, nx), U (N, nu))`` to start from: the warm plan shifted by one stage (last stage
    repeated), else the nominal input rolled out from the state; angles aligned with the state
    by whole turns, so a wrapped heading does not look like a full turn."""
    m, n = problem.model, problem.horizon
    warm = problem.warm
    if warm is not None and warm.inputs.shape[0] >= 1:
        u_old, x_old = warm.inputs, warm.states
        idx = np.minimum(np.arange(1, n + 1), u_old.shape[0] - 1)
        u = np.asarray(u_old[idx], dtype=float)
        x = np.asarray(x_old[np.minimum(np.arange(1, n + 2), x_old.shape[0] - 1)], dtype=float)
        x[0] = problem.state
        for i in m.angle_indices:
            x[1:, i] += 2.0 * math.pi * np.round((problem.state[i] - x[1, i]) / (2.0 * math.pi))
        u = m.clip_input(u)
    else:
        u = np.tile(np.asarray(m.nominal_input), (n, 1))
        x = np.empty((n + 1, m.nx))
        x[0] = problem.state
        for k in range(n):
            x[k + 1] = m.step(x[k], u[k], problem.dt_s, problem.wind)
    lo, hi = np.asarray(m.state_lower), np.asarray(m.state_upper)
    return np.clip(x, lo, hi), u


def project_inputs(problem: TrackingProblem, inputs: FloatArray) -> FloatArray:
    """``inputs`` ``(N, nu)`` moved, stage by stage, into the input box and the rate limits
    around the previous stage's input (removes solver-tolerance violations)."""
    m = problem.model
    step = np.asarray(m.input_rate_max) * problem.dt_s
    out = np.empty_like(np.asarray(inputs, dtype=float))
    last = problem.u_prev
    for k in range(out.shape[0]):
        last = m.clip_input(np.clip(inputs[k], last - step, last + step))
        out[k] = last
    return out
