"""The closed loop of thesis 001: targets drive, UAVs sense, the graph filter updates, the
guidance strategy flies the UAVs.

One step: move the targets; sense; per UAV associate and update (Algorithm 1); detect and
instantiate trackers; dissolve; guide and move the UAVs; predict the LRT and the trackers. The
thesis fixes the order of the filter (Ch. 3–4) but not where guidance and prediction sit; here
the UAVs are guided on the posterior beliefs and the prediction comes last.

Sensing (the thesis leaves it open): every road node in a UAV's footprint gets its own ``ζ``
(``N(m, 1)`` where a target is, ``N(0, 1)`` elsewhere), so the LRT evidence is local and a
detection's super-threshold component is the target's neighbourhood, not the whole disc (read
literally, one ``ζ`` for the disc makes the born tracker nearly uniform over hundreds of nodes,
below ``P_min`` at once). A position measurement enters association only when the node nearest
to it measured ``ζ > c = m/2`` (§4.1).

With ``filter.belief = "rbpf"`` the mission estimates instead with the Rao-Blackwellized
particle filter of Moore et al. 2021 (paper 000), updated from the position measurements only
and read by the same guidance (:mod:`searchtrack.sim.roads.rbpf_belief`); the world, the
guidance and the scores are the same.

Association and guidance are chosen by name from their registries
(:data:`searchtrack.estimate.association.BACKENDS`,
:data:`searchtrack.plan.guidance.BACKENDS`). The guidance of each step is seeded with an
integer drawn from the mission's generator, and the search-and-reacquire routes pass from one
step's answer to the next step's problem.

Three rules of this library change the thesis's loop: ``filter.handover`` (on by default: a
birth where a live tracker lost its target goes to that tracker, which keeps its identity:
:mod:`searchtrack.estimate.handover`), and, off by default, ``filter.tracker_alpha`` (the
trackers diffuse at their own rate, see :class:`World`) and ``guidance.coverage_weight`` (free
searching UAVs are pushed away from road covered recently: :mod:`searchtrack.sim.roads.coverage`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import MAX_SEED
from searchtrack.core.types import FloatArray
from searchtrack.estimate import (
    Association,
    Associator,
    GraphDiffusion,
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    ScanUpdater,
    TrackerBank,
    TrackerDeleter,
    TrackerPredictor,
)
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.handover import STALE_AFTER_S, TrackHandover
from searchtrack.models import (
    CourierMotion,
    RoadNetwork,
    UavState,
    lrt_measurements,
    position_measurements,
    step_force,
)
from searchtrack.models.measurements import FALSE_ALARM, LrtScan, PositionScan
from searchtrack.plan.guidance import Guidance, GuidanceProblem
from searchtrack.plan.guidance import solve as solve_guidance
from searchtrack.sim.roads.coverage import CoverageMemory
from searchtrack.sim.roads.guidance_setup import next_problem, strategy_config, view
from searchtrack.sim.roads.metrics import StepScore, match_trackers
from searchtrack.sim.roads.rbpf_belief import RBPFMissionBelief
from searchtrack.sim.roads.record import MissionLog, PairRecord, Recorder, StepTimes
from searchtrack.sim.roads.scenario import Scenario

log = logging.getLogger("searchtrack.sim.roads.mission")
Progress = Callable[[int, int], None]


class TimedAssociator:
    """An :class:`~searchtrack.estimate.association.Associator` that adds up the seconds the
    wrapped one spends, so a step's association time is reported apart from its updates."""

    def __init__(self, inner: Associator) -> None:
        self.inner = inner
        self.seconds = 0.0

    def associate(self, bank: TrackerBank, densities: FloatArray) -> Association:
        """Delegate to the wrapped associator and time it."""
        tic = time.perf_counter()
        try:
            return self.inner.associate(bank, densities)
        finally:
            self.seconds += time.perf_counter() - tic

    def lap(self) -> float:
        """Seconds since the previous lap, and start a new one."""
        spent, self.seconds = self.seconds, 0.0
        return spent


