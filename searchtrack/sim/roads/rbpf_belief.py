"""Paper 000's Rao-Blackwellized particle filter (Moore et al. 2021) as the belief of a thesis 001
road mission: the thesis's couriers and sensor mapped onto the RBPF's models, and the RBPF
stepped as a :class:`~searchtrack.estimate.stepping.RoadFilter` and read through the belief
protocols the Ch. 5 guidance laws take (:mod:`searchtrack.estimate.belief`).

The filter (:class:`~searchtrack.estimate.road_rbpf.RoadRBPF`) holds ``M`` = the scenario's
number of targets (known, as the paper assumes), ``H`` histories of ``N`` particles per target
on :class:`~searchtrack.models.road_particles.DirectedRoads` of the mission's map, starting
uniform (Eq. 1). Each step: one update per UAV (its position measurements as detections, its
position as the scan centre; Eq. 10–11, 15–16), then the localisation below, the guidance, and
one prediction over ``Δt`` (the motion below), last as in the thesis's mission.

Models (the thesis's settings turned into the paper's; :func:`courier_motion`,
:func:`thesis_disc_sensor`):

- Motion: the couriers' drives and stops
  (:class:`~searchtrack.models.road_particles.CourierRoadMotion`, beyond the paper): each
  particle carries its speed, uniform in ``[f·V_max, V_max]`` while driving and 0 while
  stopped, drives last exponential times of the couriers' mean and stops of their mean dwell.
  Eq. 9 with the couriers' mean speed draws its noise afresh every step, so its cloud spreads
  like ``σ_ν √(Δt·t)`` around the mean: a courier that stops, or drives at its own speed, leaves
  it within seconds (tracks were lost at every stop); the drive-and-stop cloud keeps stopped,
  slow and fast particles. Its speeds are roughened after each resampling
  (:class:`~searchtrack.estimate.road_resampling.SpeedRoughening`), so the copies a
  resampling makes part instead of driving on as clumps.
- Sensor (Eq. 10–11): the field of view is the footprint disc ``ρ`` (the thesis sensor reports
  every target within ``ρ``), ``σ² = s²`` (position noise), ``P_FN = 1 − P_d``, and ``P_FA =
  1 − e^{−λ}``, the chance of at least one of the ``Poisson(λ)`` false alarms per footprint and
  step (capped at 0.999). The negative update covers the whole footprint (``negative_radius_factor``
  1: the thesis's disc has no image-edge margin), and the clutter density is per metre of road
  in view (``"view"``), since the thesis's false alarms fall in the footprint.
- Detections (beyond the paper): each cloud's prior is regularised near a detection and
  particles are drawn there (:mod:`searchtrack.estimate.road_births`), so a cloud with no
  particle near a target it has not found yet localises it within a few detections; on a city
  map ``N`` particles per target are one every few hundred metres of road, and without it a
  second target seen by a UAV was never taken up (its detections found no particle and were
  read as clutter). With a jump rate (``filter.jump_rate_per_s > 0``) the robust prior of
  :mod:`searchtrack.estimate.road_jumps` takes its place.
- Associations within one scan are one-to-one (``"joint"``): a footprint sees a target once.
  A scan with no road in view keeps only its negative information: its detections (false
  alarms: the targets are on the roads) would have likelihood 0 under every history.

Reading the filter (the best history, as the paper's planner does):

- A target is *localised* while its node belief (each particle's weight on the nearer end node)
  has a peak probability ``≥ P_min``, the thesis's dissolution threshold (§4.2). The
  :class:`~searchtrack.estimate.belief.BeliefBank` is the node beliefs of the localised targets
  (``track_id`` = the target's index in the filter) read at the sensor's resolution (beyond
  the paper): blurred along the roads by a Gaussian of ``filter.node_resolution_m``, by
  default the position noise ``s`` (:mod:`searchtrack.estimate.road_kernel`), so the peak
  ``𝒫`` the guidance compares with ``ϱ`` (5.16) is on the scale of the thesis's trackers and
  falls as soon as the cloud spreads beyond what a detection resolves. A target becoming
  localised is a tracker birth, one spreading below ``P_min`` is dissolved. In ``detect`` mode
  the bank stays empty, as the thesis's detect-mode trackers are dropped at birth.
- The :class:`~searchtrack.estimate.belief.SearchField` the searching UAVs climb is, with
  ``filter.search_field = "particles"``, the
  :class:`~searchtrack.sim.roads.particle_field.ParticleSearchField`: per node ``v``, the log
  ratio of the pooled mass of the targets not localised around ``v`` (a neighbourhood the size
  of the footprint disc) to what the uniform prior puts there, floored at
  :data:`~searchtrack.sim.roads.particle_field.SCORE_FLOOR`. Like the LRT's ``φ`` (3.3) it is 0
  under the prior, falls where the UAVs looked and found nothing, and rises where an unseen
  target's mass gathers; but it refills a searched footprint as fast as the couriers drive in,
  so the gradient search (5.7) keeps no memory of where it looked. With ``"lrt"`` it is the
  thesis's own search field: the LRT of :class:`~searchtrack.sim.roads.lrt_belief.
  LRTMissionBelief` flown beside the RBPF on the same scans (it reads the footprints' ``ζ``),
  whose ``φ`` keeps a look for about ``C/α`` and whose own trackers take the evidence of the
  targets it found out of ``φ``; the mission reads and scores only the RBPF's bank.
- What the mission scores (thesis 001 §6.2): the trackers' positions
  (:meth:`RBPFMissionBelief.estimates_xy`) are the RBPF's MAP positions (densest 5 m road bin)
  of the localised targets; an update reports as its associations the detections the best
  history gives to a target that was in the bank at the start of the step, and as its births
  the targets that became localised (:class:`~searchtrack.estimate.stepping.RoadUpdate`). The
  recorded tracks keep the node beliefs' peak nodes.

Guidance re-plans reacquisition routes with the thesis's tracker prediction (4.2) on these node
beliefs (the mission's tracker diffusion).
"""

