"""Closed-loop multi-UAV search and tracking with the SMC-PHD filter in the loop (paper 003).

``R`` fixed-wing UAVs with downward cameras (003 eqs. 6–8, Poisson clutter) track taxi-like
vehicles driving on a synthetic road grid (:func:`~searchtrack.models.road_traces.taxi_traces`,
the stand-in for the Cabspotting data). Every step of ``dt_s`` seconds:

1. the vehicles move (ground truth from the traces); every UAV takes one image;
2. the SMC-PHD filter predicts with the learned GP velocity field or a Gaussian random walk
   (uniform grid births plus measurement-driven births) and updates with every image in turn;
3. each UAV gets its fixed-wing motion primitives over ``horizon`` steps (003 §2.3; primitives
   leaving the area are dropped) and 003's Algorithm 1 (greedy) assigns one per UAV maximising
   END (eq. 13) or binary MI (§2.5); the ``"lawnmower"`` baseline instead flies one
   boustrophedon at a fixed altitude with the UAVs spaced evenly along it;
4. the UAVs fly the first step of their plan (receding horizon).

Logged per step, as in 003's figures: expected count over true count, entropy per target
(eq. 15), the share of vehicles inside some image, the mean altitude, plus the OSPA of the
extracted estimates (not in 003). The GP is fitted on vehicles that are not the ground truth
(003's training/test split).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.particle_belief import ParticleBelief, WeightedParticles
from searchtrack.estimate.phd import (
    BirthGrid,
    PHDConfig,
    PHDState,
    SensorScan,
    entropy_per_target,
    extract,
    predict,
    resample,
    systematic_indices,
    update,
)
from searchtrack.models.camera import DownwardCamera
from searchtrack.models.gp_motion import GPMotion, GPVelocityField
from searchtrack.models.motion import RandomWalk
from searchtrack.models.particle_models import MotionModel
from searchtrack.models.road_synthetic import grid_network
from searchtrack.models.road_traces import TaxiModel, taxi_traces
from searchtrack.plan.assign import (
    AssignmentProblem,
    ExpectedDetections,
    FixedWingPrimitives,
    MutualInformation,
    Objective,
    fixed_wing_actions,
)
from searchtrack.plan.assign.greedy import solve_greedy
from searchtrack.plan.search import lawnmower_2d

__all__ = ["TRACK_PLANNERS", "TaxiWorld", "TrackConfig", "TrackEpisode", "run_track_episode",
           "taxi_world"]

log = logging.getLogger("searchtrack.sim.particles.tracking")

TrackPlanner = Literal["end", "mi", "lawnmower"]
TRACK_PLANNERS = ("end", "mi", "lawnmower")


def _primitives() -> FixedWingPrimitives:
    return FixedWingPrimitives(speeds_mps=(15.0,), yaw_rates_rps=(-0.2, -0.1, 0.0, 0.1, 0.2),
                               pitch_rates_rps=(-0.08, 0.0, 0.08), steps=1, step_s=5.0,
                               euler_dt_s=0.1, z_min_m=20.0, z_max_m=150.0, max_pitch_rad=0.4)


@dataclass(frozen=True)
class TrackConfig:
    """One paper-003 episode (this library's scale: a 300 m road grid, 5 s steps; 003 gives no
    sensor or control constants).

    Parameters
    ----------
    planner
        ``"end"``, ``"mi"`` or ``"lawnmower"``.
    motion
        Filter motion model: ``"gp"`` (learned) or ``"random_walk"``.
    robots
        Number of UAVs ``R ≥ 1`` (003: 2, 4, 6).
    horizon
        Steps per action ``T ≥ 1`` (``R·T ≤ 12`` keeps the binary MI exact, as in 003).
    steps
        Episode length in steps, ``≥ 1``.
    dt_s
        Seconds per step ``D`` (003: 5).
    n_targets, n_training
        Ground-truth vehicles and the vehicles the GP is fitted on, ``≥ 1``.
    blocks, block_m
        The road grid: ``blocks × blocks`` intersections ``block_m`` apart.
    one_way_fraction
        Share of one-way streets (what gives the traffic a learnable direction).
    walk_sigma_mps
        Per-axis velocity spread of the random-walk model (m/s), ``> 0``.
    particles
        Initial uniform particles; ``max_particles`` caps the filter, ``plan_particles`` the
        belief handed to the planner (a systematic subsample).
    lawnmower_altitude_m, lawnmower_spacing_m
        The baseline's fixed altitude and line spacing (m).
    min_separation_m
        Collision pruning distance between UAVs (m), ``≥ 0``.
    camera, primitives
        The sensor and the fixed-wing control grid (``primitives.steps`` is set to
        ``horizon``).
    """

    planner: TrackPlanner = "end"
    motion: Literal["gp", "random_walk"] = "gp"
    robots: int = 2
    horizon: int = 2
    steps: int = 60
    dt_s: float = 5.0
    n_targets: int = 20
    n_training: int = 60
    blocks: int = 4
    block_m: float = 100.0
    one_way_fraction: float = 0.5
    walk_sigma_mps: float = 6.0
    particles: int = 2000
    max_particles: int = 8000
    plan_particles: int = 800
    lawnmower_altitude_m: float = 60.0
    lawnmower_spacing_m: float = 60.0
    min_separation_m: float = 10.0
    camera: DownwardCamera = field(default_factory=lambda: DownwardCamera(sigma_px=20.0))
    primitives: FixedWingPrimitives = field(default_factory=_primitives)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if self.planner not in TRACK_PLANNERS:
            raise InvalidInputError("planner", self.planner, f"must be one of {TRACK_PLANNERS}")
        if self.motion not in ("gp", "random_walk"):
            raise InvalidInputError("motion", self.motion, "must be 'gp' or 'random_walk'")
        for name, least in (("robots", 1), ("horizon", 1), ("steps", 1), ("n_targets", 1),
                            ("n_training", 1), ("blocks", 2), ("particles", 1),
                            ("max_particles", 1), ("plan_particles", 1)):
            set_(self, name, checks.count(name, getattr(self, name), least))
        for name in ("dt_s", "block_m", "walk_sigma_mps", "lawnmower_altitude_m",
                     "lawnmower_spacing_m"):
            set_(self, name, checks.positive(name, getattr(self, name)))
        set_(self, "one_way_fraction",
             checks.real("one_way_fraction", self.one_way_fraction, low=0.0, high=1.0))
        set_(self, "min_separation_m", checks.non_negative("min_separation_m",
                                                             self.min_separation_m))
        if not isinstance(self.camera, DownwardCamera):
            raise InvalidInputError("camera", self.camera, "must be a DownwardCamera")
        if not isinstance(self.primitives, FixedWingPrimitives):
            raise InvalidInputError("primitives", self.primitives, "must be FixedWingPrimitives")

    @property
    def area(self) -> FloatArray:
        """``(2, 2)`` ground area (m): the road grid."""
        side = (self.blocks - 1) * self.block_m
        return np.array([[0.0, side], [0.0, side]])

    def phd(self) -> PHDConfig:
        """Filter settings: survival 0.99, uniform grid births plus measurement births."""
        return PHDConfig(survival_probability=0.99, birth_mass=0.3,
                         birth_particles_per_measurement=200, birth_position_sigma_m=5.0,
                         birth_grid=BirthGrid.uniform(self.area, 0.2, 200),
                         particles_per_target=400, max_particles=self.max_particles,
                         min_particles=200, merge_radius_m=10.0, region=self.area)


@dataclass(frozen=True, eq=False)
class TaxiWorld:
    """Ground truth ``(steps + 1, n, 2)`` vehicle positions and the GP fitted on other vehicles
    (``None`` when the configuration does not use it)."""

    truth: FloatArray
    field: GPVelocityField | None


def taxi_world(config: TrackConfig, seed: int) -> TaxiWorld:
    """Taxi traces on the road grid (training and truth vehicles share the one-way streets) and,
    for ``motion="gp"``, the GP velocity field fitted on the training vehicles; deterministic for
    a seed."""
    seed = checks.count("seed", seed, 0)
    rng = np.random.default_rng([seed, 2])
    net = grid_network(config.blocks, config.blocks, block_m=config.block_m,
                       spacing_m=config.block_m / 10.0)
    n = config.n_targets + config.n_training
    duration = max(config.steps + 1, 2) * config.dt_s
    traces = taxi_traces(net, n, duration, config.dt_s, rng,
                         TaxiModel(one_way_fraction=config.one_way_fraction))
    truth_ids = np.arange(config.n_training, n)
    sub = traces.select(truth_ids)
    per = sub.xy_m.shape[0] // config.n_targets
    truth = sub.xy_m.reshape(config.n_targets, per, 2)[:, : config.steps + 1]
    gp = None
    if config.motion == "gp":
        x, v = traces.select(np.arange(config.n_training)).velocities()
        gp = GPVelocityField.fit(x, v, rng, bounds=config.area, n_hyper=200)
    return TaxiWorld(np.ascontiguousarray(truth.transpose(1, 0, 2)), gp)


@dataclass(frozen=True, eq=False)
class TrackEpisode:
    """Per-step metrics of one episode (arrays of length ``steps``) and mean timings (ms)."""

    count_ratio: FloatArray
    entropy: FloatArray
    in_view: FloatArray
    ospa_m: FloatArray
    altitude_m: FloatArray
    planner_ms: float
    filter_ms: float

    def __post_init__(self) -> None:
        if self.planner_ms < 0.0 or self.filter_ms < 0.0:
            raise InvalidInputError("planner_ms", (self.planner_ms, self.filter_ms),
                                    "times must be >= 0")
        for arr in (self.count_ratio, self.entropy, self.in_view, self.ospa_m, self.altitude_m):
            arr.setflags(write=False)

    def tail_mean(self, name: str) -> float:
        """Mean of a metric over the second half of the episode (after the transient)."""
        values = np.asarray(getattr(self, name), dtype=np.float64)
        return float(np.nanmean(values[values.shape[0] // 2:]))


def _motion(config: TrackConfig, world: TaxiWorld) -> MotionModel:
    if config.motion == "gp":
        if world.field is None:
            raise InvalidInputError("world", "no GP field", "motion='gp' needs a fitted field")
        return GPMotion(world.field)
    return RandomWalk(config.walk_sigma_mps, position_dim=2)


def _candidates(states: FloatArray, config: TrackConfig) -> list[FloatArray]:
    """Each UAV's primitives whose poses stay over the area (all of them if none does)."""
    prim = replace(config.primitives, steps=config.horizon)
    area = config.area
    out = []
    for s in states:
        acts = fixed_wing_actions(s, prim)
        xy = acts[:, :, :2]
        inside = np.all((xy >= area[:, 0]) & (xy <= area[:, 1]), axis=(1, 2))
        if not inside.any():
            centre = area.mean(axis=1)
            inside = np.linalg.norm(xy[:, -1] - centre, axis=1) == np.min(
                np.linalg.norm(xy[:, -1] - centre, axis=1))
        out.append(acts[inside])
    return out


