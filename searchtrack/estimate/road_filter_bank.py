"""``M`` road particle filters with known association (Moore et al. 2021, §2.5, Eq. 12): the
belief of a planner that knows which target each detection came from."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.estimate.road_entropy import RoadBins, combined_entropy, entropy, map_positions
from searchtrack.estimate.road_pf import RoadClouds, node_trackers
from searchtrack.estimate.road_resampling import ResamplePolicy
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads, RoadMotion


class RoadFilterBank:
    """``M`` independent road particle filters with known association (paper §2.5, Eq. 12).

    A detection labelled with its target updates that target's filter; every target without a
    detection in the scan gets the negative update. It is a
    :class:`~searchtrack.estimate.belief.RoadParticleBelief`: the belief of a planner that knows
    the associations (the paper's ideal baseline knows even the positions).

    Parameters
    ----------
    roads
        The directed roads.
    n_targets, n_particles
        ``M ≥ 1`` and ``N ≥ 1``.
    rng
        Draws the uniform initial clouds.
    motion, sensor, resample
        As :class:`RoadParticleFilter`.
    bin_m
        Bin length (m) of :meth:`target_entropy` and :meth:`map_positions`.
    """

    def __init__(self, roads: DirectedRoads, n_targets: int, n_particles: int,
                 rng: np.random.Generator, *, motion: RoadMotion | None = None,
                 sensor: DiscSensor | None = None, resample: ResamplePolicy | None = None,
                 bin_m: float = 5.0) -> None:
        self.motion = motion or RoadMotion()
        self.clouds = RoadClouds.uniform(roads, checks.count("n_targets", n_targets, 1),
                                         n_particles, rng, sensor=sensor or DiscSensor(),
                                         resample=resample or ResamplePolicy())
        self.bins = RoadBins(roads, bin_m)

    @property
    def roads(self) -> DirectedRoads:
        """The directed roads."""
        return self.clouds.roads

    @property
    def n_targets(self) -> int:
        """``M``."""
        return self.clouds.shape[0]

    def predict(self, dt_s: float, rng: np.random.Generator) -> None:
        """Move every particle ``dt_s`` seconds on (Eq. 9)."""
        self.clouds.predict(self.motion, dt_s, checks.generator("rng", rng))

    def update(self, detections: ArrayLike, targets: ArrayLike, uav_xy: ArrayLike,
               rng: np.random.Generator) -> None:
        """One scan: detection ``j`` of ``detections`` ``(k, 2)`` came from target
        ``targets[j]`` (−1: a false alarm, ignored); the targets without a detection get the
        negative update (Eq. 11)."""
        ys = checks.points("detections", detections)
        ids = np.asarray(targets)
        if ids.shape != (ys.shape[0],) or (ids.size and (ids.dtype.kind not in "iu"
                                                         or ids.min() < -1
                                                         or ids.max() >= self.n_targets)):
            raise InvalidInputError("targets", targets, f"must be {ys.shape[0]} target indices "
                                    f"in [-1, {self.n_targets})")
        uav = checks.finite_array("uav_xy", uav_xy, (2,))
        checks.generator("rng", rng)
        density = self.clouds.sensor.clutter_density(self.roads, uav)
        for y, m in zip(ys, ids.astype(np.int64), strict=True):
            if m >= 0:
                self.clouds.detection_sums(y, density)
                self.clouds.weigh(np.array([m], dtype=np.int64), rng)
        missed = np.setdiff1d(np.arange(self.n_targets), ids)
        self.clouds.miss(uav, missed.astype(np.int64), rng)

    def target_particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(edge, s, w)``, each ``(M, N)`` (copies)."""
        c = self.clouds
        return c.edge.copy(), c.s.copy(), c.w.copy()

    def target_entropy(self) -> FloatArray:
        """``(M,)`` entropy (nats) of each target on bins of ``bin_m``."""
        c = self.clouds
        return entropy(self.bins, c.edge, c.s, c.w)

    def combined_entropy(self, bin_m: float | None = None) -> float:
        """Entropy (nats) of all targets pooled (the paper's combined entropy)."""
        bins = self.bins if bin_m is None else RoadBins(self.roads, bin_m)
        c = self.clouds
        return combined_entropy(bins, c.edge, c.s, c.w)

    def map_positions(self) -> FloatArray:
        """``(M, 2)`` centre of each target's densest bin."""
        c = self.clouds
        return map_positions(self.bins, c.edge, c.s, c.w)

    def node_beliefs(self) -> tuple[NodeTracker, ...]:
        """One node belief per target (each particle's weight on the nearer end node)."""
        c = self.clouds
        return node_trackers(self.roads, c.edge, c.s, c.w)

    def belief_bank(self) -> TrackerBank:
        """The node beliefs as a :class:`~searchtrack.estimate.belief.BeliefBank`."""
        return TrackerBank(self.roads.network.n_nodes, self.node_beliefs(), self.n_targets)

    def particle_belief(self) -> WeightedParticles:
        """All particles as planar points, each target's weights summing to 1."""
        c = self.clouds
        return WeightedParticles(c.points().reshape(-1, 2), c.w.ravel())