from __future__ import annotations

import math
import time

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.belief import SearchField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.estimate.road_births import DetectionBirths
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_kernel import RoadKernel
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_resampling import KLDSampling, SpeedRoughening
from searchtrack.estimate.stepping import RoadScan, RoadUpdate, TrackBirth, TrackPair
from searchtrack.models import CourierModel, RoadNetwork, SensorModel, UavState
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads
from searchtrack.sim.roads.lrt_belief import LRTMissionBelief
from searchtrack.sim.roads.particle_field import ParticleFieldBuilder, ParticleSearchField
from searchtrack.sim.roads.scenario import Scenario
from searchtrack.sim.roads.world import World

#: Largest ``P_FA`` of the disc sensor (Eq. 10 needs ``P_FA < 1``).
MAX_P_FA = 0.999

#: KLD-sampling's speed bins are ``s / KLD_SPEED_SPAN_S`` wide (``s`` the position noise):
#: particles a bin apart in speed drift apart by the position noise within this time.
KLD_SPEED_SPAN_S = 5.0

#: Shortest mean stop (s) of the particles' motion: couriers that never dwell stop for about a
#: step at a time.
MIN_MEAN_STOP_S = 1e-3


def courier_motion(courier: CourierModel) -> CourierRoadMotion:
    """The drive-and-stop motion of the thesis's couriers (see the module docstring): their
    speed range and mean drive, and their mean dwell as the mean stop (at least
    :data:`MIN_MEAN_STOP_S`)."""
    return CourierRoadMotion(
        min_speed_mps=courier.min_speed_fraction * courier.max_speed_mps,
        max_speed_mps=courier.max_speed_mps, mean_drive_s=courier.mean_drive_s,
        mean_stop_s=max(0.5 * (courier.dwell_min_s + courier.dwell_max_s), MIN_MEAN_STOP_S))


def thesis_disc_sensor(sensor: SensorModel) -> DiscSensor:
    """The disc sensor (Eq. 10–11) of the thesis's sensor: view ``ρ``, ``σ² = s²``,
    ``P_FN = 1 − P_d``, ``P_FA = 1 − e^{−λ}`` (see the module docstring).

    Raises
    ------
    InvalidInputError
        ``position_noise_m`` is 0 (the paper's likelihood needs a positive variance).
    """
    if sensor.position_noise_m <= 0.0:
        raise InvalidInputError("sensor.position_noise_m", sensor.position_noise_m,
                                "the RBPF needs a positive position noise")
    return DiscSensor(fov_radius_m=sensor.footprint_radius_m,
                      sigma2_m2=sensor.position_noise_m ** 2,
                      p_fa=min(-math.expm1(-sensor.false_alarm_mean), MAX_P_FA),
                      p_fn=1.0 - sensor.pd, negative_radius_factor=1.0, clutter="view")