@dataclass(frozen=True, eq=False)
class World:
    """What a scenario builds once: the road network and the filter's operators.

    The LRT diffuses at ``filter.alpha`` with decay ``C`` (3.8); the trackers (4.2), and with
    them the reacquisition horizon ``T_r`` of the guidance, at ``filter.tracker_alpha`` when
    it is set, else at the same ``alpha`` (the thesis).
    """

    network: RoadNetwork
    lrt_diffusion: GraphDiffusion
    tracker_diffusion: GraphDiffusion

    @classmethod
    def build(cls, scenario: Scenario, network: RoadNetwork | None = None) -> World:
        """Build (or reuse ``network``) and prepare the diffusion operators."""
        net = network if network is not None else scenario.map.build()
        f = scenario.filter
        world = cls(
            net,
            GraphDiffusion.on_network(net, f.alpha, scenario.dt_s, decay_c=f.decay_c),
            GraphDiffusion.on_network(net, f.tracker_diffusivity, scenario.dt_s),
        )
        _ = world.lrt_diffusion.operator, world.tracker_diffusion.operator  # build them now
        return world

    def mismatch(self, scenario: Scenario) -> str | None:
        """Why this world's operators are not those ``scenario`` builds (``None``: they are):
        a different LRT or tracker diffusivity, decay or time step."""
        f = scenario.filter
        lrt, trk = self.lrt_diffusion, self.tracker_diffusion
        wanted = {"filter.alpha": (lrt.alpha, f.alpha), "filter.decay_c": (lrt.decay_c, f.decay_c),
                  "filter.tracker_alpha": (trk.alpha, f.tracker_diffusivity),
                  "dt_s": (trk.dt_s, scenario.dt_s)}
        off = [f"{k}: world {have:g}, scenario {want:g}" for k, (have, want) in wanted.items()
               if have != float(want)]
        return "; ".join(off) if off else None


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
    :class:`~searchtrack.sim.roads.record.MissionLog`."""

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
        f = scenario.filter
        self.associator = TimedAssociator(EMDAssociator(net, f.associator, gate_m=f.gate_m))
        detect = (scenario.sensor.pd * scenario.sensor.hit_rate if f.negative_information
                  else 0.0)
        self.updater = ScanUpdater(net, self.associator, scenario.sensor.cell_radius_m,
                                   f.llr_floor, detect)
        self.initiator = LRTInitiator(net, f.phi_max, f.birth_weighting, f.merge_radius_m)
        self.deleter = TrackerDeleter(f.p_min)
        self.handover = TrackHandover(net, 2.0 * f.gate_m) if f.handover else None
        self.lrt_predictor = LRTPredictor(self.world.lrt_diffusion)
        self.tracker_predictor = TrackerPredictor(self.world.tracker_diffusion)
        self.motion = CourierMotion(net, scenario.courier)

    def run(self, progress: Progress | None = None) -> MissionLog:
        """Fly the whole mission (stops early in ``detect`` mode once every target is found,
        and after the current step when a stop is requested: the log then ends there)."""
        sc = self.scenario
        net = self.world.network
        rng = np.random.default_rng(sc.seed)
        config = strategy_config(sc)
        previous: tuple[GuidanceProblem, Guidance] | None = None
        targets = self.motion.spawn(sc.target_count, rng)
        uavs = initial_uavs(sc, net, rng)
        field = LikelihoodField.neutral(net.n_nodes)
        bank = TrackerBank(net.n_nodes)
        particles = RBPFMissionBelief(sc, net) if sc.filter.belief == "rbpf" else None
        first_detection = np.full(sc.target_count, np.nan)
        last_fix: dict[int, float] = {}  # track_id -> time of its last fix or birth
        detected = np.zeros(sc.target_count, dtype=bool)
        record = Recorder(sc, net, uavs.xy_m, targets.xy_m(net))
        coverage = (CoverageMemory(net, sc.sensor.footprint_radius_m,
                                   sc.filter.decay_c / sc.filter.alpha)
                    if sc.guidance.coverage_weight > 0.0 else None)
        self.associator.lap()
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
            if particles is None:
                lrt_scan = lrt_measurements(net, uav_xy, targets.nodes(net)[visible], sc.sensor,
                                            rng)
            pos = position_measurements(uav_xy, truth_xy[visible], sc.sensor, rng)
            pos_target = np.where(pos.target == FALSE_ALARM, FALSE_ALARM, visible[pos.target])
            times.sense = time.perf_counter() - tic

            if particles is not None:
                pairs, n_valid_assoc, n_false_assoc = particles.filter(
                    pos, pos_target, uav_xy, truth_xy, t_now, detected, first_detection, record,
                    times)
                bank = particles.bank
            else:
                field, bank, pairs, n_valid_assoc, n_false_assoc = self._lrt_filter(
                    lrt_scan, pos, pos_target, truth_xy, field, bank, times)
                tic = time.perf_counter()
                last_fix.update((track, t_now) for _, track, _ in pairs)
                before, first_new = {t.track_id for t in bank}, bank.next_id
                field, bank = self.initiator.initiate(field, bank)
                taken: set[int] = set()
                if self.handover is not None:
                    lost = {t for t in before
                            if t_now - last_fix.get(t, -np.inf) >= STALE_AFTER_S - 1e-9}
                    bank, handed = self.handover.hand_over(bank, first_new, lost)
                    taken = {kept for kept, _ in handed}
                born = [i for i, t in enumerate(bank)
                        if t.track_id not in before or t.track_id in taken]
                last_fix.update((bank[i].track_id, t_now) for i in born)
                bank = self._attribute(bank, born, truth_xy, detected, first_detection, t_now,
                                       record, taken)
                bank = self.deleter.delete(bank)
                times.initiate = time.perf_counter() - tic

            tic = time.perf_counter()
            covered = None
            if coverage is not None:
                coverage.see(uav_xy, t_now)
                covered = coverage.level(t_now)
            seen = (view(net, uavs, field, bank, t_now, covered) if particles is None
                    else particles.view(uavs, t_now, covered))
            problem = next_problem(previous, seen, config, self.world.tracker_diffusion)
            answer = solve_guidance(problem, backend=sc.guidance.strategy,
                                    time_limit_s=sc.guidance.optw_budget_s,
                                    seed=int(rng.integers(0, MAX_SEED)))
            if answer.plan is None:
                raise RuntimeError(f"guidance {answer.backend} gave no plan: {answer.message}")
            guidance = answer.plan
            previous = (problem, guidance)
            uavs = step_force(uavs, guidance.force, sc.dt_s, sc.limits)
            times.guide = time.perf_counter() - tic

            tic = time.perf_counter()
            if particles is not None:
                particles.predict(sc.dt_s)
            else:
                field = self.lrt_predictor.predict(field)
                bank = self.tracker_predictor.predict(bank)
            times.predict = time.perf_counter() - tic

            if particles is not None:
                peaks = particles.peaks_xy  # the RBPF's MAP positions
            else:
                peaks = (net.coords[[t.peak_node() for t in bank]] if len(bank)
                         else np.empty((0, 2)))
            now_match = match_trackers(peaks, truth_xy, sc.valid_distance_m)
            if sc.mode == "track":
                fresh = now_match[now_match >= 0]
                fresh = fresh[~np.isfinite(first_detection[fresh])]
                first_detection[fresh] = t_now
            valid = int(np.count_nonzero(now_match >= 0))
            step = StepScore(len(bank), valid, n_valid_assoc, n_false_assoc,
                             tuple(sorted(int(t) for t in now_match[now_match >= 0])))
            record.add(t_now, uavs.xy_m, truth_xy, step, guidance, times, bank, pairs)
            if record.heat_due():
                record.add_heat(field if particles is None
                                else particles.field.as_likelihood_field(), bank)
            if progress is not None:
                progress(k + 1, sc.n_steps)
            if sc.mode == "detect" and detected.all():
                log.info("all %d targets detected at t=%.1f s", sc.target_count, t_now)
                break
        final = field if particles is None else particles.field.as_likelihood_field()
        return record.finish(final, bank, first_detection)

    def _lrt_filter(self, lrt_scan: LrtScan, pos: PositionScan, pos_target: NDArray[np.int64],
                    truth_xy: FloatArray, field: LikelihoodField, bank: TrackerBank,
                    times: StepTimes) -> tuple[LikelihoodField, TrackerBank, list[PairRecord],
                                               int, int]:
        """Per UAV associate and update (Algorithm 1); the step's associations and the numbers
        of valid and false ones (matched at the start of the step)."""
        sc = self.scenario
        net = self.world.network
        m = sc.sensor.sensitivity
        peaks = net.coords[[t.peak_node() for t in bank]] if len(bank) else np.empty((0, 2))
        match = match_trackers(peaks, truth_xy, sc.valid_distance_m)
        n_valid_assoc = n_false_assoc = 0
        pairs: list[PairRecord] = []
        tic = time.perf_counter()
        for j in range(sc.uav_count):
            mine = lrt_scan.uav == j
            if not np.any(mine):
                continue  # no road node under this UAV: nothing measured
            footprint, zeta = lrt_scan.node[mine], lrt_scan.zeta[mine]
            rows = self._confirmed(pos.xy_m, np.flatnonzero(pos.uav == j), footprint, zeta)
            out = self.updater.update(field, bank, zeta=zeta, footprint=footprint,
                                      sensitivity=m, positions_m=pos.xy_m[rows],
                                      noise_sd_m=sc.sensor.position_noise_m)
            field, bank = out.field, out.bank
            for tr, q in out.association.pairs:
                truth = pos_target[rows[q]]
                pairs.append((j, bank[tr].track_id, int(truth)))
                if tr < match.size and truth != FALSE_ALARM and match[tr] == truth:
                    n_valid_assoc += 1
                else:
                    n_false_assoc += 1
        times.associate = self.associator.lap()
        times.update = time.perf_counter() - tic - times.associate
        return field, bank, pairs, n_valid_assoc, n_false_assoc

    def _confirmed(self, xy: FloatArray, rows: NDArray[np.int64], footprint: NDArray[np.int64],
                   zeta: FloatArray) -> NDArray[np.int64]:
        """The position measurements ``rows`` whose nearest footprint node measured ``ζ > c``
        (§4.1: the criterion keeps superfluous measurements out of association)."""
        if rows.size == 0:
            return rows
        coords = self.world.network.coords[footprint]
        near = np.argmin(np.linalg.norm(xy[rows][:, None, :] - coords[None, :, :], axis=2),
                         axis=1)
        keep: NDArray[np.int64] = rows[zeta[near] > self.scenario.sensor.criterion]
        return keep

    def _attribute(self, bank: TrackerBank, born: list[int], truth_xy: FloatArray,
                   detected: NDArray[np.bool_], first_detection: FloatArray, t_now: float,
                   record: Recorder, taken: set[int] | None = None) -> TrackerBank:
        """Credit each new tracker to the nearest true target within the validity distance; in
        ``detect`` mode mark it found (invisible from now on) and drop the tracker. Trackers
        whose ``track_id`` is in ``taken`` took a birth over (identity hand-over) and are
        recorded as births of their kept identity."""
        if not born:
            return bank
        net = self.world.network
        kept = taken or set()
        for i in born:
            peak = net.coords[bank[i].peak_node()]
            dist = np.linalg.norm(truth_xy - peak, axis=1)
            if self.scenario.mode == "detect":
                dist[detected] = np.inf
            target = int(np.argmin(dist))
            hit = bool(dist[target] < self.scenario.valid_distance_m)
            record.birth(t_now, bank[i].track_id, target if hit else -1, float(dist[target]),
                         handover=bank[i].track_id in kept)
            if hit and self.scenario.mode == "detect":
                detected[target] = True
                first_detection[target] = t_now
        if self.scenario.mode == "detect":
            keep = tuple(t for i, t in enumerate(bank) if i not in set(born))
            return bank.with_trackers(keep)
        return bank
