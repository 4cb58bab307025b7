"""What a mission leaves behind: paths, per-step scores and timings, births, the final beliefs,
the road map and sparse heat frames of the beliefs (what the replay page draws).

A log keeps the beliefs of at most :data:`MAX_HEAT_FRAMES` evenly spaced steps of the planned
mission as heat frames (and its last step when it ends early). Each holds the nodes where ``φ``
(3.3) exceeds :data:`HEAT_LLR_MIN` (the evidence of a target building towards ``φ_max``; the
negative evidence of searched roads is left out, being dense) and where the trackers' summed
node probabilities exceed :data:`HEAT_TRACKER_MIN`, each at most the :data:`HEAT_MAX_NODES`
highest (the RBPF's search score, its ``φ``, is positive over every unsearched road).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import LikelihoodField, TrackerBank
from searchtrack.models import RoadNetwork
from searchtrack.sim.roads.metrics import MissionScore, StepScore, score
from searchtrack.sim.roads.scenario import Scenario

PHASES = ("truth", "sense", "associate", "update", "initiate", "guide", "predict")
"""Timed phases of a step; the filter-and-plan step is every phase but ``truth`` and
``sense`` (the simulated world)."""


class StepGuidance(Protocol):
    """The part of a guidance answer the log keeps."""

    @property
    def mode(self) -> tuple[str, ...]: ...

    @property
    def plan_ms(self) -> float: ...


@dataclass
class StepTimes:
    """Seconds spent in each phase of one step."""

    truth: float = 0.0
    sense: float = 0.0
    associate: float = 0.0
    update: float = 0.0
    initiate: float = 0.0
    guide: float = 0.0
    predict: float = 0.0

    def as_ms(self) -> list[float]:
        """Milliseconds per phase, in :data:`PHASES` order."""
        return [1e3 * getattr(self, p) for p in PHASES]


@dataclass(frozen=True, eq=False)
class Birth:
    """A tracker instantiated by the LRT: when, which track, which true target (−1: none);
    ``handover`` when the new distribution went to a live tracker that had lost its target,
    which kept its ``track_id`` (:mod:`searchtrack.estimate.handover`)."""

    time_s: float
    track_id: int
    target: int
    distance_m: float
    handover: bool = False


MAX_HEAT_FRAMES = 150
"""Most heat frames a log keeps (plus the last step when a mission ends early)."""

HEAT_LLR_MIN = 0.05
"""Smallest LRT ``φ`` (nats) a heat frame keeps."""

HEAT_TRACKER_MIN = 1e-3
"""Smallest summed tracker node probability a heat frame keeps."""

HEAT_MAX_NODES = 400
"""Most nodes a heat frame keeps of each belief (the highest values)."""


def heat_steps(n_steps: int, max_frames: int = MAX_HEAT_FRAMES) -> IntArray:
    """The step indices (0-based) of the heat frames of an ``n_steps`` mission: at most
    ``max_frames`` (≥ 2) evenly spaced ones, the first and the last always among them."""
    if n_steps <= 0 or max_frames <= 0:
        return np.zeros(0, dtype=np.int64)
    picked = np.round(np.linspace(0, n_steps - 1, min(n_steps, max_frames)))
    return np.unique(picked.astype(np.int64))


def sparse_top(values: FloatArray, minimum: float,
               most: int = HEAT_MAX_NODES) -> tuple[IntArray, FloatArray]:
    """The nodes (ascending) where ``values > minimum``, at most the ``most`` highest (the
    lower node first on ties), and a copy of their values."""
    nodes = np.flatnonzero(values > minimum)
    if nodes.size > most:
        nodes = np.sort(nodes[np.argsort(-values[nodes], kind="stable")[:most]])
    return nodes, np.array(values[nodes], dtype=np.float64)


def significant(values: FloatArray, digits: int = 3) -> list[float]:
    """``values`` rounded to ``digits`` significant digits, as plain floats."""
    return [float(f"{v:.{digits}g}") for v in np.asarray(values, dtype=np.float64).tolist()]


@dataclass(frozen=True, eq=False)
class HeatFrame:
    """The beliefs at the end of one step, kept sparsely: node indices and their values."""

    step: int
    llr_nodes: IntArray
    llr: FloatArray
    tracker_nodes: IntArray
    trackers: FloatArray

    @classmethod
    def capture(cls, step: int, field_: LikelihoodField, bank: TrackerBank) -> HeatFrame:
        """The nodes of ``φ > HEAT_LLR_MIN`` and of summed tracker probability above
        :data:`HEAT_TRACKER_MIN` (see :func:`sparse_top`; copies, the frame outlives the
        beliefs)."""
        llr_nodes, llr = sparse_top(field_.llr, HEAT_LLR_MIN)
        tracker_nodes, mass = sparse_top(bank.node_probability(), HEAT_TRACKER_MIN)
        return cls(step, llr_nodes, llr, tracker_nodes, mass)

    def to_json(self) -> dict[str, Any]:
        """``{"step", "llr": {"nodes", "values"}, "trackers": {"nodes", "values"}}``, values
        to 3 significant digits."""
        return {"step": self.step,
                "llr": {"nodes": self.llr_nodes.tolist(), "values": significant(self.llr)},
                "trackers": {"nodes": self.tracker_nodes.tolist(),
                             "values": significant(self.trackers)}}


TrackRecord = tuple[int, int, float]
"""A live tracker at the end of a step: ``(track_id, peak node, peak probability)``."""

PairRecord = tuple[int, int, int]
"""An association of a step: ``(uav, track_id, true target)``; target −1 for a false alarm."""


@dataclass(frozen=True, eq=False)
class MissionLog:
    """Everything one mission recorded (arrays indexed by step; paths include the start)."""

    scenario: Scenario
    network: RoadNetwork
    time_s: FloatArray
    uav_xy_m: FloatArray
    target_xy_m: FloatArray
    steps: tuple[StepScore, ...]
    modes: tuple[tuple[str, ...], ...]
    plan_ms: FloatArray
    phase_ms: FloatArray
    births: tuple[Birth, ...]
    tracks: tuple[tuple[TrackRecord, ...], ...]
    associations: tuple[tuple[PairRecord, ...], ...]
    first_detection_s: FloatArray
    final_llr: FloatArray
    final_trackers: FloatArray
    score: MissionScore
    heat: tuple[HeatFrame, ...] = ()

    @property
    def moc(self) -> FloatArray:
        """MOC at each step."""
        return np.array([s.valid_trackers / self.score.targets for s in self.steps])

    @property
    def step_ms(self) -> FloatArray:
        """Filter-and-plan milliseconds per step (associate, update, initiate, guide, predict)."""
        return np.asarray(self.phase_ms[:, 2:].sum(axis=1), dtype=np.float64)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dictionary (numbers rounded to what the data justify)."""
        sc = self.scenario
        s = self.score
        return {
            "scenario": {
                "name": sc.name, "map": sc.map.describe(), "mode": sc.mode,
                "strategy": sc.guidance.strategy, "uavs": sc.uav_count,
                "targets": sc.target_count, "altitude_m": sc.altitude_m,
                "sensor": {"pd": sc.sensor.pd, "pf": sc.sensor.pf,
                           "footprint_radius_m": sc.sensor.footprint_radius_m,
                           "position_noise_m": sc.sensor.position_noise_m},
                "associator": sc.filter.associator,
                "belief": {"kind": sc.filter.belief, "histories": sc.filter.histories,
                           "particles": sc.filter.particles},
                "duration_s": sc.duration_s,
                "dt_s": sc.dt_s, "seed": sc.seed, "valid_distance_m": sc.valid_distance_m,
            },
            "network": {"nodes": self.network.n_nodes, "edges": self.network.n_edges,
                        "intersections": self.network.n_intersections},
            "summary": {
                "steps": s.steps, "moc_mean": s.moc_mean, "moc_final": s.moc_final,
                "pvt": s.pvt, "pva": s.pva, "nvt": s.nvt, "nst": s.nst, "nva": s.nva,
                "nfa": s.nfa, "detected": s.detected,
                "moc_after_detection": s.moc_after_detection,
                "time_to_detect_all_s": s.time_to_detect_all_s,
                "time_to_first_detection_s": s.time_to_first_detection_s,
                "step_ms_median": float(np.median(self.step_ms)) if self.steps else None,
                "step_ms_p95": float(np.percentile(self.step_ms, 95)) if self.steps else None,
                "phase_ms_mean": dict(zip(PHASES, np.round(self.phase_ms.mean(axis=0), 3)
                                          .tolist(), strict=True)) if self.steps else {},
            },
            "first_detection_s": [None if math.isnan(v) else v
                                  for v in self.first_detection_s.tolist()],
            "births": [{"time_s": round(b.time_s, 3), "track_id": b.track_id,
                        "target": b.target, "distance_m": round(b.distance_m, 1),
                        **({"handover": True} if b.handover else {})}
                       for b in self.births],
            "time_s": np.round(self.time_s, 3).tolist(),
            "moc": np.round(self.moc, 4).tolist(),
            "trackers": [st.trackers for st in self.steps],
            "valid_trackers": [st.valid_trackers for st in self.steps],
            "valid_associations": [st.valid_associations for st in self.steps],
            "false_associations": [st.false_associations for st in self.steps],
            "modes": [list(m) for m in self.modes],
            "tracks": [[[t, n, round(p, 4)] for t, n, p in step] for step in self.tracks],
            "associations": [[list(a) for a in step] for step in self.associations],
            "plan_ms": np.round(self.plan_ms, 3).tolist(),
            "step_ms": np.round(self.step_ms, 3).tolist(),
            "uav_xy_m": np.round(self.uav_xy_m, 1).tolist(),
            "target_xy_m": np.round(self.target_xy_m, 1).tolist(),
            "map": {"nodes_xy_m": np.round(self.network.coords, 1).tolist(),
                    "edges": self.network.edges.tolist()},
            "heat": {"llr_min": HEAT_LLR_MIN, "tracker_min": HEAT_TRACKER_MIN,
                     "max_nodes": HEAT_MAX_NODES, "frames": [h.to_json() for h in self.heat]},
        }