def node_resolution(scenario: Scenario) -> float:
    """The ``σ`` (m) the bank's node beliefs are read at: ``filter.node_resolution_m``, or the
    sensor's position noise when that is ``None`` (0: the cloud's own beliefs)."""
    sigma = scenario.filter.node_resolution_m
    return scenario.sensor.position_noise_m if sigma is None else float(sigma)


def searches_on_lrt(scenario: Scenario) -> bool:
    """Whether the RBPF mission of ``scenario`` searches on an LRT's ``φ`` (and so reads the
    footprints' ``ζ``; module docstring)."""
    return scenario.filter.search_field == "lrt"


def rbpf_config(scenario: Scenario) -> RBPFConfig:
    """The RBPF of ``scenario``: ``M`` = its targets, ``H``, ``N`` and the jump rate from its
    filter spec, the couriers' motion with its speeds roughened, the thesis sensor's disc, the
    rejuvenation near detections unless the spec asks for jumps (module docstring), and
    KLD-sampling when the spec sets ``kld_epsilon``: on road bins of the sensor's position noise
    ``s``, each cut into speed bins of ``s /`` :data:`KLD_SPEED_SPAN_S`."""
    f = scenario.filter
    jumps = TargetJumps.at_rate(f.jump_rate_per_s)
    sigma = scenario.sensor.position_noise_m
    counts = None if f.kld_epsilon is None else KLDSampling(
        epsilon=f.kld_epsilon, bin_m=sigma, speed_bin_mps=sigma / KLD_SPEED_SPAN_S)
    return RBPFConfig(n_targets=scenario.target_count, n_histories=f.histories,
                      n_particles=f.particles, motion=courier_motion(scenario.courier),
                      sensor=thesis_disc_sensor(scenario.sensor), association="joint",
                      jumps=jumps, births=DetectionBirths() if jumps is None else None,
                      roughening=SpeedRoughening(), counts=counts)


