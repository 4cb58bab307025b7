"""The ``trajectory`` family of ``searchtrack plan``: a vehicle flies a waypoint course past
obstacles in closed loop with a trajectory controller; the plan is the flown states and inputs.

PROBLEM.json::

    {"vehicle": "unicycle",
     "waypoints": [[0, 0], [120, 0], [120, 80]],
     "speed_mps": 10.0,
     "obstacles": [{"center": [60, 2], "radius_m": 8, "cylinder": true}],
     "start": [0, 0, 0],
     "duration_s": 26.0, "dt_s": 0.2, "horizon": 15,
     "safety_margin_m": 1.0, "goal_tolerance_m": 10.0}

* ``vehicle``: a vehicle model of :mod:`searchtrack.models.vehicles` with its default limits:
  ``"unicycle"`` (2-D, states ``x_m, y_m, heading_rad``), ``"fixed_wing"`` (3-D, ``x_m, y_m,
  z_m, yaw_rad, pitch_rad``, altitude 0–50 m) or ``"uav7"`` (3-D NED, ``north_m, east_m,
  down_m, airspeed_mps, heading_rad, flight_path_rad, roll_rad``: ``z`` is *down*).
* ``waypoints``: ≥ 2 points with the vehicle's number of position axes (2 or 3), none inside an
  obstacle; the course is the polyline through them flown at ``speed_mps`` (> 0), the timed
  reference :func:`~searchtrack.plan.trajectory.waypoint_path`.
* ``obstacles`` (optional): ``center`` has 2 or 3 numbers, ``radius_m`` > 0, ``cylinder``
  (default true) a vertical cylinder, else a sphere; a 2-D vehicle sees every one as a cylinder.
* ``start`` (optional): the initial state, a list of all state values or an object keyed by
  state names (missing ones from the default); default: on the first waypoint, heading along the
  first leg, level, at ``speed_mps`` (``uav7``'s airspeed, clipped to its box). It must lie
  outside every obstacle.
* ``duration_s`` (default: the course's duration at ``speed_mps``), ``dt_s`` (control period,
  default 0.2), ``horizon`` (MPC stages, default 15), ``safety_margin_m`` (clearance the
  controllers keep, default 1), ``goal_tolerance_m`` (default 10).

:func:`solve` flies the course with :func:`searchtrack.sim.flight.loop.fly`. ``time_limit_s`` is the
whole flight's controller budget, split evenly over the control steps (the one-off NMPC build of
a new problem shape is not counted). Status: ``FEASIBLE`` when the flight stays clear of every
obstacle and ends within ``goal_tolerance_m`` of the last waypoint, ``INTERRUPTED`` with the
flight so far when a stop request ends it early, else ``NO_SOLUTION`` carrying the flight as a
fallback. Objective (minimised): the RMS tracking error (m) against the
timed reference; no bound. ``stats`` counts the steps each controller answered (``steps_<name>``)
and the fallbacks fired.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.deadline import check_time_limit
from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import read_json
from searchtrack.core.intervals import interval_count
from searchtrack.core.registry import check_seed
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.plan.trajectory import BACKENDS as BACKENDS
from searchtrack.plan.trajectory import Obstacles, SampledPath, waypoint_path
from searchtrack.sim.export.plans import VehiclePaths
from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly
from searchtrack.sim.kernels import kernels_of
from searchtrack.sim.toml_fields import MAX_MAGNITUDE, Table

DESCRIPTION = "fly a waypoint course past obstacles in closed loop (NMPC / LTV-MPC / closed form)"
KERNELS = kernels_of(BACKENDS)

VEHICLES: dict[str, Callable[[], VehicleModel]] = {
    "unicycle": unicycle, "fixed_wing": fixed_wing, "uav7": uav7}

#: Largest PROBLEM.json read (bytes), waypoint count and number of control steps.
MAX_PROBLEM_BYTES = 16 * 2**20
MAX_WAYPOINTS = 10_000
MAX_STEPS = 100_000


@dataclass(frozen=True)
class TrajectoryProblem:
    """A validated PROBLEM.json: the vehicle, its start, the course, obstacles, flight settings."""

    model: VehicleModel
    start: FloatArray
    waypoints_m: FloatArray
    speed_mps: float
    obstacles: Obstacles
    duration_s: float
    dt_s: float
    horizon: int
    safety_margin_m: float
    goal_tolerance_m: float

    @property
    def reference(self) -> SampledPath:
        """The course flown at ``speed_mps`` from time 0."""
        return waypoint_path(self.waypoints_m, self.speed_mps)

    @property
    def steps(self) -> int:
        """Number of control steps of the flight."""
        return interval_count(self.duration_s, self.dt_s)


def backends() -> list[str]:
    """The trajectory controllers, ``auto`` first."""
    return BACKENDS.names()


def _point(table: Table, value: Any, name: str, sizes: tuple[int, ...]) -> FloatArray:
    """A list of ``sizes`` finite numbers within ±MAX_MAGNITUDE (``name`` is relative)."""
    if (not isinstance(value, list) or len(value) not in sizes
            or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
        raise table.fail(name, f"must be a list of {' or '.join(map(str, sizes))} numbers, "
                               f"got {value!r}")
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > MAX_MAGNITUDE):
        raise table.fail(name, f"must be finite numbers within ±{MAX_MAGNITUDE:g}, got {value!r}")
    return arr


def _list(table: Table, name: str, *, required: bool, most: int) -> list[Any]:
    value = table.raw(name, None if required else [])
    if value is None:
        raise table.fail(name, "missing list")
    if not isinstance(value, list) or len(value) > most:
        raise table.fail(name, f"must be a list of at most {most} entries")
    return value


def _obstacles(top: Table, path: Path) -> Obstacles:
    centers, radii, flags = [], [], []
    for i, raw in enumerate(_list(top, "obstacles", required=False, most=MAX_WAYPOINTS)):
        if not isinstance(raw, dict):
            raise top.fail(f"obstacles[{i}]", "must be an object with center and radius_m")
        t = Table(raw, path, top.key(f"obstacles[{i}]"))
        c = _point(t, t.raw("center"), "center", (2, 3))
        centers.append(np.append(c, 0.0) if c.size == 2 else c)
        radii.append(t.number("radius_m", positive=True))
        flags.append(t.boolean("cylinder", True))
        t.done()
    return Obstacles(np.reshape(centers, (-1, 3)), np.asarray(radii, dtype=float),
                     np.asarray(flags, dtype=bool))


def _default_start(model: VehicleModel, waypoints: FloatArray, speed_mps: float) -> FloatArray:
    x = np.zeros(model.nx)
    x[list(model.position_indices)] = waypoints[0]
    lead = waypoints[1] - waypoints[0]
    x[model.angle_indices[0]] = math.atan2(lead[1], lead[0])
    if "airspeed_mps" in model.state_names:
        i = model.state_names.index("airspeed_mps")
        x[i] = float(np.clip(speed_mps, model.state_lower[i], model.state_upper[i]))
    return x


def _start(top: Table, path: Path, model: VehicleModel, default: FloatArray) -> FloatArray:
    raw = top.raw("start")
    if raw is None:
        start = default
    elif isinstance(raw, dict):
        t = Table(raw, path, "start")
        start = default.copy()
        for i, name in enumerate(model.state_names):
            if t.has(name):
                start[i] = t.number(name)
            else:
                t.raw(name)  # listed as known in the unknown-key message
        t.done()
    else:
        start = _point(top, raw, "start", (model.nx,))
    try:
        return model.check_state("start", start)
    except InvalidInputError as exc:
        raise top.fail("start", exc.reason) from None


def _inside(obstacles: Obstacles, point: FloatArray) -> int | None:
    """Index of an obstacle containing ``point`` (on the surface counts), else ``None``."""
    if obstacles.k == 0:
        return None
    d = obstacles.distance_m(point[None, :])[0]
    return int(np.argmin(d)) if np.min(d) <= 0.0 else None


def read_problem(path: str | Path) -> TrajectoryProblem:
    """Read and validate PROBLEM.json (the format is in the module docstring).

    Raises
    ------
    ParseError
        Naming the file and the dotted key at fault (``waypoints[2][1]``,
        ``obstacles[0].radius_m``, ``start``, ...).
    """
    p = Path(path)
    raw = read_json(p, max_bytes=MAX_PROBLEM_BYTES)
    if not isinstance(raw, dict):
        raise ParseError(p, None, None, "the top level must be a JSON object")
    top = Table(raw, p)
    model = VEHICLES[top.string("vehicle", choices=VEHICLES)]()
    dim = model.n_wind
    wps = _list(top, "waypoints", required=True, most=MAX_WAYPOINTS)
    waypoints = np.asarray([_point(top, w, f"waypoints[{i}]", (dim,))
                            for i, w in enumerate(wps)]).reshape(-1, dim)
    if waypoints.shape[0] < 2 or np.all(np.linalg.norm(waypoints - waypoints[0], axis=1) < 1e-9):
        raise top.fail("waypoints", "needs at least 2 distinct waypoints")
    speed = top.number("speed_mps", positive=True, maximum=1e3)
    obstacles = _obstacles(top, p)
    for i, w in enumerate(waypoints):
        j = _inside(obstacles, w)
        if j is not None:
            raise top.fail(f"waypoints[{i}]", f"lies inside obstacles[{j}]")
    start = _start(top, p, model, _default_start(model, waypoints, speed))
    j = _inside(obstacles, model.position(start))
    if j is not None:
        raise top.fail("start", f"lies inside obstacles[{j}]")
    course_s = waypoint_path(waypoints, speed).duration_s
    duration = top.number("duration_s", course_s, positive=True)
    dt = top.number("dt_s", 0.2, positive=True, maximum=10.0)
    if duration / dt > MAX_STEPS:
        raise top.fail("duration_s", f"needs more than {MAX_STEPS} control steps of {dt:g} s")
    problem = TrajectoryProblem(
        model=model, start=start, waypoints_m=waypoints, speed_mps=speed, obstacles=obstacles,
        duration_s=duration, dt_s=dt, horizon=top.integer("horizon", 15, minimum=1),
        safety_margin_m=top.number("safety_margin_m", 1.0, minimum=0.0),
        goal_tolerance_m=top.number("goal_tolerance_m", 10.0, positive=True))
    if problem.horizon > 200:
        raise top.fail("horizon", f"must be ≤ 200, got {problem.horizon}")
    top.done()
    return problem


def solve(problem: TrajectoryProblem, *, backend: str, time_limit_s: float,
          seed: int) -> Result[FlightLog]:
    """Fly the course in closed loop with controller ``backend``.

    Parameters
    ----------
    problem
        The validated problem.
    backend
        One of :func:`backends`.
    time_limit_s
        The whole flight's controller budget, ``time_limit_s / steps`` per control step.
    seed
        Unused (the flight is noise-free and the controllers deterministic).

    Raises
    ------
    InvalidInputError
        Unknown backend, bad time limit or seed.
    """
    budget = check_time_limit(time_limit_s)
    check_seed(seed)
    BACKENDS.get(backend)
    per_step = budget / problem.steps if math.isfinite(budget) else 1.0
    config = FlightConfig(backend=backend, dt_s=problem.dt_s, horizon=problem.horizon,
                          time_limit_s=per_step, duration_s=problem.duration_s,
                          safety_margin_m=problem.safety_margin_m)
    began = time.perf_counter()
    flight = fly(problem.model, problem.start, problem.reference, problem.obstacles, config,
                 rng=np.random.default_rng(seed))
    runtime = time.perf_counter() - began
    final = _final_distance_m(problem, flight)
    answered = Counter(flight.controllers)
    stats = {f"steps_{name}": float(n) for name, n in sorted(answered.items())}
    stats.update(steps=float(len(flight.controllers)), fallbacks=float(flight.fallbacks),
                 final_distance_m=final)
    mix = ", ".join(f"{name} {n}" for name, n in answered.most_common())
    note = (f"flew {len(flight.controllers)} steps ({mix}), {flight.fallbacks} fallbacks, "
            f"ended {final:.1f} m from the last waypoint")
    if flight.collisions:
        status, note = Status.NO_SOLUTION, f"crashed into an obstacle; {note}"
    elif flight.interrupted:
        status = Status.INTERRUPTED
        note = f"interrupted after {len(flight.controllers)} of {problem.steps} steps; {note}"
    elif final > problem.goal_tolerance_m:
        status = Status.NO_SOLUTION
        note = f"missed the last waypoint (tolerance {problem.goal_tolerance_m:g} m); {note}"
    else:
        status = Status.FEASIBLE
    return Result(status, flight.rms_error_m, None, runtime, backend, flight,
                  sense=Sense.MINIMIZE, message=note, stats=stats)


def _final_distance_m(problem: TrajectoryProblem, flight: FlightLog) -> float:
    end = problem.model.position(flight.states[-1])
    return float(np.linalg.norm(end - problem.waypoints_m[-1]))


def _rows(values: FloatArray) -> list[list[float]]:
    return [[float(v) for v in row] for row in np.atleast_2d(values)]


def plan_json(problem: TrajectoryProblem, result: Result[FlightLog]) -> dict[str, Any]:
    """The ``plan`` object: the flown ``times_s``, ``states`` and ``inputs`` (with their
    names), the closest obstacle approach, the tracking error, the controllers that answered
    and the fallbacks; ``{"vehicle": ..., "flown": false}`` without a flight."""
    m, flight = problem.model, result.plan
    if flight is None:
        return {"vehicle": m.name, "flown": False}
    clear = flight.clearance_m
    closest = int(np.argmin(clear))
    obstacle = None
    if problem.obstacles.k:
        dist = problem.obstacles.distance_m(m.position(flight.states[closest])[None, :])[0]
        obstacle = int(np.argmin(dist))
    err = flight.tracking_error_m
    final = _final_distance_m(problem, flight)
    return {
        "vehicle": m.name,
        "flown": True,
        "state_names": list(m.state_names),
        "input_names": list(m.input_names),
        "times_s": [float(t) for t in flight.times_s],
        "states": _rows(flight.states),
        "inputs": _rows(flight.inputs) if flight.inputs.size else [],
        "controllers": list(flight.controllers),
        "controller_steps": dict(Counter(flight.controllers)),
        "fallbacks": flight.fallbacks,
        "min_clearance_m": float(clear[closest]) if obstacle is not None else None,
        "closest_obstacle": obstacle,
        "closest_time_s": float(flight.times_s[closest]) if obstacle is not None else None,
        "collisions": flight.collisions,
        "rms_error_m": flight.rms_error_m,
        "max_error_m": float(np.max(err)),
        "final_distance_m": final,
        "reached_goal": final <= problem.goal_tolerance_m and not flight.collisions,
        "solve_s_mean": float(np.mean(flight.solve_s)) if flight.solve_s.size else 0.0,
        "solve_s_max": float(np.max(flight.solve_s)) if flight.solve_s.size else 0.0,
    }


def figure(problem: TrajectoryProblem, result: Result[FlightLog], path: Path) -> Path | None:
    """Top view of the course, the obstacles (with the safety margin dashed) and the flown path,
    written as a PNG; ``None`` without a flight."""
    flight = result.plan
    if flight is None:
        return None
    from matplotlib.patches import Circle

    from searchtrack.sim.figure_style import pyplot, save_png

    plt = pyplot()

    fig, ax = plt.subplots(figsize=(7, 6))
    try:
        wp = problem.waypoints_m
        ax.plot(wp[:, 0], wp[:, 1], "k--o", lw=1, ms=4, label="course")
        for c, r in zip(problem.obstacles.centers_m, problem.obstacles.radii_m, strict=True):
            ax.add_patch(Circle((c[0], c[1]), r, color="r", alpha=0.3))
            ax.add_patch(Circle((c[0], c[1]), r + problem.safety_margin_m, fill=False,
                                    ec="r", ls=":", lw=0.8))
        pos = flight.states[:, list(problem.model.position_indices)]
        ax.plot(pos[:, 0], pos[:, 1], "b-", lw=1.5, label=f"flown ({result.backend})")
        ax.plot(pos[0, 0], pos[0, 1], "g^", ms=8, label="start")
        ax.plot(pos[-1, 0], pos[-1, 1], "bs", ms=6, label="end")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)" if problem.model.n_wind == 2 else "x / north (m)")
        ax.set_ylabel("y (m)" if problem.model.n_wind == 2 else "y / east (m)")
        ax.set_title(f"{problem.model.name}: {result.status.value}, "
                     f"rms {flight.rms_error_m:.2f} m")
        ax.legend(loc="best")
        return save_png(fig, Path(path))
    except BaseException:
        plt.close(fig)
        raise


def vehicle_paths(problem: TrajectoryProblem, result: Result[FlightLog]) -> VehiclePaths:
    """The vehicle's flown ground track (its position entries' first two)."""
    if result.plan is None:
        raise ValueError("vehicle_paths needs a result with a plan")
    where = result.plan.states[:, list(problem.model.position_indices)]
    return VehiclePaths((where[:, :2],))
