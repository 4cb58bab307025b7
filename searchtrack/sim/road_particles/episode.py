"""Closed-loop road tracking of Moore et al. 2021 (§6): UAVs flying the road graph, targets
driving it, the Rao-Blackwellized filter, and a planner choosing the next road at every node.

One episode (:func:`run_road_tracking`):

* The targets drive the directed roads by the motion model of Eq. 9 (truth speed noise
  ``truth_sigma_mps``, 2 m/s in the authors' simulation; the filter assumes
  ``filter_sigma_mps``, 4 m/s), starting uniformly by length (Eq. 1).
* Each UAV flies along the roads at ``uav_speed_mps`` (40 m/s) from a random node; when it
  reaches a node its planner picks the next directed edge and the distance left over in the
  step is flown on it. Each UAV decides when it reaches a node: jointly with the others in
  flight (``coordination="joint"``, beyond the paper) or alone (``"alone"``, the paper's).
* The filter (:class:`~searchtrack.estimate.road_rbpf.RoadRBPF`, ``H × M × N``), stepped as a
  :class:`~searchtrack.estimate.stepping.SteppedFilter`
  (:class:`~searchtrack.estimate.road_rbpf_stepping.SteppedRoadRBPF`), predicts every ``dt_s``
  (0.1 s) and takes one scan per UAV every ``scan_period_s`` (1 s, the authors' code): the
  downward disc sensor's detections, or negative information when there are none.
* Recorded at every scan: the combined entropy of the best history (pooled over the targets,
  5 m road bins, nats: the quantity of Fig. 10–11), each target's entropy, and the error of
  the MAP position estimates against the truth (best matching of estimates to targets).

The planners (:data:`PLANNERS`): the road-search solver family
(:mod:`searchtrack.plan.road_search`, by backend name, reading the filter through the
:class:`~searchtrack.estimate.belief.RoadParticleBelief` seam: ``exhaustive`` is the paper's
receding-horizon controller), ``random`` (a uniform choice among the roads leaving the node,
U-turns included, as the authors' random planner), ``ideal`` (knows where the targets are) and
``rl`` (a trained policy evaluated with NumPy).
"""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import check_seed
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_rbpf import RBPFConfig
from searchtrack.estimate.road_rbpf_stepping import SteppedRoadRBPF
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.plan.road_search.weights import NORMALIZATIONS, Normalization
from searchtrack.sim.road_particles.planners import PLANNERS, Chooser, make_chooser
from searchtrack.sim.roads.scenario import MAX_STEPS, MapSpec

log = logging.getLogger("searchtrack.sim.road_particles.episode")

Coordination = Literal["joint", "alone"]
COORDINATIONS: tuple[Coordination, ...] = ("joint", "alone")
"""How the UAVs of an episode decide: together, or each alone (the paper's)."""

PAPER_GRID = MapSpec("grid", rows=3, cols=3, block_m=100.0, spacing_m=100.0)
"""The 3 × 3 road network of the paper's simulation (§6, Fig. 9): 100 m roads."""