class RBPFMissionBelief:
    """A mission's RBPF and what the guidance and the scores read from it (module docstring): a
    :class:`~searchtrack.estimate.stepping.RoadFilter`.

    Parameters
    ----------
    scenario
        The mission (``filter.belief`` need not be ``"rbpf"``: sizes come from its filter spec).
    network
        Its road network.
    rng
        The filter's generator: the initial clouds (Eq. 1), the association sampling and the
        resampling (Eq. 15–16) and the motion noise (Eq. 9) all draw from it.
    roads
        The directed view of ``network`` (built when ``None``).
    kernel
        The road kernel the bank's node beliefs are read through (module docstring), of
        ``network`` at :func:`node_resolution`; built when ``None``, none when that is 0.
    search
        The LRT whose ``φ`` is the search field (module docstring), stepped with the RBPF;
        ``None``: the particle search field.

    Attributes
    ----------
    rbpf
        The filter.
    search
        The thesis's LRT flown for the search field (``filter.search_field = "lrt"``, module
        docstring); ``None``: the particle search field.
    field
        The particle search field, as of the last :meth:`update` (neutral with ``search``).
    peaks_xy
        ``(len(bank), 2)`` MAP positions of the bank's targets.
    """

    def __init__(self, scenario: Scenario, network: RoadNetwork, rng: np.random.Generator,
                 roads: DirectedRoads | None = None, kernel: RoadKernel | None = None,
                 search: LRTMissionBelief | None = None) -> None:
        self.scenario = scenario
        self.network = network
        directed = roads if roads is not None else DirectedRoads(network)
        if directed.network is not network:
            raise InvalidInputError("roads", roads, "must be the directed view of network")
        self.rng = checks.generator("rng", rng)
        self.rbpf = RoadRBPF(directed, rbpf_config(scenario), self.rng)
        sigma = node_resolution(scenario)
        if kernel is not None and (kernel.n_nodes != network.n_nodes or kernel.sigma_m != sigma):
            raise InvalidInputError("kernel", kernel, f"must be a road kernel of network at the "
                                    f"scenario's node resolution ({sigma:g} m)")
        self.kernel = kernel if kernel is not None or sigma == 0.0 else RoadKernel(network, sigma)
        m = scenario.target_count
        self.localised = np.zeros(m, dtype=bool)
        self._bank = TrackerBank(network.n_nodes, (), m)
        self.search = search
        if search is not None and search.network is not network:
            raise InvalidInputError("search", search, "must be an LRT of the same network")
        # the particle field is built only when it is the one the UAVs climb
        self.fields = (ParticleFieldBuilder(network, scenario.sensor.footprint_radius_m)
                       if search is None else None)
        self.field = ParticleSearchField(np.zeros(network.n_nodes))
        self.peaks_xy: FloatArray = np.empty((0, 2))

    @classmethod
    def for_mission(cls, scenario: Scenario, world: World,
                    rng: np.random.Generator) -> RBPFMissionBelief:
        """The filter of ``scenario`` on ``world``'s network, drawing from ``rng`` (the road
        kernel the world keeps), with the LRT of ``scenario`` on ``world`` for the search
        field when ``filter.search_field`` is ``"lrt"`` (it draws nothing)."""
        sigma = node_resolution(scenario)
        search = (LRTMissionBelief.for_mission(scenario, world, rng)
                  if searches_on_lrt(scenario) else None)
        return cls(scenario, world.network, rng,
                   kernel=world.road_kernel(sigma) if sigma > 0.0 else None, search=search)

    @property
    def search_field(self) -> SearchField:
        """The field the searching UAVs climb (module docstring)."""
        return self.field if self.search is None else self.search.search_field

    @property
    def bank(self) -> TrackerBank:
        """The localised targets' node beliefs (``track_id`` = target index)."""
        return self._bank

    def estimates_xy(self) -> FloatArray:
        """``(len(bank), 2)`` MAP positions of the bank's targets (:attr:`peaks_xy`)."""
        return self.peaks_xy

    def update(self, scan: RoadScan, pose: UavState) -> RoadUpdate:
        """One update per UAV (its position measurements, its position as the scan centre;
        Eq. 10–11, 15–16), then the localisation. The pairs are the detections the best
        history gave to a target localised when the update began; the births are the targets
        that became localised."""
        if self.search is not None:
            self.search.update(scan, pose)
        tracked = {t.track_id for t in self._bank}
        pos, uav_xy = scan.positions, pose.xy_m
        pairs: list[TrackPair] = []
        for j in range(pose.n):
            rows = np.flatnonzero(pos.uav == j)
            self.rbpf.update(pos.xy_m[rows], uav_xy[j], self.rng)
            pairs += [(j, c, q) for q, c in
                      zip(rows.tolist(), self.rbpf.best_association().tolist(), strict=True)
                      if c in tracked]  # else clutter, or a target not tracked yet
        tic = time.perf_counter()
        births = self._localise()
        return RoadUpdate(tuple(pairs), births, initiate_s=time.perf_counter() - tic)

    def _localise(self) -> tuple[TrackBirth, ...]:
        """Refresh the bank, the MAP peaks and the field; the targets newly localised."""
        sc = self.scenario
        beliefs: tuple[NodeTracker, ...] = self.rbpf.node_beliefs()
        now = np.array([b.peak_probability >= sc.filter.p_min for b in beliefs])
        map_xy = self.rbpf.map_positions()
        births = tuple(TrackBirth(m, map_xy[m])
                       for m in np.flatnonzero(now & ~self.localised).tolist())
        self.localised = now
        tracked = np.flatnonzero(now) if sc.mode != "detect" else np.empty(0, dtype=np.int64)
        self._bank = TrackerBank(self.network.n_nodes, tuple(self._read(beliefs[m])
                                                             for m in tracked),
                                 sc.target_count)
        self.peaks_xy = map_xy[tracked]
        if self.fields is not None:
            free = np.flatnonzero(~now)
            mass = (np.sum([beliefs[m].probability for m in free], axis=0) if free.size
                    else np.zeros(self.network.n_nodes))
            self.field = self.fields.field(mass, int(free.size))
        return births

    def _read(self, belief: NodeTracker) -> NodeTracker:
        """``belief`` as the bank holds it: through the road kernel, if any."""
        if self.kernel is None:
            return belief
        return NodeTracker(self.kernel.smooth(belief.probability), belief.track_id)

    def predict(self, dt_s: float) -> None:
        """The couriers' drive-and-stop motion over ``dt_s`` seconds (and the search LRT's
        prediction (3.8), (4.2))."""
        if self.search is not None:
            self.search.predict(dt_s)
        self.rbpf.predict(dt_s, self.rng)
