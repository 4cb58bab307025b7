"""The closed loop of paper 002 (Nguyen et al.): one UAV with a directional antenna flies over
radio-tagged objects, a filter (the JMS TBD-LMB on the raw STFT, or the detection-then-track
baseline) updates every measurement interval T0, and a planner picks the next heading sequence
every planning interval N_p (§III-D, eq. 45; §IV).

Each second the truth moves (born and dying on the scenario's schedule), the UAV flies one step
of its current primitive (or, with ``keep_out``, of the primitive tracked by a trajectory
controller that keeps a disc of radius r_min around every estimate, :mod:`.radio_keep_out`),
the spectrogram is simulated at the UAV's pose, the filter steps, and the step is scored: OSPA
(p = 1, c = 100 m, §IV-B) with its localisation and cardinality parts, the cardinality mean and
variance (Fig. 5c), and whether a live object was within r_min of the UAV (ground distance), the
event the void-probability constraint (eq. 44) guards against. With ``replan_on_breach`` the
updated belief is checked against the constraint at the poses still to be flown after every
measurement, and a breach makes the next second plan again (the paper plans every N_p only).
"""

from __future__ import annotations

import logging
import math
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import check_seed
from searchtrack.core.result import Status
from searchtrack.core.types import FloatArray
from searchtrack.estimate.metrics import ospa_components
from searchtrack.estimate.radio import LabelledFilter
from searchtrack.estimate.radio.likelihood import correlated_cells_temper
from searchtrack.models.radio import (
    RadioScenario,
    RadioTruth,
    fly_heading,
    simulate_truth,
    straight_sweep_heading,
)
from searchtrack.plan.radio import RadioPlanProblem, solve, void_probability
from searchtrack.plan.radio.problem import check_lookahead_size, keep_out_radii
from searchtrack.sim.radio.config import STRAIGHT, RadioMissionConfig
from searchtrack.sim.radio.keep_out import KeepOut, fly_with_keep_out
from searchtrack.sim.radio.run import SIMULATORS, spectrogram
from searchtrack.sim.radio.track_job import make_filter

log = logging.getLogger("searchtrack.sim.radio.mission")

@dataclass(frozen=True)
class RadioMissionLog:
    """What one run recorded, one row per measurement interval ``k = 1..K``.

    ``poses`` has ``K + 1`` rows (the start, then the pose at each measurement);
    ``estimates[k]`` lists ``(label, (x, y))``; ``ospa`` is ``(K, 3)``: total, localisation,
    cardinality; ``nearest_m`` the ground distance from the UAV to the nearest live object
    (``inf`` when none lives); ``plan_status`` counts the planning answers by status.
    """

    scenario: RadioScenario
    config: RadioMissionConfig
    truth: RadioTruth
    times_s: FloatArray
    poses: FloatArray
    estimates: list[list[tuple[int, tuple[float, float]]]]
    existence: FloatArray
    cardinality_mean: FloatArray
    cardinality_var: FloatArray
    ospa: FloatArray
    nearest_m: FloatArray
    filter_ms: float
    planner_ms: list[float]
    plan_status: dict[str, int]
    keep_out_fallbacks: int = 0
    breach_replans: int = 0
    interrupted: bool = False

    @property
    def steps(self) -> int:
        """Measurement intervals flown."""
        return int(self.times_s.size)

    def unsafe_fraction(self) -> float:
        """Fraction of steps with a live object closer than r_min (ground distance)."""
        if not self.steps:
            return 0.0
        return float(np.mean(self.nearest_m < self.config.plan.r_min_m))

    def cardinality_hit_fraction(self, tolerance: float = 0.5) -> float:
        """Fraction of steps whose mean cardinality ``Σ r`` is within ``tolerance`` of the
        number of live objects (Fig. 5c: the estimate following the truth)."""
        if not self.steps:
            return 0.0
        alive = np.array([self.truth.positions(k)[0].size for k in range(self.steps)])
        return float(np.mean(np.abs(self.cardinality_mean - alive) <= tolerance))

    def objects_detected(self) -> int:
        """How many objects were ever reported under their own label within the OSPA cut-off
        ``c`` of their true position while alive."""
        found: set[int] = set()
        for k, row in enumerate(self.estimates):
            labels, xy = self.truth.positions(k)
            where = {int(lab): xy[i] for i, lab in enumerate(labels)}
            found.update(lab for lab, p in row if lab in where and math.hypot(
                where[lab][0] - p[0], where[lab][1] - p[1]) < self.config.ospa_c_m)
        return len(found)

    def mean_ospa(self) -> tuple[float, float, float]:
        """Time means of OSPA and its localisation and cardinality parts."""
        if not self.steps:
            return (float("nan"),) * 3
        m = self.ospa.mean(axis=0)
        return float(m[0]), float(m[1]), float(m[2])

    def to_json(self) -> dict[str, Any]:
        """The log as JSON: configuration, summary and per-step series."""
        total, loc, card = self.mean_ospa()
        c = self.config
        return {
            "filter": c.filter, "planner": c.planner, "backend": c.backend,
            "particles_per_label": c.particles_per_label, "keep_out": c.keep_out,
            "noise_var_v2": self.scenario.signal.noise_var_v2, "steps": self.steps,
            "interrupted": self.interrupted,
            "summary": {"mean_ospa_m": total, "mean_localisation_m": loc,
                        "mean_cardinality_m": card, "unsafe_fraction": self.unsafe_fraction(),
                        "cardinality_hit_fraction": self.cardinality_hit_fraction(),
                        "objects_detected": self.objects_detected(),
                        "filter_ms": self.filter_ms,
                        "planner_ms": float(np.mean(self.planner_ms)) if self.planner_ms
                        else None,
                        "plan_status": self.plan_status,
                        "keep_out_fallbacks": self.keep_out_fallbacks,
                        "breach_replans": self.breach_replans},
            "times_s": self.times_s.tolist(),
            "uav_poses": np.round(self.poses, 3).tolist(),
            "estimates": [[{"label": lab, "xy": [round(x, 3), round(y, 3)]}
                           for lab, (x, y) in row] for row in self.estimates],
            "cardinality": np.round(self.cardinality_mean, 6).tolist(),
            "cardinality_var": np.round(self.cardinality_var, 6).tolist(),
            "ospa": np.round(self.ospa, 4).tolist(),
            "nearest_m": [round(float(d), 3) if np.isfinite(d) else None
                          for d in self.nearest_m]}


