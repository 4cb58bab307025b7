"""The closed loop of thesis 001: targets drive, UAVs sense, the filter updates, the guidance
strategy flies the UAVs.

One step: move the targets; sense; update the filter with every UAV's scan; score the step's
associations and credit its births; guide and move the UAVs; predict the filter. The thesis
fixes the order of its filter (Ch. 3–4) but not where guidance and prediction sit; here the
UAVs are guided on the posterior beliefs and the prediction comes last.

The filter is chosen once, by the scenario's ``filter.belief``, from the registered road
mission filters (:data:`searchtrack.sim.roads.filters.FILTERS`: the thesis's LRT field and node
trackers, :mod:`searchtrack.sim.roads.lrt_belief`, by default; paper 000's RBPF,
:mod:`searchtrack.sim.roads.rbpf_belief`), and stepped through the
:class:`~searchtrack.estimate.stepping.RoadFilter` protocol: the loop never asks which filter
it holds. The filter draws from its own random stream; the world (targets, sensors, guidance
seeds) from the mission's. The sensors draw the per-node ``ζ`` of the footprints only for a
filter that reads them. The truth stays here: the filter reports which measurement went to
which track and which tracks were born; the mission scores those (thesis 001 §6.2,
:mod:`searchtrack.sim.roads.metrics`).

Guidance is chosen by name from its registry (:data:`searchtrack.plan.guidance.BACKENDS`). The
guidance of each step is seeded with an integer drawn from the mission's generator, and the
search-and-reacquire routes pass from one step's answer to the next step's problem.

Three rules of this library change the thesis's loop: ``filter.handover`` (on by default: a
birth where a live tracker lost its target goes to that tracker, which keeps its identity:
:mod:`searchtrack.estimate.handover`), and, off by default, ``filter.tracker_alpha`` (the
trackers diffuse at their own rate, see :class:`~searchtrack.sim.roads.world.World`) and
``guidance.coverage_weight`` (free searching UAVs are pushed away from road covered recently:
:mod:`searchtrack.sim.roads.coverage`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import MAX_SEED
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.stepping import RoadFilter, RoadScan, TrackBirth
from searchtrack.models import (
    CourierMotion,
    RoadNetwork,
    TargetState,
    UavState,
    lrt_measurements,
    position_measurements,
    step_force,
)
from searchtrack.models.measurements import FALSE_ALARM
from searchtrack.plan.guidance import Guidance, GuidanceProblem
from searchtrack.plan.guidance import solve as solve_guidance
from searchtrack.sim.roads.coverage import CoverageMemory
from searchtrack.sim.roads.filters import FILTERS, MissionFilter
from searchtrack.sim.roads.guidance_setup import next_problem, strategy_config, view
from searchtrack.sim.roads.metrics import (
    StepScore,
    count_associations,
    credit_birth,
    match_trackers,
    match_tracks,
)
from searchtrack.sim.roads.record import MissionLog, Recorder, StepTimes
from searchtrack.sim.roads.scenario import Scenario
from searchtrack.sim.roads.world import World

__all__ = ["Mission", "Progress", "World", "initial_uavs"]

log = logging.getLogger("searchtrack.sim.roads.mission")
Progress = Callable[[int, int], None]


def initial_uavs(scenario: Scenario, network: RoadNetwork, rng: np.random.Generator) -> UavState:
    """UAV start states: random road nodes, the map centre or the map's southern edge."""
    o = scenario.uav_count
    lo, hi = network.coords.min(axis=0), network.coords.max(axis=0)
    if scenario.uav_start == "random":
        xy = network.coords[rng.choice(network.n_nodes, size=o, replace=False)]
        heading = rng.uniform(-np.pi, np.pi, o)
    elif scenario.uav_start == "center":
        xy = np.repeat(network.coords[network.nearest_nodes((lo + hi)[None, :] / 2.0)], o, axis=0)
        heading = np.linspace(-np.pi, np.pi, o, endpoint=False)
    else:
        x = lo[0] + (hi[0] - lo[0]) * (np.arange(o) + 0.5) / o
        xy = np.column_stack([x, np.full(o, lo[1])])
        heading = np.full(o, np.pi / 2.0)
    speed = np.full(o, scenario.limits.speed_max_mps)
    return UavState(xy[:, 0], xy[:, 1], heading, speed)


