"""Closed-loop flight: a trajectory controller flying the true vehicle model along a reference.

Every ``dt_s`` the controller is asked for a plan from the measured state (exact, no estimation
error) with the wind it assumes; the first input (clipped to the actuator box) is applied to the
true model, which integrates with the true wind and additive Gaussian process noise
``σ √dt`` per state. The log records tracking error, inputs, obstacle clearance, solve times and
the controller that answered each step (so fallbacks can be counted). A stop request
(:mod:`searchtrack.core.interrupt`) ends the flight before the next step; the log then holds the
steps flown and says it was interrupted.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.trajectory import (
    ControlPlan,
    NmpcOptions,
    Obstacles,
    Reference,
    TrackingProblem,
    TrackingWeights,
    solve,
)
from searchtrack.sim.figure_style import pyplot, save_png

log = logging.getLogger("searchtrack.sim.flight.loop")



@dataclass(frozen=True)
class FlightConfig:
    """How a closed-loop flight runs.

    Parameters
    ----------
    backend
        Trajectory controller (``"auto"``, ``"nmpc"``, ``"ltv_mpc"``, ``"closed_form"``).
    dt_s
        Control period and stage length (s).
    horizon
        MPC horizon (stages).
    time_limit_s
        Per-step solve budget (s).
    duration_s
        Flight length (s); ``None``: the reference's duration plus 2 s.
    wind_mps
        True wind (m/s), one per position axis; ``None``: calm.
    wind_known
        Whether the controller is told the true wind (else it assumes calm air).
    process_noise
        Standard deviation per state of the process noise (units per √s); ``None``: none.
    safety_margin_m
        Clearance the controllers keep around obstacles.
    weights
        Tracking cost weights.
    nmpc_options
        NMPC build/solve options (e.g. ``NmpcOptions(jit=True)``); ``None``: the defaults.
    """

    backend: str = "auto"
    dt_s: float = 0.1
    horizon: int = 20
    time_limit_s: float = 0.05
    duration_s: float | None = None
    wind_mps: tuple[float, ...] | None = None
    wind_known: bool = True
    process_noise: tuple[float, ...] | None = None
    safety_margin_m: float = 1.0
    weights: TrackingWeights = field(default_factory=TrackingWeights)
    nmpc_options: NmpcOptions | None = None

    def __post_init__(self) -> None:
        checks.positive("dt_s", self.dt_s)
        checks.count("horizon", self.horizon, least=1)
        checks.positive("time_limit_s", self.time_limit_s)
        if self.duration_s is not None:
            checks.positive("duration_s", self.duration_s)
        checks.non_negative("safety_margin_m", self.safety_margin_m)


@dataclass(frozen=True)
class FlightLog:
    """What happened in one closed-loop flight (``T`` control steps).

    ``states`` is ``(T + 1, nx)``, ``inputs`` ``(T, nu)`` (as commanded, before actuator
    clipping), ``reference_m`` ``(T + 1, dim)``, ``clearance_m`` ``(T + 1,)`` to the nearest
    obstacle surface, ``solve_s`` ``(T,)`` and ``controllers`` the backend that answered each step
    (``"none"`` when a single backend found no plan and the next input of its last plan was
    applied). A flight that
    enters an obstacle stops there: ``collisions`` is then 1. ``interrupted``: a stop request
    ended the flight before its duration.
    """

    model: VehicleModel
    times_s: FloatArray
    states: FloatArray
    inputs: FloatArray
    reference_m: FloatArray
    clearance_m: FloatArray
    solve_s: FloatArray
    controllers: tuple[str, ...]
    fallbacks: int
    interrupted: bool = False

    @property
    def tracking_error_m(self) -> FloatArray:
        """``(T + 1,)`` distance between the vehicle and the reference."""
        pos = self.states[:, list(self.model.position_indices)]
        return np.asarray(np.linalg.norm(pos - self.reference_m, axis=1), dtype=np.float64)

    @property
    def rms_error_m(self) -> float:
        """Root-mean-square tracking error (m)."""
        return float(np.sqrt(np.mean(self.tracking_error_m**2)))

    @property
    def input_effort(self) -> float:
        """Mean of ``‖(u − u_nom)/range‖²`` over the steps (dimensionless)."""
        m = self.model
        width = np.asarray(m.input_upper) - np.asarray(m.input_lower)
        scale = np.where(np.isfinite(width) & (width > 0), width, 1.0)
        dev = (self.inputs - np.asarray(m.nominal_input)) / scale
        return float(np.mean(np.sum(dev**2, axis=1)))

    @property
    def collisions(self) -> int:
        """Number of logged states inside an obstacle."""
        return int(np.count_nonzero(self.clearance_m < 0.0))

    @property
    def min_clearance_m(self) -> float:
        """Smallest clearance to any obstacle (m; ``inf`` without obstacles)."""
        return float(np.min(self.clearance_m))

    @property
    def state_violations(self) -> int:
        """Logged states outside the model's state box (beyond 1e-6 relative): the true model
        is not clipped, only the state the controllers are given."""
        m = self.model
        lo, hi = np.asarray(m.state_lower), np.asarray(m.state_upper)
        tol = 1e-6 * np.maximum(1.0, np.abs(np.where(np.isfinite(hi), hi, 0.0)))
        out = (self.states < lo - tol) | (self.states > hi + tol)
        return int(np.count_nonzero(out.any(axis=1)))

    def count(self, controller: str) -> int:
        """Steps answered by ``controller``."""
        return sum(1 for c in self.controllers if c == controller)


def fly(
    model: VehicleModel,
    start: ArrayLike,
    reference: Reference,
    obstacles: Obstacles | None = None,
    config: FlightConfig | None = None,
    *,
    rng: np.random.Generator,
) -> FlightLog:
    """Fly ``model`` from ``start`` along ``reference`` in closed loop.

    Raises
    ------
    InvalidInputError
        A start outside the state box or inside an obstacle, bad wind or noise sizes.
    """
    cfg = FlightConfig() if config is None else config
    gen = checks.generator("rng", rng)
    obs = Obstacles() if obstacles is None else obstacles
    wind = _vector("wind_mps", cfg.wind_mps, model.n_wind)
    noise = _vector("process_noise", cfg.process_noise, model.nx)
    x = np.array(model.check_state("start", start))
    obs.check_outside("start", model.position(x))
    duration = cfg.duration_s if cfg.duration_s is not None else reference.duration_s + 2.0
    steps = max(1, int(np.ceil(duration / cfg.dt_s - 1e-9)))
    states, inputs, solve_s, who = [x.copy()], [], [], []
    u_prev = np.asarray(model.nominal_input, dtype=float)
    warm: ControlPlan | None = None
    last: ControlPlan | None = None
    age, fallbacks = 0, 0
    stopped = False
    lo, hi = np.asarray(model.state_lower), np.asarray(model.state_upper)
    for k in range(steps):
        t = k * cfg.dt_s
        if obs.k and obs.clearance_m(model.position(x)[None, :])[0] <= 0.0:
            log.warning("flight %s via %s crashed into an obstacle at t = %.1f s", model.name,
                        cfg.backend, t)
            break
        if stop_requested():
            log.info("flight %s via %s stopped on request at t = %.1f s", model.name,
                     cfg.backend, t)
            stopped = True
            break
        problem = TrackingProblem(
            model, np.clip(x, lo, hi), reference, time_s=t, obstacles=obs, horizon=cfg.horizon,
            dt_s=cfg.dt_s, previous_input=u_prev,
            wind_mps=wind if cfg.wind_known else np.zeros(model.n_wind),
            safety_margin_m=cfg.safety_margin_m, weights=cfg.weights, warm=warm,
            nmpc_options=cfg.nmpc_options)
        result = solve(problem, backend=cfg.backend, time_limit_s=cfg.time_limit_s)
        if result.plan is None:  # a single backend without an answer: follow the last plan
            age += 1
            u = u_prev if last is None else last.inputs[min(age, last.inputs.shape[0] - 1)]
            warm = _stale(last, age)
            who.append("none")
        else:
            u, warm, last, age = result.plan.first_input, result.plan, result.plan, 0
            who.append(result.backend)
        fallbacks += int(result.stats.get("fallbacks", 0.0))
        solve_s.append(result.runtime_s)
        inputs.append(np.asarray(u, dtype=float))
        u_prev = model.clip_input(u)
        x = model.step(x, u_prev, cfg.dt_s, wind)
        if np.any(noise > 0):
            x = x + gen.normal(0.0, 1.0, model.nx) * noise * np.sqrt(cfg.dt_s)
        states.append(x.copy())
    times = np.asarray(cfg.dt_s * np.arange(len(states)), dtype=np.float64)
    traj = np.asarray(states)
    flown = FlightLog(model=model, times_s=times, states=traj,
                      inputs=np.asarray(inputs).reshape(-1, model.nu),
                      reference_m=reference.positions(times),
                      clearance_m=obs.clearance_m(traj[:, list(model.position_indices)]),
                      solve_s=np.asarray(solve_s), controllers=tuple(who), fallbacks=fallbacks,
                      interrupted=stopped)
    log.info("flight %s via %s: rms %.2f m, min clearance %.2f m, %d fallbacks", model.name,
             cfg.backend, flown.rms_error_m, flown.min_clearance_m, fallbacks)
    return flown


def _stale(plan: ControlPlan | None, age: int) -> ControlPlan | None:
    """``plan`` made ``age`` steps ago, cut so that the usual one-stage shift lines it up with
    now (a warm start after a failed solve); ``None`` once it is used up."""
    if plan is None or age >= plan.inputs.shape[0]:
        return None
    return ControlPlan(inputs=plan.inputs[age - 1:], states=plan.states[age - 1:],
                       dt_s=plan.dt_s, controller=plan.controller)


def _vector(name: str, value: tuple[float, ...] | None, size: int) -> FloatArray:
    if value is None:
        return np.zeros(size)
    arr = checks.finite_array(name, value, (size,))
    if name == "process_noise" and np.any(arr < 0):
        raise InvalidInputError(name, value, "standard deviations must be ≥ 0")
    return np.asarray(arr, dtype=np.float64)


def plot_flight(flight: FlightLog, path: str | Path, obstacles: Obstacles | None = None,
                *, title: str = "") -> Path:
    """Top view of the flown path beside the reference (obstacles as circles), saved as a PNG;
    a 3-D flight gets a second panel, altitude against time (``−down`` for the NED ``uav7``)."""
    plt = pyplot()
    out = Path(path)
    pos = flight.states[:, list(flight.model.position_indices)]
    three_d = pos.shape[1] == 3
    fig, axes = plt.subplots(1, 2 if three_d else 1, figsize=(11 if three_d else 6, 6),
                             squeeze=False)
    ax = axes[0, 0]
    try:
        ax.plot(flight.reference_m[:, 0], flight.reference_m[:, 1], "k--", lw=1, label="reference")
        ax.plot(pos[:, 0], pos[:, 1], "b-", lw=1.5, label="flown")
        if obstacles is not None:
            for c, r in zip(obstacles.centers_m, obstacles.radii_m, strict=True):
                ax.add_patch(plt.Circle((c[0], c[1]), r, color="r", alpha=0.3))
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(title or f"{flight.model.name}: rms {flight.rms_error_m:.2f} m")
        ax.legend(loc="best")
        if three_d:
            up = -1.0 if flight.model.name == "uav7" else 1.0
            side = axes[0, 1]
            side.plot(flight.times_s, up * flight.reference_m[:, 2], "k--", lw=1,
                      label="reference")
            side.plot(flight.times_s, up * pos[:, 2], "b-", lw=1.5, label="flown")
            side.set_xlabel("time (s)")
            side.set_ylabel("altitude (m)")
            side.legend(loc="best")
    except BaseException:
        plt.close(fig)
        raise
    return save_png(fig, out, dpi=100)
