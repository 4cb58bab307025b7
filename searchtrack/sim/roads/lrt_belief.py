"""Thesis 001's filter as a road mission's :class:`~searchtrack.estimate.stepping.RoadFilter`:
the likelihood-ratio field (Ch. 3) searching for undetected targets, and node trackers (Ch. 4)
following the detected ones.

One update (the thesis fixes this order, Ch. 3–4): per UAV, associate its confirmed position
measurements with the trackers and update them, and the LRT with the rest (Algorithm 1,
:class:`~searchtrack.estimate.scan.ScanUpdater`); then detect and instantiate trackers
(:class:`~searchtrack.estimate.lrt.LRTInitiator`), hand births over to lost trackers
(:mod:`searchtrack.estimate.handover`, when on) and dissolve (:class:`~searchtrack.estimate.
node_tracker.TrackerDeleter`). One prediction: the LRT (3.8) and the trackers (4.2).

Sensing (the thesis leaves it open): every road node in a UAV's footprint gets its own ``ζ``
(``N(m, 1)`` where a target is, ``N(0, 1)`` elsewhere), so the LRT evidence is local and a
detection's super-threshold component is the target's neighbourhood, not the whole disc (read
literally, one ``ζ`` for the disc makes the born tracker nearly uniform over hundreds of nodes,
below ``P_min`` at once). A position measurement enters association only when the node nearest
to it measured ``ζ > c = m/2`` (§4.1).

The filter draws no random numbers. In ``detect`` mode (§6.1) each tracker is dropped at birth:
the birth is the detection.
"""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.association import Association, Associator
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.handover import STALE_AFTER_S, TrackHandover
from searchtrack.estimate.lrt import LikelihoodField, LRTInitiator, LRTPredictor
from searchtrack.estimate.node_tracker import TrackerBank, TrackerDeleter, TrackerPredictor
from searchtrack.estimate.scan import ScanUpdater
from searchtrack.estimate.stepping import RoadScan, RoadUpdate, TrackBirth, TrackPair
from searchtrack.models import RoadNetwork, SensorModel, UavState
from searchtrack.sim.roads.scenario import Scenario
from searchtrack.sim.roads.world import World


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