class Mission:
    """Run one scenario; :meth:`run` returns the
    :class:`~searchtrack.sim.roads.record.MissionLog`.

    Attributes
    ----------
    registration
        The registered filter the scenario's ``filter.belief`` names
        (:data:`~searchtrack.sim.roads.filters.FILTERS`): how to build it, what it reads.
    """

    def __init__(self, scenario: Scenario, world: World | None = None) -> None:
        self.scenario = scenario
        self.world = world if world is not None else World.build(scenario)
        stale = self.world.mismatch(scenario)
        if stale is not None:
            raise InvalidInputError("world", stale, "was built for another filter: build it "
                                    "with World.build(scenario, network)")
        net = self.world.network
        fits = [("targets.count", scenario.target_count, "targets spawn on the road nodes")]
        if scenario.uav_start == "random":
            fits.insert(0, ("uavs.count", scenario.uav_count, "UAVs start on distinct road nodes"))
        for name, wanted, why in fits:
            if wanted > net.n_nodes:
                raise InvalidInputError(name, wanted, f"more than the {net.n_nodes} road nodes "
                                        f"of {scenario.map.describe()} ({why})")
        self.registration: MissionFilter = FILTERS.get(scenario.filter.belief)
        self.motion = CourierMotion(net, scenario.courier)

    def new_filter(self) -> RoadFilter:
        """A fresh filter for one run of the mission (:meth:`MissionFilter.filter_for`)."""
        return self.registration.filter_for(self.scenario, self.world)

    def run(self, progress: Progress | None = None) -> MissionLog:
        """Fly the whole mission (stops early in ``detect`` mode once every target is found,
        and after the current step when a stop is requested: the log then ends there)."""
        sc = self.scenario
        net = self.world.network
        rng = np.random.default_rng(sc.seed)
        belief = self.new_filter()
        config = strategy_config(sc)
        previous: tuple[GuidanceProblem, Guidance] | None = None
        targets = self.motion.spawn(sc.target_count, rng)
        uavs = initial_uavs(sc, net, rng)
        first_detection = np.full(sc.target_count, np.nan)
        detected = np.zeros(sc.target_count, dtype=bool)
        record = Recorder(sc, net, uavs.xy_m, targets.xy_m(net))
        coverage = (CoverageMemory(net, sc.sensor.footprint_radius_m,
                                   sc.filter.decay_c / sc.filter.alpha)
                    if sc.guidance.coverage_weight > 0.0 else None)
        for k in range(sc.n_steps):
            if stop_requested():
                log.info("stop requested: mission ends after %d of %d steps", k, sc.n_steps)
                break
            t_now = (k + 1) * sc.dt_s
            times = StepTimes()
            tic = time.perf_counter()
            targets = self.motion.step(targets, sc.dt_s, rng)
            truth_xy = targets.xy_m(net)
            visible = (np.flatnonzero(~detected) if sc.mode == "detect"
                       else np.arange(sc.target_count))
            times.truth = time.perf_counter() - tic

            tic = time.perf_counter()
            uav_xy = uavs.xy_m
            scan, scan_target = self._sense(uav_xy, targets, truth_xy, visible, t_now,
                                            rng)
            times.sense = time.perf_counter() - tic

            matched = match_tracks([t.track_id for t in belief.bank], belief.estimates_xy(),
                                   truth_xy, sc.valid_distance_m)
            tic = time.perf_counter()
            found = belief.update(scan, uavs)
            spent = time.perf_counter() - tic
            times.associate, times.initiate = found.associate_s, found.initiate_s
            times.update = spent - found.associate_s - found.initiate_s
            pairs = [(j, track, int(scan_target[q])) for j, track, q in found.pairs]
            n_valid_assoc, n_false_assoc = count_associations(pairs, matched)
            self._credit(found.births, truth_xy, t_now, detected, first_detection, record)

            tic = time.perf_counter()
            covered = None
            if coverage is not None:
                coverage.see(uav_xy, t_now)
                covered = coverage.level(t_now)
            seen = view(net, uavs, belief.search_field, belief.bank, t_now, covered)
            problem = next_problem(previous, seen, config, self.world.tracker_diffusion)
            answer = solve_guidance(problem, backend=sc.guidance.strategy,
                                    time_limit_s=sc.guidance.optw_budget_s,
                                    seed=int(rng.integers(0, MAX_SEED)))
            if answer.plan is None:
                raise RuntimeError(f"guidance {answer.backend} gave no plan: {answer.message}")
            guidance = answer.plan
            previous = (problem, guidance)
            uavs = step_force(uavs, guidance.force, sc.dt_s, sc.limits,
                              turn_back=guidance.turn_back(sc.guidance.steering))
            times.guide = time.perf_counter() - tic

            tic = time.perf_counter()
            belief.predict(sc.dt_s)
            times.predict = time.perf_counter() - tic

            now_match = match_trackers(belief.estimates_xy(), truth_xy, sc.valid_distance_m)
            if sc.mode == "track":
                fresh = now_match[now_match >= 0]
                fresh = fresh[~np.isfinite(first_detection[fresh])]
                first_detection[fresh] = t_now
            valid = int(np.count_nonzero(now_match >= 0))
            step = StepScore(len(belief.bank), valid, n_valid_assoc, n_false_assoc,
                             tuple(sorted(int(t) for t in now_match[now_match >= 0])))
            record.add(t_now, uavs.xy_m, truth_xy, step, guidance, times, belief.bank, pairs)
            if record.heat_due():
                record.add_heat(log_field(belief), belief.bank)
            if progress is not None:
                progress(k + 1, sc.n_steps)
            if sc.mode == "detect" and detected.all():
                log.info("all %d targets detected at t=%.1f s", sc.target_count, t_now)
                break
        return record.finish(log_field(belief), belief.bank, first_detection)

    def _sense(self, uav_xy: FloatArray, targets: TargetState, truth_xy: FloatArray,
               visible: IntArray, time_s: float,
               rng: np.random.Generator) -> tuple[RoadScan, IntArray]:
        """The UAVs' scan of the ``visible`` targets (the per-node ``ζ`` only for a filter that
        reads them, drawn first), and each position measurement's true target (−1: false
        alarm)."""
        sc = self.scenario
        net = self.world.network
        lrt = (lrt_measurements(net, uav_xy, targets.nodes(net)[visible], sc.sensor, rng)
               if self.registration.reads_lrt_of(sc) else None)
        pos = position_measurements(uav_xy, truth_xy[visible], sc.sensor, rng)
        target: IntArray = np.where(pos.target == FALSE_ALARM, FALSE_ALARM, visible[pos.target])
        return RoadScan(time_s, pos, lrt), target

    def _credit(self, births: tuple[TrackBirth, ...], truth_xy: FloatArray, time_s: float,
                detected: NDArray[np.bool_], first_detection: FloatArray, record: Recorder) -> None:
        """Record each birth with the true target it found (:func:`~searchtrack.sim.roads.
        metrics.credit_birth`); in ``detect`` mode mark that target found (invisible from now
        on), and once every target is found record no more births: the mission ends with
        this step."""
        detect = self.scenario.mode == "detect"
        for b in births:
            if detect and detected.all():
                break
            target, dist = credit_birth(b.xy_m, truth_xy, self.scenario.valid_distance_m,
                                        detected if detect else None)
            record.birth(time_s, b.track_id, target, dist, handover=b.handover)
            if detect and target >= 0:
                detected[target] = True
                first_detection[target] = time_s


def log_field(belief: RoadFilter) -> LikelihoodField:
    """The filter's search field as the log keeps it, drawn like the LRT's ``φ`` (the LRT's
    own field as it is; another filter's scores as a field)."""
    field = belief.search_field
    return field if isinstance(field, LikelihoodField) else LikelihoodField(field.node_score())