class _Flight:
    """The UAV's primitive for the current planning interval, one pose per second."""

    def __init__(self, scenario: RadioScenario, config: RadioMissionConfig, seed: int) -> None:
        self.scenario, self.config, self.seed = scenario, config, seed
        uav = scenario.uav
        self.pose = np.array([*uav.start_xy, uav.start_heading], dtype=float)
        self.path = np.empty((0, 3))
        self.statuses: Counter[str] = Counter()
        self.planner_ms: list[float] = []
        self.keep_out_fallbacks = 0
        self.breach_replans = 0
        self.interval = max(1, round(uav.plan_interval_s / uav.step_s))
        self.keep = KeepOut(radius_m=config.plan.r_min_m) if config.keep_out else None

    def replan(self, belief: LabelledFilter, k: int) -> None:
        sc, uav = self.scenario, self.scenario.uav
        if self.config.planner == STRAIGHT:
            # the sweep's heading is recomputed every second, so it turns at the corners
            self.path = self._sweep(uav.step_s)
            if k % self.interval == 0:
                self.statuses[STRAIGHT] += 1
            return
        problem = RadioPlanProblem(belief, self.pose, sc, self.config.plan)  # copied once
        t0 = time.perf_counter()
        result = solve(problem, backend=self.config.backend,
                       time_limit_s=self.config.plan_time_limit_s,
                       seed=(self.seed * 7919 + k) % (2**31 - 1))
        self.planner_ms.append(1e3 * (time.perf_counter() - t0))
        self.statuses[result.status.name] += 1
        if result.plan is None or result.status is Status.ERROR:
            log.warning("planning at step %d gave no plan (%s): straight sweep", k,
                        result.message)
            self.path = self._sweep(uav.plan_interval_s)
            return
        self.path = np.asarray(result.plan.path[: self.interval], dtype=float)

    def _sweep(self, duration_s: float) -> FloatArray:
        """The straight sweep's poses over ``duration_s`` from the current pose."""
        uav = self.scenario.uav
        heading = straight_sweep_heading(uav, self.pose, self.scenario.area_m)
        return fly_heading(uav, self.pose, heading, duration_s)

    def check_breach(self, belief: LabelledFilter) -> None:
        """Drop the rest of the path (so the next step plans again) when the belief's void
        probability at one of its poses is no more than ``P_vmin``."""
        plan = self.config.plan
        if (not self.config.replan_on_breach or self.config.planner == STRAIGHT
                or self.path.shape[0] == 0):
            return
        state = belief.state
        xy = state.x[:, :, ::2]
        void = void_probability(state.r, state.w, xy, self.path[:, :2],
                                keep_out_radii(xy, state.r, plan))
        if plan.p_void_min > 0.0 and np.any(void <= plan.p_void_min):
            self.path = self.path[:0]
            self.breach_replans += 1

    def advance(self, estimates: list[tuple[int, FloatArray]]) -> FloatArray:
        """Fly one second; the pose reached."""
        if self.keep is None:
            self.pose, self.path = self.path[0].copy(), self.path[1:]
            return self.pose
        centres = (np.array([xy for _, xy in estimates], dtype=float).reshape(-1, 2))
        pose, result = fly_with_keep_out(self.keep, self.scenario.uav, self.pose,
                                         self.path[:, :2], centres)
        if result.stats.get("heading_fallback", 0.0) > 0:
            self.keep_out_fallbacks += 1
        self.pose, self.path = np.asarray(pose, dtype=float), self.path[1:]
        return self.pose


