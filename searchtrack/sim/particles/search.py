"""Closed-loop 3-D search with the SMC-PHD filter in the loop (paper 004, Algorithm 1).

One UAV searches a box for static point targets. Every step ``k``:

1. sense once at the current position with the range–bearing–elevation sensor (detection
   probability ``π`` of eq. 1, noisy ``[d, θ, ϖ]`` of eq. 2, optional Poisson clutter);
2. drop, for each found target, its closest measurement within the gate (lines 9–12; see
   below for the gate);
3. run the SMC-PHD filter (static targets, measurement-driven birth) with what is left (line 15);
4. cluster the posterior by weighted k-means; clusters with radius ``≤ T_r`` and mass ``≥ T_m``
   are saved as found and their particles deleted (lines 1–7, done here right after the update
   and before resampling, which is the start of the next step in the paper's numbering);
5. update the exploration bonus ``ι`` (eq. 9) and plan the next waypoint (eq. 8):

   - ``"proposed"``: ``α E + T`` (exploration + refinement, T = centre probabilities or MI),
     the ``receding`` backend of :mod:`searchtrack.plan.search`;
   - ``"refinement"``: refinement only (``α = 0``), 004's MI-only style baseline;
   - ``"lawnmower"``: the 3-D layered boustrophedon, flown one waypoint per step from the start.

A true target counts as *found* once a saved estimate lies within ``match_m`` of it (004 does not
say how found targets are matched to true ones); saved estimates farther than that from every
target are *false*. The episode ends when every target is found or after ``max_steps`` steps.
Thresholds: 004 prints ``T_r = 1.1 m``, ``T_m = 2.2``, ``T_z = 5 m``; a cluster mass of 2.2 needs
a much larger birth mass than this filter's. With this filter a repeatedly seen target carries a
mass near ``1/π ≈ 1``, so the default ``T_m`` here is 0.7 (set ``found=FoundConfig(mass=2.2)`` to
use the printed value). With ``PHDConfig(adaptive_birth=True, birth_mass=1)`` a measurement no
particle explains seeds one unit and one that a particle explains seeds nothing. A static target
then carries ``m' = (1 − π) m + 1`` after a scan that detects it and ``(1 − π) m`` after a miss,
so its mass averages 1. Right after a detection it is at least 1, and after a miss it is below 1
whenever ``π > 1/2``: ``T_m = 1`` is the threshold derived for that birth.

The gate of step 2 is 4 standard deviations of the innovation ``z − h(x̂)`` (sensor noise plus
a position uncertainty ``T_z / 4`` of the found target ``x̂``), not 004's printed ball of
``T_z = 5`` m, which it equals at short range (see :mod:`searchtrack.estimate.phd.found`). With
``σ_θ = 0.02`` rad the position noise is 2–4 m per axis at 100–200 m, where the faint field of
view still detects found targets: in three lawnmower runs 14 % of the found targets' detections
left the 5 m ball, each adding a unit of mass at a found target; the rebuilt peaks were saved
again or, displaced, as false targets, and made up most of the upward drift of the expected
count plus saved estimates (18.1 after 400 steps for 12 targets). The innovation gate let none
through and the count stayed near 12 (``benchmarks/phd_count_drift.py``).

The centres ``x̂_i`` of the refinement term (eq. 11) are those of k-means clusters that together
cover every particle group carrying at least ``cover_mass``: the ``round(λ)`` clusters of the
found-target test, plus one more cluster seeded at the heaviest particle left outside them while
the particles outside carry ``cover_mass`` or more. 004's k-means partitions all particles, so
every group of the PHD has a centre in eq. (11). The ``round(λ)`` trimmed clusters alone leave
whole groups out: with ``λ ≈ 1.4`` and two groups 370 m apart only the group holding the heaviest
particle had a centre, the group the UAV approached lost weight by ``(1 − π)`` and the other took
the centre, so the refinement goal jumped between the two each step and the UAV oscillated
between two waypoints half-way, where ``ι ≈ 0`` (up to half the steps of the slow episodes).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd import (
    Clusters,
    FoundConfig,
    PHDConfig,
    PHDState,
    SensorScan,
    gate_found,
    kmeans_clusters,
    mark_found,
    predict,
    resample,
    update,
)
from searchtrack.models.motion import Static
from searchtrack.models.range_sensor import RangeBearingElevationSensor
from searchtrack.plan.search import (
    CentreProbability,
    EmptyHorizonMI,
    ExplorationBonus,
    SearchProblem,
    SearchSettings,
    lawnmower_3d,
    solve,
)

__all__ = ["PLANNERS", "SearchConfig", "SearchEpisode", "run_search_episode"]

log = logging.getLogger("searchtrack.sim.particles.search")

SearchPlanner = Literal["proposed", "refinement", "lawnmower"]
PLANNERS = ("proposed", "refinement", "lawnmower")


def _box_004() -> FloatArray:
    return np.array([[-20.0, 260.0]] * 3)


def _sensor_004() -> RangeBearingElevationSensor:
    return RangeBearingElevationSensor(gain=0.98, fov_m=25.0, sigma=(1.0, 0.02, 0.02))


def _phd_004() -> PHDConfig:
    return PHDConfig(survival_probability=1.0, birth_mass=0.5,
                     birth_particles_per_measurement=500, birth_position_sigma_m=1.0,
                     particles_per_target=500, max_particles=5000, min_particles=100,
                     extraction="kmeans", kmeans_seed_radius_m=8.0)


@dataclass(frozen=True)
class SearchConfig:
    """One paper-004 search episode (defaults: 004's simulation where it gives a value).

    Parameters
    ----------
    planner
        ``"proposed"``, ``"refinement"`` or ``"lawnmower"``.
    bounds
        ``(3, 2)`` search box (m); 004: ``[−20, 260]³``.
    n_targets
        Number of static targets, uniform in the box, ``≥ 1`` (004: 12).
    max_steps
        Step cap, ``≥ 1`` (004: 812, the lawnmower's length).
    horizon
        Planner horizon ``τ`` in ``[1, 5]`` (004 compares 1, 2, 3).
    alpha
        Exploration weight ``α ≥ 0`` of the proposed planner (004 gives no value; 1 here).
    refinement
        The refinement term: :class:`~searchtrack.plan.search.CentreProbability` (eq. 11) or
        :class:`~searchtrack.plan.search.EmptyHorizonMI`.
    step_m
        Lattice move length (m), ``> 0`` (004: 12).
    bonus_resolution_m
        Spacing of the ``ι`` grid (m), ``> 0`` (004 gives none).
    lawnmower_spacing_m
        Line and layer spacing of the lawnmower (m), ``> 0`` (004: 48).
    match_m
        A saved estimate within this distance (m) of a true target finds it, ``> 0``.
    start
        ``(3,)`` initial UAV position (004: the origin).
    sensor
        The ranging sensor (004: ``G = 0.98``, ``F = 25 m``; 004 gives no noise ``σ``).
    phd
        SMC-PHD settings (p_s = 1, measurement-driven birth, k-means extraction, ≤ 5000
        particles as in 004).
    found
        ``T_r``, ``T_m``, ``T_z`` and the gate (see the module docstring for ``T_m`` and the
        gate; ``gate_sigmas=0`` gives the printed ``T_z`` ball).
    min_distinct
        Distinct particle positions a cluster needs to be saved as found, ``≥ 1``. Static
        particles are only copied by resampling, and without clutter a measurement's unit of mass
        lands on whichever few copies explain it best, however far: such a cluster is narrow and
        heavy but is one or two stale hypotheses, not a localised target.
    cover_mass
        Particles outside every cluster get one more centre for the refinement term while they
        carry at least this expected number of targets, ``> 0`` (see the module docstring).
    """

    planner: SearchPlanner = "proposed"
    bounds: FloatArray = field(default_factory=_box_004)
    n_targets: int = 12
    max_steps: int = 812
    horizon: int = 1
    alpha: float = 1.0
    refinement: CentreProbability | EmptyHorizonMI = field(default_factory=CentreProbability)
    step_m: float = 12.0
    bonus_resolution_m: float = 10.0
    lawnmower_spacing_m: float = 48.0
    match_m: float = 5.0
    start: FloatArray = field(default_factory=lambda: np.zeros(3))
    sensor: RangeBearingElevationSensor = field(default_factory=_sensor_004)
    phd: PHDConfig = field(default_factory=_phd_004)
    found: FoundConfig = field(default_factory=lambda: FoundConfig(1.1, 0.7, 5.0, 4.0))
    min_distinct: int = 10
    cover_mass: float = 0.1

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if self.planner not in PLANNERS:
            raise InvalidInputError("planner", self.planner, f"must be one of {PLANNERS}")
        b = np.array(self.bounds, dtype=np.float64)
        if b.shape != (3, 2) or not np.all(np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
            raise InvalidInputError("bounds", self.bounds, "must be (3, 2) with low < high")
        b.setflags(write=False)
        set_(self, "bounds", b)
        set_(self, "n_targets", checks.count("n_targets", self.n_targets, 1))
        set_(self, "max_steps", checks.count("max_steps", self.max_steps, 1))
        if not isinstance(self.horizon, int) or not 1 <= self.horizon <= 5:
            raise InvalidInputError("horizon", self.horizon, "must be an integer in [1, 5]")
        set_(self, "alpha", checks.non_negative("alpha", self.alpha))
        if not isinstance(self.refinement, (CentreProbability, EmptyHorizonMI)):
            raise InvalidInputError("refinement", self.refinement,
                                    "must be CentreProbability() or EmptyHorizonMI()")
        set_(self, "min_distinct", checks.count("min_distinct", self.min_distinct, 1))
        set_(self, "cover_mass", checks.positive("cover_mass", self.cover_mass))
        for name in ("step_m", "bonus_resolution_m", "lawnmower_spacing_m", "match_m"):
            set_(self, name, checks.positive(name, getattr(self, name)))
        s = np.array(self.start, dtype=np.float64).reshape(-1)
        if s.shape != (3,) or not np.all((s >= b[:, 0]) & (s <= b[:, 1])):
            raise InvalidInputError("start", self.start, "must be a point [x, y, z] in bounds")
        s.setflags(write=False)
        set_(self, "start", s)
        for name, kind in (("sensor", RangeBearingElevationSensor), ("phd", PHDConfig),
                           ("found", FoundConfig)):
            if not isinstance(getattr(self, name), kind):
                raise InvalidInputError(name, getattr(self, name), f"must be a {kind.__name__}")

    def lawnmower_route(self) -> FloatArray:
        """The 3-D lawnmower's waypoints over :attr:`bounds` (the ``lawnmower`` planner's path,
        and the default cap of an episode's length)."""
        return lawnmower_3d(np.array(self.bounds), self.lawnmower_spacing_m,
                            self.lawnmower_spacing_m, self.step_m)

    def settings(self) -> SearchSettings:
        """The planner settings this episode uses (``α = 0`` for refinement only)."""
        alpha = 0.0 if self.planner == "refinement" else self.alpha
        return SearchSettings(step_m=self.step_m, horizon=self.horizon, alpha=alpha,
                              refinement=self.refinement, dims=3,
                              lawnmower_spacing_m=self.lawnmower_spacing_m)


@dataclass(frozen=True, eq=False)
class SearchEpisode:
    """What one search episode did.

    Attributes
    ----------
    steps_to_find_all
        First step (1-based) after which every target was found; ``max_steps + 1`` if never.
    found_per_step
        ``(K,)`` true targets found after each step (``K ≤ max_steps`` steps were run).
    false_found
        Saved estimates not within ``match_m`` of any target.
    rmse_m
        RMS distance from each found target to its nearest saved estimate (``nan`` if none).
    planner_ms, filter_ms
        Mean wall time per step of the planner (with the ``ι`` update) and of sensing, gating,
        filter and found-target bookkeeping (ms).
    targets, estimates, path
        ``(n, 3)`` true targets, ``(m, 3)`` saved estimates, ``(K + 1, 3)`` UAV positions.
    """

    steps_to_find_all: int
    found_per_step: NDArray[np.int64]
    false_found: int
    rmse_m: float
    planner_ms: float
    filter_ms: float
    targets: FloatArray
    estimates: FloatArray
    path: FloatArray

    def __post_init__(self) -> None:
        if self.planner_ms < 0.0 or self.filter_ms < 0.0:
            raise InvalidInputError("planner_ms", (self.planner_ms, self.filter_ms),
                                    "times must be >= 0")
        for arr in (self.found_per_step, self.targets, self.estimates, self.path):
            arr.setflags(write=False)

    @property
    def finished(self) -> bool:
        """Whether every target was found within the cap."""
        return bool(self.found_per_step.size) and int(self.found_per_step[-1]) == \
            self.targets.shape[0]


def _matches(targets: FloatArray, estimates: FloatArray, match_m: float) -> tuple[
        NDArray[np.bool_], NDArray[np.bool_], FloatArray]:
    """Targets with an estimate within ``match_m``, estimates near a target, and the distance
    from each target to its nearest estimate."""
    if estimates.shape[0] == 0:
        return (np.zeros(targets.shape[0], dtype=bool), np.zeros(0, dtype=bool),
                np.full(targets.shape[0], np.inf))
    d = np.linalg.norm(targets[:, None, :] - estimates[None, :, :], axis=2)
    return d.min(axis=1) <= match_m, d.min(axis=0) <= match_m, d.min(axis=1)


def _filter_step(state: PHDState, found: FloatArray, z: FloatArray, position: FloatArray,
                 config: SearchConfig, rng: np.random.Generator) -> tuple[
                     PHDState, FloatArray, FloatArray]:
    """Gate, predict, update, mark found, resample; also returns the cluster centres left."""
    sensor = config.sensor
    z = z[gate_found(found, sensor, position, z, config.found)]
    state = predict(state, Static(3), config.phd, 1.0, rng)
    state = update(state, [SensorScan(sensor, position, z)], config.phd)
    lam = state.expected_count()
    k = max(round(lam), 1) if lam > 0.25 else 0
    clusters = kmeans_clusters(state, k, config.phd)
    masses = clusters.masses.copy()
    for i in np.flatnonzero(clusters.radii_m <= config.found.radius_m):
        members = state.positions[clusters.members == i]
        if np.unique(members, axis=0).shape[0] < config.min_distinct:
            masses[i] = 0.0
    solid = replace(clusters, masses=masses)
    updated = state
    state, found = mark_found(state, solid, config.found, found)
    kept = clusters if state is updated else None  # nothing found: the same PHD, same k-means
    return resample(state, config.phd, rng), found, _refinement_centres(state, k, config, kept)


def _refinement_centres(state: PHDState, k: int, config: SearchConfig,
                        clusters: Clusters | None = None) -> FloatArray:
    """``(c, 3)`` centres of k-means clusters (``k`` or more) covering every particle group of
    at least ``cover_mass``: eq. (11)'s ``x̂_i``, on the PHD left after the found-target test
    (``clusters``: its ``k``-means when already known)."""
    while True:
        if clusters is None:
            clusters = kmeans_clusters(state, k, config.phd)
        outside = clusters.members < 0
        if k >= state.n_particles or state.weights[outside].sum() < config.cover_mass:
            return clusters.centres[clusters.masses > 0.0, :3]
        k, clusters = k + 1, None


def run_search_episode(config: SearchConfig, seed: int) -> SearchEpisode:
    """Run Algorithm 1 of paper 004 in closed loop with the SMC-PHD filter; deterministic for a
    seed (the target map depends on the seed only, so planners compare on the same maps)."""
    seed = checks.count("seed", seed, 0)
    targets = np.random.default_rng([seed, 0]).uniform(
        config.bounds[:, 0], config.bounds[:, 1], size=(config.n_targets, 3))
    rng = np.random.default_rng([seed, 1])
    sensor, box = config.sensor, config.bounds
    settings = config.settings()
    bonus = ExplorationBonus(box, config.bonus_resolution_m)
    route = config.lawnmower_route() if config.planner == "lawnmower" else None
    state = PHDState.empty(3, 3)
    found = np.empty((0, 3))
    position = np.array(config.start)
    path, counts = [position], []
    t_plan = t_filter = 0.0
    for k in range(config.max_steps):
        t0 = time.perf_counter()
        z, _origin = sensor.measure(position, targets, rng)
        state, found, centres = _filter_step(state, found, z, position, config, rng)
        t1 = time.perf_counter()
        counts.append(int(_matches(targets, found, config.match_m)[0].sum()))
        if counts[-1] == config.n_targets:
            t_filter += t1 - t0
            break
        if route is not None:
            position = route[min(k + 1, route.shape[0] - 1)]
        else:
            bonus = bonus.updated(sensor, position)
            problem = SearchProblem(position, box, bonus, sensor, settings, belief=state,
                                    centres=centres)
            result = solve(problem, backend="receding")
            if result.plan is None:
                raise InvalidInputError("bounds", box, f"step {k}: {result.message}")
            position = result.plan.waypoint
        path.append(position)
        t_plan += time.perf_counter() - t1
        t_filter += t1 - t0
    steps = len(counts)
    hit, true_est, dist = _matches(targets, found, config.match_m)
    done = bool(counts) and counts[-1] == config.n_targets
    rmse = float(np.sqrt(np.mean(dist[hit] ** 2))) if hit.any() else math.nan
    log.info("search %s seed %d: %d/%d found in %d steps", config.planner, seed, counts[-1],
             config.n_targets, steps)
    return SearchEpisode(steps if done else config.max_steps + 1,
                         np.array(counts, dtype=np.int64), int((~true_est).sum()), rmse,
                         1e3 * t_plan / max(steps, 1), 1e3 * t_filter / max(steps, 1),
                         targets, np.asarray(found, dtype=np.float64), np.array(path))