@dataclass(frozen=True)
class RoadTrackingConfig:
    """One closed-loop road tracking episode; defaults: the paper's simulation (§6).

    Parameters
    ----------
    map
        The road network (the 3 × 3 grid of 100 m roads by default).
    targets, uavs
        ``M`` targets (known to the filter) and ``Q`` UAVs, ≥ 1.
    uav_speed_mps, target_speed_mps
        ``V_a`` (40) and the targets' nominal speed ``v_e`` (10), m/s, > 0.
    truth_sigma_mps, filter_sigma_mps
        Speed noise ``σ_ν`` (m/s) of the true targets (2) and the one the filter assumes (4).
    sensor
        The downward disc sensor (30 m view, ``R`` = 5 m²).
    histories, particles
        ``H`` (10) and ``N`` (500) of the filter.
    jump_rate_per_s
        ``λ`` of the filter's robust prior (:mod:`searchtrack.estimate.road_jumps`, beyond the
        paper): the rate at which a target may leave its predicted cloud; 0 (the paper's
        prior) by default.
    dt_s, scan_period_s, duration_s
        Filter step (0.1 s), time between scans (1 s) and episode length (s).
    planner
        One of :data:`PLANNERS`.
    coordination
        ``"joint"``: a solver planner chooses every UAV's path together, the others joining
        from the nodes they fly to (beyond the paper); ``"alone"``: each UAV plans by itself
        (the paper's controller). The same with one UAV.
    horizon_s
        Plan over a time horizon (s, beyond the paper): a path ends at the first node reached
        this long from now, with ``lookahead`` edges at most; 0 (the paper's): paths of
        ``lookahead`` edges.
    lookahead, discount, gain, normalization
        Road-search settings: look-ahead ``L`` (3), discount (0.8), sigmoid gain ``a`` (10),
        entropy normaliser of Eq. 20 (``"sum"`` as the authors' code; ``"max"`` keeps the most
        uncertain of ``M > 2`` targets above weight 1/2).
    time_limit_s
        Time limit of one planning call (s).
    policy
        A trained policy file (``.npz``) for ``planner="rl"`` (the shipped one if empty).
    """

    map: MapSpec = PAPER_GRID
    targets: int = 2
    uavs: int = 1
    uav_speed_mps: float = 40.0
    target_speed_mps: float = 10.0
    truth_sigma_mps: float = 2.0
    filter_sigma_mps: float = 4.0
    sensor: DiscSensor = field(default_factory=DiscSensor)
    histories: int = 10
    particles: int = 500
    jump_rate_per_s: float = 0.0
    dt_s: float = 0.1
    scan_period_s: float = 1.0
    duration_s: float = 120.0
    planner: str = "exhaustive"
    coordination: Coordination = "joint"
    horizon_s: float = 0.0
    lookahead: int = 3
    discount: float = 0.8
    gain: float = 10.0
    normalization: Normalization = "sum"
    time_limit_s: float = 1.0
    policy: str = ""

    def __post_init__(self) -> None:
        for name in ("targets", "uavs", "histories", "particles", "lookahead"):
            checks.count(name, getattr(self, name), 1)
        for name in ("uav_speed_mps", "target_speed_mps", "dt_s", "scan_period_s",
                     "duration_s", "gain", "time_limit_s"):
            checks.positive(name, getattr(self, name))
        for name in ("truth_sigma_mps", "filter_sigma_mps", "jump_rate_per_s", "horizon_s"):
            checks.non_negative(name, getattr(self, name))
        checks.real("discount", self.discount, low=0.0, high=1.0, low_open=True)
        checks.choice("normalization", self.normalization, NORMALIZATIONS)
        checks.choice("planner", self.planner, PLANNERS)
        checks.choice("coordination", self.coordination, COORDINATIONS)
        if self.scan_period_s < self.dt_s:
            raise InvalidInputError("scan_period_s", self.scan_period_s,
                                    f"must be ≥ dt_s = {self.dt_s}")
        if self.n_steps < self.scan_every:
            raise InvalidInputError("duration_s", self.duration_s,
                                    f"must span one scan (scan_period_s = {self.scan_period_s:g} "
                                    f"s): an episode records its entropy at the scans")
        if (steps := self.duration_s / self.dt_s) > MAX_STEPS:
            raise InvalidInputError("duration_s", self.duration_s, f"{steps:.3g} steps of dt_s="
                                    f"{self.dt_s:g}, above the {MAX_STEPS} an episode may take")

    @property
    def n_steps(self) -> int:
        """Filter steps in the episode."""
        return round(self.duration_s / self.dt_s)

    @property
    def scan_every(self) -> int:
        """Filter steps between scans."""
        return max(1, round(self.scan_period_s / self.dt_s))

    def filter_config(self) -> RBPFConfig:
        """The filter's configuration."""
        return RBPFConfig(n_targets=self.targets, n_histories=self.histories,
                          n_particles=self.particles,
                          motion=RoadMotion(self.target_speed_mps, self.filter_sigma_mps),
                          sensor=self.sensor,
                          jumps=TargetJumps.at_rate(self.jump_rate_per_s))


@dataclass(frozen=True)
class RoadTrackingLog:
    """What an episode recorded, one entry per scan time.

    Attributes
    ----------
    times_s
        ``(K,)`` scan times (s).
    entropy
        ``(K,)`` combined entropy of the best history (nats, 5 m bins).
    target_entropy
        ``(K, M)`` each target's entropy.
    error_m
        ``(K,)`` mean distance (m) between the MAP estimates and the true targets, matched.
    detected
        ``(M,)`` time (s) each target was first detected, ``nan`` if never.
    planner_ms, filter_ms
        Mean time of one planning decision and of one filter step (predict + scans).
    decisions
        Planning decisions taken.
    interrupted
        Whether a stop request ended the episode early.
    """

    times_s: FloatArray
    entropy: FloatArray
    target_entropy: FloatArray
    error_m: FloatArray
    detected: FloatArray
    planner_ms: float
    filter_ms: float
    decisions: int
    interrupted: bool = False

    @property
    def mean_entropy(self) -> float:
        """Combined entropy averaged over the episode."""
        return float(self.entropy.mean()) if self.entropy.size else float("nan")