def run_radio_mission(scenario: RadioScenario, config: RadioMissionConfig, seed: int,
                      progress: Callable[[int, int], None] | None = None) -> RadioMissionLog:
    """Fly one closed-loop run of ``scenario`` (deterministic for ``seed``). Honours a stop
    request between steps: the log then holds the steps done and says ``interrupted``."""
    seed = check_seed(seed)
    if config.planner != STRAIGHT:
        check_lookahead_size(scenario, config.plan)
    streams = np.random.SeedSequence(seed).spawn(3)
    truth = simulate_truth(scenario, np.random.default_rng(streams[0]))
    meas_rng = np.random.default_rng(streams[1])
    tempered = (config.temper_correlated and config.measurement == "time"
                and config.filter == "tbd")  # DTT reads peaks, not the cells' likelihood
    temper = correlated_cells_temper(scenario.signal) if tempered else 1.0
    filt = make_filter(config.filter, scenario, config.particles_per_label,
                       int(streams[2].generate_state(1)[0] % (2**31 - 1)),
                       temper, config.roughening_m)
    simulate = SIMULATORS[config.measurement]
    flight = _Flight(scenario, config, seed)
    n = scenario.n_steps
    poses = [flight.pose.copy()]
    estimates: list[list[tuple[int, tuple[float, float]]]] = []
    existence, card_mean, card_var, ospa_rows, nearest = [], [], [], [], []
    filter_s = 0.0
    interrupted = False
    current: list[tuple[int, FloatArray]] = []
    for k in range(n):
        if stop_requested():
            interrupted = True
            break
        if flight.path.shape[0] == 0:
            flight.replan(filt, k)
        pose = flight.advance(current)
        z = spectrogram(scenario.signal, truth, k, pose, simulate, meas_rng)
        xy = truth.positions(k)[1]
        t0 = time.perf_counter()
        filt.step(z, pose)
        filter_s += time.perf_counter() - t0
        current = filt.estimates()
        flight.check_breach(filt)
        est_xy = np.array([p for _, p in current], dtype=float).reshape(-1, 2)
        ospa_rows.append(ospa_components(est_xy, xy, config.ospa_c_m, config.ospa_p))
        d = np.hypot(xy[:, 0] - pose[0], xy[:, 1] - pose[1]) if xy.size else np.array([])
        nearest.append(float(d.min()) if d.size else float("inf"))
        estimates.append([(int(lab), (float(p[0]), float(p[1]))) for lab, p in current])
        existence.append(filt.state.r.copy())
        card_mean.append(filt.cardinality_mean())
        card_var.append(filt.cardinality_variance())
        poses.append(pose.copy())
        if progress is not None:
            progress(k + 1, n)
    done = len(estimates)
    n_labels = scenario.signal.n_labels
    return RadioMissionLog(
        scenario=scenario, config=config, truth=truth,
        times_s=np.asarray(truth.times_s[:done], dtype=float), poses=np.array(poses),
        estimates=estimates,
        existence=np.array(existence).reshape(done, n_labels),
        cardinality_mean=np.array(card_mean, dtype=float),
        cardinality_var=np.array(card_var, dtype=float),
        ospa=np.array(ospa_rows, dtype=float).reshape(done, 3),
        nearest_m=np.array(nearest, dtype=float),
        filter_ms=1e3 * filter_s / max(1, done), planner_ms=flight.planner_ms,
        plan_status=dict(flight.statuses), keep_out_fallbacks=flight.keep_out_fallbacks,
        breach_replans=flight.breach_replans,
        interrupted=interrupted)