def _plan(state: PHDState, uavs: FloatArray, config: TrackConfig,
          rng: np.random.Generator) -> FloatArray:
    """Next ``(R, 5)`` UAV states from greedy assignment on a subsample of the belief."""
    belief: ParticleBelief = state
    w = state.weights
    if state.n_particles > config.plan_particles and w.sum() > 0.0:
        idx = systematic_indices(w, config.plan_particles, rng)
        belief = WeightedParticles(state.positions[idx],
                                   np.full(config.plan_particles, w.sum() / config.plan_particles))
    acts = _candidates(uavs, config)
    objective: Objective = (MutualInformation(clutter_rate=config.camera.clutter_rate)
                            if config.planner == "mi" else ExpectedDetections())
    problem = AssignmentProblem(tuple(acts), belief, config.camera, objective=objective,
                                min_separation_m=config.min_separation_m)
    result = solve_greedy(problem, time_limit_s=30.0)
    if result.plan is None:  # no collision-free joint plan: fly each UAV's first primitive
        return np.stack([a[0, 0] for a in acts])
    return np.asarray(result.plan.poses[:, 0], dtype=np.float64)


def _lawnmower_poses(path: FloatArray, k: int, robots: int) -> FloatArray:
    """``(R, 5)`` poses of UAVs spaced evenly along the closed lawnmower ``path`` at step k."""
    n = path.shape[0]
    idx = (k + np.arange(robots) * n // robots) % n
    heading = path[(idx + 1) % n, :2] - path[idx, :2]
    yaw = np.arctan2(heading[:, 1], heading[:, 0])
    return np.column_stack([path[idx], yaw, np.zeros(robots)])


def _start(config: TrackConfig) -> FloatArray:
    """UAVs start spread along the south edge at 40 m, heading north."""
    side = config.area[0, 1]
    x = (np.arange(config.robots) + 0.5) * side / config.robots
    return np.column_stack([x, np.full(config.robots, 0.05 * side),
                            np.full(config.robots, 40.0), np.full(config.robots, np.pi / 2),
                            np.zeros(config.robots)])


def run_track_episode(config: TrackConfig, world: TaxiWorld, seed: int) -> TrackEpisode:
    """Run one closed-loop 003 episode on ``world`` (from :func:`taxi_world`); deterministic
    for a seed."""
    seed = checks.count("seed", seed, 0)
    if world.truth.shape[0] < config.steps + 1 or world.truth.shape[1] != config.n_targets:
        raise InvalidInputError("world", world.truth.shape,
                                f"must hold ({config.steps + 1}, {config.n_targets}, 2) truth")
    rng = np.random.default_rng([seed, 3])
    area, cam, phd, motion = config.area, config.camera, config.phd(), _motion(config, world)
    init = rng.uniform(area[:, 0], area[:, 1], size=(config.particles, 2))
    state = PHDState.from_particles(init, np.full(config.particles,
                                                  config.n_targets / config.particles))
    path = lawnmower_2d(area, config.lawnmower_spacing_m, config.lawnmower_altitude_m,
                        config.primitives.speeds_mps[0] * config.dt_s)
    uavs = _lawnmower_poses(path, 0, config.robots) if config.planner == "lawnmower" \
        else _start(config)
    rows: list[tuple[float, float, float, float, float]] = []
    t_plan = t_filter = 0.0
    for k in range(config.steps):
        truth = world.truth[k + 1]
        t0 = time.perf_counter()
        scans = [SensorScan(cam, q[:4], cam.measure(q[:4], truth, rng)[0]) for q in uavs]
        state = update(predict(state, motion, phd, config.dt_s, rng), scans, phd)
        estimates = extract(state, phd)
        state = resample(state, phd, rng)
        t1 = time.perf_counter()
        seen = np.zeros(config.n_targets, dtype=bool)
        for q in uavs:
            seen |= cam.detection_probability(q[:4], truth) > 0.0
        rows.append((state.expected_count() / config.n_targets,
                     entropy_per_target(state, area, 10.0), float(seen.mean()),
                     ospa(estimates.positions, truth, c=50.0, p=1.0), float(uavs[:, 2].mean())))
        t2 = time.perf_counter()
        if config.planner == "lawnmower":
            uavs = _lawnmower_poses(path, k + 1, config.robots)
        else:
            uavs = _plan(state, uavs, config, rng)
        t_plan += time.perf_counter() - t2
        t_filter += t1 - t0
    m = np.array(rows)
    log.info("track %s R=%d T=%d %s seed %d: count ratio %.2f", config.planner, config.robots,
             config.horizon, config.motion, seed, m[-1, 0])
    return TrackEpisode(m[:, 0], m[:, 1], m[:, 2], m[:, 3], m[:, 4],
                        1e3 * t_plan / config.steps, 1e3 * t_filter / config.steps)
