"""Paper 004's experiment E7 (§5): the exploration planner's 3-D search waypoints flown by the
7-state UAV past three spheres.

The receding-horizon exploration planner (τ = 1, 12 m lattice moves, no filter: a target counts
as found at its first detection, as in the idealised benchmark) produces 3-D search waypoints;
the 7-state UAV flies them in NED with wind ``(3, 0, 0)`` m/s past three spheres, by default
with the closed-form backstepping law (eq. 13, obstacle term eqs. 14–15 with ``d_l = 6`` m,
``k_obs = 5``: the :class:`~searchtrack.plan.trajectory.ClosedFormGains` defaults).

The 004 planner ignores obstacles (§4.3: only the low-level controller avoids them), and their
placement in E7 is not given: here each sphere sits beside the planned path, its surface
``obstacle_standoff_m`` from the nearest path segment, so the avoidance term acts without a
waypoint lying inside an obstacle.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.range_sensor import RangeBearingElevationSensor
from searchtrack.models.vehicles import uav7
from searchtrack.plan.search import (
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    SearchSettings,
    solve,
)
from searchtrack.plan.trajectory import Obstacles, SampledPath
from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly
from searchtrack.sim.flight.routes import fixed_wing_path, polyline_distance_m, until_reference_end

log = logging.getLogger("searchtrack.sim.flight.e7")


@dataclasses.dataclass(frozen=True)
class E7Setup:
    """Experiment E7 of paper 004 (§5) as flown here.

    Parameters
    ----------
    steps
        Planner steps (200 in E7); each is one 12 m lattice move.
    targets
        Static targets, uniform in the box (E7's manual placement is not given).
    box_m
        The cube ``[lo, hi]³`` searched (planner frame, ``z`` up; flown in NED, down = −z).
    speed_mps
        Ground speed of the reference along horizontal legs.
    max_slope
        Largest climb or descent gradient of the reference (:func:`fixed_wing_path`).
    wind_mps
        True wind (NED), known to the controller.
    obstacle_radius_m, obstacle_standoff_m
        Sphere radius and the gap between its surface and the nearest planned leg.
    resolution_m
        Spacing of the exploration-bonus grid ι.
    """

    steps: int = 200
    targets: int = 12
    box_m: tuple[float, float] = (-20.0, 260.0)
    speed_mps: float = 15.0
    max_slope: float = 0.25
    wind_mps: tuple[float, float, float] = (3.0, 0.0, 0.0)
    obstacle_radius_m: float = 5.0
    obstacle_standoff_m: float = 3.0
    resolution_m: float = 10.0

    def __post_init__(self) -> None:
        checks.count("steps", self.steps, least=1)
        checks.count("targets", self.targets, least=1)
        lo, hi = (checks.real("box_m", v) for v in self.box_m)
        if not lo < 0.0 < hi:
            raise InvalidInputError("box_m", self.box_m, "must contain the start 0 (lo < 0 < hi)")
        for name in ("speed_mps", "max_slope", "obstacle_radius_m", "resolution_m"):
            checks.positive(name, getattr(self, name))
        checks.non_negative("obstacle_standoff_m", self.obstacle_standoff_m)
        checks.finite_array("wind_mps", self.wind_mps, (3,))


@dataclasses.dataclass(frozen=True)
class E7Flight:
    """One E7 run: the flight, the planner's NED waypoints, the flown reference, the
    obstacles, and the search outcome."""

    flight: FlightLog
    waypoints_m: FloatArray
    reference: SampledPath
    obstacles: Obstacles
    targets_found: int
    all_found_step: int | None


SENSOR_004 = RangeBearingElevationSensor(gain=0.98, fov_m=25.0, sigma=1.0)


def e7_waypoints(setup: E7Setup, rng: np.random.Generator) -> tuple[FloatArray, int, int | None]:
    """Run the exploration planner for ``setup.steps`` steps (filter-free, targets found at
    first detection); the ``(steps + 1, 3)`` planner-frame waypoints from the origin, the
    number of targets found and the step all were found (``None`` if not)."""
    gen = checks.generator("rng", rng)
    box = np.array([setup.box_m] * 3, dtype=np.float64)
    targets = gen.uniform(box[:, 0], box[:, 1], size=(setup.targets, 3))
    found = np.zeros(setup.targets, dtype=bool)
    bonus = ExplorationBonus(box, setup.resolution_m)
    settings = SearchSettings(step_m=12.0, horizon=1, refinement=NoRefinement())
    position = np.zeros(3)
    path, all_found = [position], None
    for k in range(setup.steps):
        found |= gen.random(setup.targets) < SENSOR_004.detection_probability(position, targets)
        if all_found is None and found.all():
            all_found = k
        bonus = bonus.updated(SENSOR_004, position)
        plan = solve(SearchProblem(position, box, bonus, SENSOR_004, settings)).plan
        if plan is None:  # a 12 m move always stays in a box that holds the start
            raise InvalidInputError("box_m", setup.box_m, "leaves no move inside the box")
        position = plan.waypoint
        path.append(position)
    return np.asarray(path, dtype=np.float64), int(found.sum()), all_found


def e7_obstacles(waypoints_m: FloatArray, setup: E7Setup, count: int = 3) -> Obstacles:
    """``count`` spheres spread along the (densely sampled) NED path, each centre offset
    sideways (horizontally, across the local leg) so that its surface is
    ``obstacle_standoff_m`` from the nearest leg; :class:`InvalidInputError` if there is no room.
    """
    path = checks.finite_array("waypoints_m", waypoints_m, (None, 3))
    r, gap = setup.obstacle_radius_m, setup.obstacle_standoff_m
    n = path.shape[0]
    centres: list[FloatArray] = []
    for j in range(1, count + 1):
        for i in [*range(j * n // (count + 1), n - 1), *range(j * n // (count + 1) - 1, 0, -1)]:
            lead = path[i + 1, :2] - path[i - 1, :2] if i > 0 else path[1, :2] - path[0, :2]
            if np.linalg.norm(lead) < 1e-9:
                continue
            side = np.array([-lead[1], lead[0]]) / np.linalg.norm(lead)
            options = [path[i] + np.array([*(s * (r + gap) * side), 0.0]) for s in (1.0, -1.0)]
            ok = [c for c in options if polyline_distance_m(c[None], path)[0] >= r + gap - 1e-6
                  and all(np.linalg.norm(c - o) > 2.0 * r + gap for o in centres)]
            if ok:
                centres.append(ok[0])
                break
    if len(centres) < count:
        raise InvalidInputError("waypoints_m", waypoints_m.shape,
                                f"no room for {count} obstacles beside the path")
    return Obstacles(centers_m=np.asarray(centres), radii_m=np.full(count, r),
                     cylinder=np.zeros(count, dtype=bool))


def fly_e7(seed: int, *, setup: E7Setup | None = None, config: FlightConfig | None = None
           ) -> E7Flight:
    """Plan E7's search waypoints with seed ``seed`` and fly them with the 7-state UAV.

    ``config`` defaults to the closed-form controller with the setup's wind (its ``wind_mps``
    is replaced by the setup's). The UAV starts at the origin at 15 m/s, heading π/4, level
    (004 §5).
    """
    s = E7Setup() if setup is None else setup
    gen = np.random.default_rng(checks.count("seed", seed))
    planned, found, all_found = e7_waypoints(s, gen)
    ned = planned * np.array([1.0, 1.0, -1.0])
    reference = fixed_wing_path(ned, s.speed_mps, s.max_slope)
    obstacles = e7_obstacles(reference.positions_m, s)
    cfg = FlightConfig(backend="closed_form") if config is None else config
    cfg = dataclasses.replace(until_reference_end(cfg, reference), wind_mps=s.wind_mps)
    start = np.array([0.0, 0.0, 0.0, 15.0, math.pi / 4.0, 0.0, 0.0])
    flight = fly(uav7(), start, reference, obstacles, cfg, rng=gen)
    log.info("E7 seed %d: %d/%d targets found, %d waypoints, min clearance %.2f m", seed, found,
             s.targets, ned.shape[0], flight.min_clearance_m)
    return E7Flight(flight, ned, reference, obstacles, found, all_found)