@dataclass(eq=False)
class Recorder:
    """Collects a mission step by step; :meth:`finish` freezes it into a :class:`MissionLog`."""

    scenario: Scenario
    network: RoadNetwork
    uav_start: FloatArray
    target_start: FloatArray
    _time: list[float] = field(default_factory=list)
    _uav: list[FloatArray] = field(default_factory=list)
    _target: list[FloatArray] = field(default_factory=list)
    _steps: list[StepScore] = field(default_factory=list)
    _modes: list[tuple[str, ...]] = field(default_factory=list)
    _plan: list[float] = field(default_factory=list)
    _phases: list[list[float]] = field(default_factory=list)
    _births: list[Birth] = field(default_factory=list)
    _tracks: list[tuple[TrackRecord, ...]] = field(default_factory=list)
    _pairs: list[tuple[PairRecord, ...]] = field(default_factory=list)
    _heat: list[HeatFrame] = field(default_factory=list)
    max_heat_frames: int = MAX_HEAT_FRAMES
    _heat_at: frozenset[int] = field(init=False, default=frozenset())

    def __post_init__(self) -> None:
        self._heat_at = frozenset(heat_steps(self.scenario.n_steps,
                                             self.max_heat_frames).tolist())

    def add(self, time_s: float, uav_xy: FloatArray, target_xy: FloatArray, step: StepScore,
            guidance: StepGuidance, times: StepTimes, bank: TrackerBank,
            pairs: list[PairRecord]) -> None:
        """Record one step: its truth, score, guidance and timings, the live trackers' peaks
        and the step's associations."""
        self._tracks.append(tuple((t.track_id, t.peak_node(), float(t.peak_probability))
                                  for t in bank))
        self._pairs.append(tuple(pairs))
        self._time.append(time_s)
        self._uav.append(np.array(uav_xy))
        self._target.append(np.array(target_xy))
        self._steps.append(step)
        self._modes.append(tuple(guidance.mode))
        self._plan.append(float(guidance.plan_ms))
        self._phases.append(times.as_ms())

    def heat_due(self) -> bool:
        """Whether the step just added is one of the heat frames."""
        return len(self._time) - 1 in self._heat_at

    def add_heat(self, field_: LikelihoodField, bank: TrackerBank) -> None:
        """Keep the beliefs at the end of the step just added as a heat frame (call it only
        when :meth:`heat_due`: the frame copies the beliefs' sparse part)."""
        self._heat.append(HeatFrame.capture(len(self._time) - 1, field_, bank))

    def birth(self, time_s: float, track_id: int, target: int, distance_m: float,
              handover: bool = False) -> None:
        """Record a tracker birth (``handover``: taken over by the live ``track_id``)."""
        self._births.append(Birth(time_s, track_id, target, distance_m, handover))

    def finish(self, field_: LikelihoodField, bank: TrackerBank,
               first_detection_s: FloatArray) -> MissionLog:
        """The frozen log; ``field_`` and ``bank`` are the beliefs after the last step, which
        is also kept as a heat frame when it was not one (a mission that ended early)."""
        n = self.network.n_nodes
        last = len(self._time) - 1
        if last >= 0 and (not self._heat or self._heat[-1].step != last):
            self._heat.append(HeatFrame.capture(last, field_, bank))
        final = bank.probabilities().sum(axis=0) if len(bank) else np.zeros(n)
        return MissionLog(
            scenario=self.scenario, network=self.network,
            time_s=np.array(self._time),
            uav_xy_m=np.stack([self.uav_start, *self._uav]),
            target_xy_m=np.stack([self.target_start, *self._target]),
            steps=tuple(self._steps), modes=tuple(self._modes),
            plan_ms=np.array(self._plan),
            phase_ms=np.array(self._phases).reshape(-1, len(PHASES)),
            births=tuple(self._births),
            tracks=tuple(self._tracks), associations=tuple(self._pairs),
            first_detection_s=np.array(first_detection_s),
            final_llr=np.array(field_.llr), final_trackers=final,
            score=score(self._steps, self.scenario.target_count, first_detection_s),
            heat=tuple(self._heat),
        )