def matched_error(estimates: FloatArray, truth: FloatArray) -> float:
    """Mean distance between ``estimates`` and ``truth`` ``(M, 2)`` under the best one-to-one
    matching (exhaustive for ``M ≤ 6``, else greedy by distance)."""
    m = truth.shape[0]
    d = np.linalg.norm(estimates[:, None, :] - truth[None, :, :], axis=-1)
    if m <= 6:
        return float(min(d[np.arange(m), list(p)].mean()
                         for p in itertools.permutations(range(m))))
    total, rows, cols = 0.0, set(range(m)), set(range(m))
    for i, j in sorted(np.ndindex(m, m), key=lambda ij: d[ij]):
        if i in rows and j in cols:
            total += d[i, j]
            rows.discard(i)
            cols.discard(j)
    return float(total / m)


WAIT = -1
"""What a chooser answers to keep a UAV at its node for the rest of the step."""


@dataclass
class GraphUAVs:
    """UAVs flying along directed roads at a constant speed, choosing a road at every node.

    A UAV is at arc length ``s[q]`` on directed edge ``edge[q]``; ``s[q] = length`` means it is
    at the head node, waiting for its next road. A chooser may answer :data:`WAIT`: the UAV then
    stops at the node for the rest of the step (an agent that decides between steps).
    """

    roads: DirectedRoads
    speed_mps: float
    edge: IntArray
    s: FloatArray

    @classmethod
    def at_nodes(cls, roads: DirectedRoads, nodes: IntArray, speed_mps: float) -> GraphUAVs:
        """UAVs standing at ``nodes`` (each placed at the end of a road into its node)."""
        edge = np.array([int(roads.leaving(n)[0]) ^ 1 for n in nodes], dtype=np.int64)
        return cls(roads, speed_mps, edge, roads.length[edge].astype(np.float64))

    def points(self) -> FloatArray:
        """``(Q, 2)`` planar positions."""
        return self.roads.point(self.edge, self.s)

    def nodes(self) -> IntArray:
        """``(Q,)`` the node each UAV flies towards (its current node once there)."""
        return self.roads.head[self.edge]

    def arrivals(self) -> tuple[IntArray, FloatArray]:
        """``(Q,)`` the node each UAV flies towards and ``(Q,)`` seconds until it is there."""
        left = np.maximum(self.roads.length[self.edge] - self.s, 0.0)
        return self.nodes(), left / self.speed_mps

    def fly(self, dt_s: float, choose: Callable[[int, int], int]) -> int:
        """Fly ``dt_s`` seconds; ``choose(q, node)`` gives the next directed edge (leaving
        ``node``) whenever UAV ``q`` reaches a node. Returns the number of choices made."""
        made = 0
        for q in range(self.edge.size):
            left = self.speed_mps * dt_s
            while True:
                room = self.roads.length[self.edge[q]] - self.s[q]
                if left < room:
                    self.s[q] += left
                    break
                left -= room
                node = int(self.roads.head[self.edge[q]])
                nxt = int(choose(q, node))
                if nxt == WAIT:
                    self.s[q] = self.roads.length[self.edge[q]]
                    break
                if not 0 <= nxt < self.roads.n_edges or self.roads.tail[nxt] != node:
                    raise ValueError(f"planner chose edge {nxt}, which does not leave node {node}")
                self.edge[q], self.s[q] = nxt, 0.0
                made += 1
                if left <= 0.0:
                    break
        return made