class LRTMissionBelief:
    """The LRT field and the node trackers of a road mission, stepped as one filter.

    Parameters
    ----------
    network
        The road network.
    updater, initiator, deleter
        Algorithm 1 per scan, the births (§4.1) and the dissolution (§4.2). The association
        time is reported apart when the updater's associator is a :class:`TimedAssociator`.
    lrt_predictor, tracker_predictor
        The predictions (3.8) and (4.2), over their diffusions' ``Δt``.
    sensor
        The sensor: its sensitivity ``m``, criterion ``c`` and position noise ``s``.
    handover
        The identity hand-over of births to lost trackers (``None``: off, the thesis).
    drop_births
        Drop each tracker at birth (``detect`` mode).
    """

    def __init__(self, network: RoadNetwork, updater: ScanUpdater, initiator: LRTInitiator,
                 deleter: TrackerDeleter, lrt_predictor: LRTPredictor,
                 tracker_predictor: TrackerPredictor, *, sensor: SensorModel,
                 handover: TrackHandover | None = None, drop_births: bool = False) -> None:
        self.network = network
        self.updater, self.initiator, self.deleter = updater, initiator, deleter
        self.lrt_predictor, self.tracker_predictor = lrt_predictor, tracker_predictor
        self.sensor = sensor
        self.handover = handover
        self.drop_births = drop_births
        self.field = LikelihoodField.neutral(network.n_nodes)
        self._bank = TrackerBank(network.n_nodes)
        self._last_fix: dict[int, float] = {}  # track_id -> time of its last fix or birth
        self.associator = updater.associator
        if isinstance(self.associator, TimedAssociator):
            self.associator.lap()

    @classmethod
    def for_mission(cls, scenario: Scenario, world: World,
                    rng: np.random.Generator) -> LRTMissionBelief:
        """The filter ``scenario`` specifies on ``world``'s network and diffusions (``rng`` is
        not drawn from: the filter is deterministic)."""
        del rng
        net, f, sensor = world.network, scenario.filter, scenario.sensor
        associator = TimedAssociator(EMDAssociator(net, f.associator, gate_m=f.gate_m))
        detect = sensor.pd * sensor.hit_rate if f.negative_information else 0.0
        return cls(net, ScanUpdater(net, associator, sensor.cell_radius_m, f.llr_floor, detect),
                   LRTInitiator(net, f.phi_max, f.birth_weighting, f.merge_radius_m),
                   TrackerDeleter(f.p_min), LRTPredictor(world.lrt_diffusion),
                   TrackerPredictor(world.tracker_diffusion), sensor=sensor,
                   handover=TrackHandover(net, 2.0 * f.gate_m) if f.handover else None,
                   drop_births=scenario.mode == "detect")

    @property
    def search_field(self) -> LikelihoodField:
        """The LRT's ``φ`` (3.3)."""
        return self.field

    @property
    def bank(self) -> TrackerBank:
        """The live trackers, in birth order."""
        return self._bank

    def estimates_xy(self) -> FloatArray:
        """``(len(bank), 2)`` positions of the trackers' peak nodes."""
        if not len(self._bank):
            return np.empty((0, 2))
        return np.asarray(self.network.coords[[t.peak_node() for t in self._bank]],
                          dtype=np.float64)

    def update(self, scan: RoadScan, pose: UavState) -> RoadUpdate:
        """Per UAV associate and update (Algorithm 1), then births, hand-overs and deletions.

        Raises
        ------
        InvalidInputError
            The scan holds no per-node ``ζ`` (``scan.lrt`` is ``None``).
        """
        lrt = scan.lrt
        if lrt is None:
            raise InvalidInputError("scan.lrt", None, "the LRT reads every footprint node's ζ")
        pos, s = scan.positions, self.sensor
        pairs: list[TrackPair] = []
        for j in range(pose.n):
            mine = lrt.uav == j
            if not np.any(mine):
                continue  # no road node under this UAV: nothing measured
            footprint, zeta = lrt.node[mine], lrt.zeta[mine]
            rows = self._confirmed(pos.xy_m, np.flatnonzero(pos.uav == j), footprint, zeta)
            out = self.updater.update(self.field, self._bank, zeta=zeta, footprint=footprint,
                                      sensitivity=s.sensitivity, positions_m=pos.xy_m[rows],
                                      noise_sd_m=s.position_noise_m)
            self.field, self._bank = out.field, out.bank
            pairs += [(j, self._bank[tr].track_id, int(rows[q]))
                      for tr, q in out.association.pairs]
        associate_s = (self.associator.lap() if isinstance(self.associator, TimedAssociator)
                       else 0.0)
        tic = time.perf_counter()
        births = self._initiate(scan.time_s, pairs)
        return RoadUpdate(tuple(pairs), births, associate_s, time.perf_counter() - tic)

    def predict(self, dt_s: float) -> None:
        """The LRT (3.8) and the trackers (4.2) one step on.

        Raises
        ------
        InvalidInputError
            ``dt_s`` is not the step the diffusions were built for.
        """
        step = self.lrt_predictor.diffusion.dt_s
        if dt_s != step:
            raise InvalidInputError("dt_s", dt_s, f"the diffusions step {step:g} s at a time")
        self.field = self.lrt_predictor.predict(self.field)
        self._bank = self.tracker_predictor.predict(self._bank)

    def _initiate(self, time_s: float, pairs: list[TrackPair]) -> tuple[TrackBirth, ...]:
        """Births (§4.1), hand-overs and deletions (§4.2); the births made."""
        self._last_fix.update((track, time_s) for _, track, _ in pairs)
        before, first_new = {t.track_id for t in self._bank}, self._bank.next_id
        self.field, bank = self.initiator.initiate(self.field, self._bank)
        taken: set[int] = set()
        if self.handover is not None:
            lost = {t for t in before
                    if time_s - self._last_fix.get(t, -np.inf) >= STALE_AFTER_S - 1e-9}
            bank, handed = self.handover.hand_over(bank, first_new, lost)
            taken = {kept for kept, _ in handed}
        born = [i for i, t in enumerate(bank) if t.track_id not in before or t.track_id in taken]
        self._last_fix.update((bank[i].track_id, time_s) for i in born)
        coords = self.network.coords
        births = tuple(TrackBirth(bank[i].track_id, coords[bank[i].peak_node()],
                                  bank[i].track_id in taken) for i in born)
        if self.drop_births and born:
            bank = bank.with_trackers(tuple(t for i, t in enumerate(bank) if i not in born))
        self._bank = self.deleter.delete(bank)
        return births

    def _confirmed(self, xy: FloatArray, rows: NDArray[np.int64], footprint: NDArray[np.int64],
                   zeta: FloatArray) -> NDArray[np.int64]:
        """The position measurements ``rows`` whose nearest footprint node measured ``ζ > c``
        (§4.1: the criterion keeps superfluous measurements out of association)."""
        if rows.size == 0:
            return rows
        coords = self.network.coords[footprint]
        near = np.argmin(np.linalg.norm(xy[rows][:, None, :] - coords[None, :, :], axis=2),
                         axis=1)
        keep: NDArray[np.int64] = rows[zeta[near] > self.sensor.criterion]
        return keep