class RoadTrackingSim:
    """The state of one episode, advanced one filter step at a time (:meth:`step`); what
    :func:`run_road_tracking` and the RL environment drive.

    Parameters
    ----------
    config
        The episode.
    seed
        Seeds the targets, filter, sensor, planner and starts (independent streams).
    roads
        The map's directed roads, if already built.
    """

    def __init__(self, config: RoadTrackingConfig, seed: int,
                 roads: DirectedRoads | None = None) -> None:
        seed = check_seed(seed)
        self.config = config
        self.roads = roads if roads is not None else DirectedRoads(config.map.build())
        (self._truth_rng, self._filter_rng, self._sensor_rng, self.plan_rng,
         start_rng) = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(5))
        self._motion = RoadMotion(config.target_speed_mps, config.truth_sigma_mps)
        self._t_edge, self._t_s = self.roads.uniform(config.targets, self._truth_rng)
        self.belief = SteppedRoadRBPF(self.roads, config.filter_config(), self._filter_rng)
        starts = start_rng.choice(self.roads.network.n_nodes, size=config.uavs, replace=True)
        self.uavs = GraphUAVs.at_nodes(self.roads, starts, config.uav_speed_mps)
        self.k = 0
        self.decisions = 0
        self.plan_s = self.filter_s = 0.0
        self.detected = np.full(config.targets, np.nan)
        self._times: list[float] = []
        self._entropy: list[float] = []
        self._target_entropy: list[FloatArray] = []
        self._error: list[float] = []

    @property
    def time_s(self) -> float:
        """Time flown (s)."""
        return self.k * self.config.dt_s

    @property
    def done(self) -> bool:
        """Whether the episode's duration is flown."""
        return self.k >= self.config.n_steps

    def truth(self) -> tuple[IntArray, FloatArray]:
        """The true targets' positions ``(edge, s)``."""
        return self._t_edge, self._t_s

    def truth_points(self) -> FloatArray:
        """``(M, 2)`` the true targets' planar positions."""
        return self.roads.point(self._t_edge, self._t_s)

    def uav_points(self) -> FloatArray:
        """``(Q, 2)`` the UAVs' planar positions."""
        return self.uavs.points()

    def uav_arrivals(self) -> tuple[IntArray, FloatArray]:
        """``(Q,)`` the node each UAV flies to and ``(Q,)`` the seconds until it gets there."""
        return self.uavs.arrivals()

    def step(self, choose: Callable[[int, int], int]) -> float | None:
        """Advance one filter step (``choose`` picks roads at nodes); returns the combined
        entropy when the step ended with a scan, else ``None``."""
        config = self.config
        self._t_edge, self._t_s = self._motion.step(self.roads, self._t_edge, self._t_s,
                                                    config.dt_s, self._truth_rng)
        t0 = time.perf_counter()
        self.decisions += self.uavs.fly(config.dt_s, choose)
        self.plan_s += time.perf_counter() - t0
        t0 = time.perf_counter()
        self.belief.predict(config.dt_s)
        self.k += 1
        scan = self.k % config.scan_every == 0
        truth = self.truth_points()
        if scan:
            for uav_xy in self.uavs.points():
                ys, source = config.sensor.detect_labelled(uav_xy, truth, self._sensor_rng,
                                                           self.roads)
                seen = source[source >= 0]
                self.detected[seen] = np.where(np.isnan(self.detected[seen]), self.time_s,
                                               self.detected[seen])
                self.belief.update(ys, uav_xy)
        self.filter_s += time.perf_counter() - t0
        if not scan:
            return None
        per_target, entropy, estimates = self.belief.summary()
        self._times.append(self.time_s)
        self._entropy.append(entropy)
        self._target_entropy.append(per_target)
        self._error.append(matched_error(estimates, truth))
        return entropy

    def log(self, interrupted: bool = False) -> RoadTrackingLog:
        """What was recorded so far."""
        return RoadTrackingLog(
            times_s=np.array(self._times), entropy=np.array(self._entropy),
            target_entropy=np.array(self._target_entropy).reshape(-1, self.config.targets),
            error_m=np.array(self._error), detected=self.detected.copy(),
            planner_ms=1e3 * self.plan_s / max(self.decisions, 1),
            filter_ms=1e3 * self.filter_s / max(self.k, 1), decisions=self.decisions,
            interrupted=interrupted)


def run_road_tracking(config: RoadTrackingConfig, seed: int,
                      roads: DirectedRoads | None = None) -> RoadTrackingLog:
    """One episode of ``config`` with ``seed`` (``roads``: the map's directed roads, if already
    built). Honours a stop request between steps (the log then says ``interrupted``)."""
    sim = RoadTrackingSim(config, seed, roads)
    chooser: Chooser = make_chooser(config, sim)
    while not sim.done:
        if stop_requested():
            return sim.log(interrupted=True)
        sim.step(chooser)
    return sim.log()
