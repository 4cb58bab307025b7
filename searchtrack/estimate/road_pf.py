"""Particle filters of targets on directed roads (Moore et al. 2021, §2.1–2.5).

A particle is ``(directed edge, arc length)`` (Eq. 8). The filter starts uniform over the road
length (Eq. 1), predicts with :class:`~searchtrack.models.road_particles.RoadMotion` (Eq. 2,
Eq. 9), weighs by Bayes' rule (Eq. 4) with the detection likelihood (Eq. 10) or the negative
information of a miss (Eq. 11 as intended, see :mod:`searchtrack.models.disc_sensor`) and
resamples by the low-variance method, after every update or when ``N_eff`` is low (Eq. 5–6,
:class:`~searchtrack.estimate.road_resampling.ResamplePolicy`).

:class:`RoadClouds` holds ``F`` clouds of at most ``N`` particles as ``(F, N)`` arrays and
updates any subset of them in place with numba kernels (with KLD-sampling, beyond the paper,
each cloud's count follows its spread:
:class:`~searchtrack.estimate.road_resampling.KLDSampling`); :class:`RoadParticleFilter` (one
target), the bank with known association (:mod:`searchtrack.estimate.road_filter_bank`, Eq. 12)
and the Rao-Blackwellized filter of :mod:`searchtrack.estimate.road_rbpf` are built on it. The
filters are mutable: each ``predict`` / ``update`` changes them in place (``copy()`` gives a
snapshot).
"""

from __future__ import annotations

import copy as _copy

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate import road_resample_kernels as rkern
from searchtrack.estimate.node_tracker import NodeTracker
from searchtrack.estimate.road_entropy import RoadBins, entropy, map_positions
from searchtrack.estimate.road_resampling import (
    KLDSampling,
    ResamplePolicy,
    SpeedRoughening,
    effective_sample_size,
)
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, DirectedRoads, RoadMotion


class RoadClouds:
    """``F`` weighted particle clouds of ``N`` particles on directed roads, updated in place.

    Parameters
    ----------
    roads
        The directed roads.
    edge, s
        ``(F, N)`` directed edges and arc lengths (m).
    w
        ``(F, N)`` non-negative weights with positive row sums (normalized here); uniform if
        ``None``.
    sensor, resample
        The measurement model and when to resample.
    speeds
        The drive-and-stop model whose speed state the particles carry (``v``, ``(F, N)``,
        resampled with them); ``None``: no speed state (``v`` all 0, as Eq. 9 needs none).
    v
        ``(F, N)`` initial speeds (m/s, ≥ 0); drawn from ``speeds``'s stationary law by
        :meth:`uniform`, 0 if ``None``.
    roughening
        Roughening of the speeds after each resampling of :meth:`resample` (Bayes' rule,
        negative information; :class:`~searchtrack.estimate.road_resampling.SpeedRoughening`,
        needs ``speeds``); ``None``: none. A join with draws near a detection is not
        roughened: its draws bring speeds of the stationary law, and roughening the union would
        blur the speeds the detections have just taught the cloud.
    counts
        KLD-sampling: each resampling keeps a number of particles that follows the cloud's
        spread, at most ``N`` (:class:`~searchtrack.estimate.road_resampling.KLDSampling`);
        ``None``: every cloud keeps ``N``.

    Attributes
    ----------
    count
        ``(F,)`` the particles each cloud holds, in its first columns (the columns beyond weigh
        0); ``N`` until a resampling with ``counts`` changes it.
    """

    def __init__(self, roads: DirectedRoads, edge: ArrayLike, s: ArrayLike,
                 w: ArrayLike | None = None, *, sensor: DiscSensor,
                 resample: ResamplePolicy, speeds: CourierRoadMotion | None = None,
                 v: ArrayLike | None = None, roughening: SpeedRoughening | None = None,
                 counts: KLDSampling | None = None) -> None:
        e = np.array(edge, copy=True)
        if e.ndim != 2 or e.shape[0] < 1 or e.shape[1] < 1 or e.dtype.kind not in "iu":
            raise InvalidInputError("edge", e.shape, "must be an integer (F, N) array, F, N ≥ 1")
        pos = np.array(s, dtype=np.float64, copy=True)
        e = e.astype(np.int64)
        roads.check_positions(e, pos)
        if w is None:
            ww = np.full(e.shape, 1.0 / e.shape[1])
        else:
            ww = np.array(w, dtype=np.float64, copy=True)
            total = ww.sum(axis=1, keepdims=True) if ww.shape == e.shape else None
            if total is None or not np.all(np.isfinite(ww)) or np.any(ww < 0.0) \
                    or np.any(total <= 0.0):
                raise InvalidInputError("w", ww.shape, f"must be {e.shape}, finite, ≥ 0, "
                                        "with positive row sums")
            ww /= total
        vv = np.zeros(e.shape) if v is None else np.array(v, dtype=np.float64, copy=True)
        if vv.shape != e.shape or not np.all(np.isfinite(vv)) or np.any(vv < 0.0):
            raise InvalidInputError("v", vv.shape, f"must be {e.shape}, finite, ≥ 0")
        if roughening is not None and (speeds is None
                                       or not isinstance(roughening, SpeedRoughening)):
            raise InvalidInputError("roughening", roughening, "must be a SpeedRoughening, with "
                                    "speeds (the drive-and-stop motion)")
        if counts is not None and not isinstance(counts, KLDSampling):
            raise InvalidInputError("counts", counts, "must be a KLDSampling or None")
        self.roads, self.sensor, self.resample_policy = roads, sensor, resample
        self.speeds, self.roughening, self.counts = speeds, roughening, counts
        self.edge, self.s, self.w, self.v = e, pos, ww, vv
        self.count: IntArray = np.full(e.shape[0], e.shape[1], dtype=np.int64)
        self._lik = np.empty(e.shape)
        self._bin_m, self._speed_bin = 1.0, 1.0
        if counts is None:
            self._bins, self._seen = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.bool_)
            self._table = np.zeros(0, dtype=np.int64)
        else:
            self._bins = RoadBins(roads, counts.bin_m).first_bin
            n_speed = counts.speed_bins(None if speeds is None else speeds.max_speed_mps)
            self._seen = np.zeros(int(self._bins[-1]) * n_speed, dtype=np.bool_)
            self._table, self._bin_m = counts.table(e.shape[1]), counts.bin_m
            self._speed_bin = counts.speed_bin_mps or 1.0

    @classmethod
    def uniform(cls, roads: DirectedRoads, n_clouds: int, n_particles: int,
                rng: np.random.Generator, *, sensor: DiscSensor, resample: ResamplePolicy,
                speeds: CourierRoadMotion | None = None,
                roughening: SpeedRoughening | None = None,
                counts: KLDSampling | None = None) -> RoadClouds:
        """``n_clouds`` clouds drawn uniformly over the road length (Eq. 1), with speeds from
        the stationary law of ``speeds`` when given (drawn after the positions)."""
        f = checks.count("n_clouds", n_clouds, 1)
        n = checks.count("n_particles", n_particles, 1)
        edge, s = roads.uniform((f, n), checks.generator("rng", rng))
        v = None if speeds is None else speeds.initial_speeds((f, n), rng)
        return cls(roads, edge, s, sensor=sensor, resample=resample, speeds=speeds, v=v,
                   roughening=roughening, counts=counts)

    def new_speeds(self, shape: tuple[int, ...], rng: np.random.Generator) -> FloatArray:
        """Speeds for particles joined to the clouds (jump and birth draws): the stationary law
        of :attr:`speeds` (nothing drawn without a speed state: 0)."""
        if self.speeds is None:
            return np.zeros(shape)
        return self.speeds.initial_speeds(shape, rng)

    @property
    def shape(self) -> tuple[int, int]:
        """``(F, N)``: the clouds and their capacity."""
        return (int(self.edge.shape[0]), int(self.edge.shape[1]))

    def copy(self) -> RoadClouds:
        """An independent copy."""
        out = _copy.copy(self)
        out.edge, out.s, out.w, out.v = (self.edge.copy(), self.s.copy(), self.w.copy(),
                                         self.v.copy())
        out.count, out._seen = self.count.copy(), self._seen.copy()
        out._lik = np.empty_like(self._lik)
        return out

    def points(self) -> FloatArray:
        """``(F, N, 2)`` planar points ``G(x)``."""
        return self.roads.point(self.edge, self.s)

    def predict(self, motion: RoadMotion | CourierRoadMotion, dt_s: float,
                rng: np.random.Generator) -> None:
        """Eq. 2 with the motion model of Eq. 9 (or the drive-and-stop model, which moves and
        updates the particles' speeds), every particle ``dt_s`` seconds on."""
        if isinstance(motion, CourierRoadMotion):
            self._courier(motion, dt_s, rng)
            return
        if type(motion) is not RoadMotion:
            edge, s = motion.step(self.roads, self.edge, self.s, dt_s, rng)
            self.edge, self.s = np.ascontiguousarray(edge), np.ascontiguousarray(s)
            return
        # RoadMotion.step by the kernels, from the same draws, in place.
        dt = checks.non_negative("dt_s", dt_s)
        e, pos, _ = self._flat()
        over = kern.move(e, pos, rng.standard_normal(pos.size), motion.speed_mps,
                         motion.sigma_mps, dt, self.roads.length, self.count)
        self._turn(e, pos, over, rng)

    def detection_sums(self, y: FloatArray, clutter_density: float) -> FloatArray:
        """``(F,)`` ``Σ_n w p(y | x)`` per cloud (Eq. 16 with the Eq. 10 likelihood); keeps the
        per-particle likelihoods for :meth:`weigh`."""
        sensor = self.sensor
        sums = np.empty(self.edge.shape[0])
        kern.detection_likelihood(self.edge, self.s, self.w, self.count, self.roads.tail_xy,
                                  self.roads.step_xy,
                                  float(y[0]), float(y[1]), sensor.detection_gain,
                                  0.5 / sensor.sigma2_m2, sensor.p_fa * clutter_density,
                                  self._lik, sums)
        return sums

    @property
    def likelihoods(self) -> FloatArray:
        """``(F, N)`` the per-particle likelihoods of the last :meth:`detection_sums`
        (read by the caller, not a copy)."""
        return self._lik

    def weigh(self, rows: IntArray, rng: np.random.Generator, *, resample: bool = True) -> None:
        """Bayes' rule (Eq. 4) on ``rows`` with the likelihoods of the last
        :meth:`detection_sums`, then resampling as the policy says (unless ``resample`` is
        false: the caller resamples)."""
        kern.weigh_rows(self.w, self._lik, rows, self.count)
        if resample:
            self.resample(rows, rng)

    def miss(self, uav_xy: FloatArray, rows: IntArray, rng: np.random.Generator, *,
             resample: bool = True) -> FloatArray:
        """Negative information (Eq. 11) on ``rows`` for a UAV at ``uav_xy``, then resampling as
        the policy says (unless ``resample`` is false); returns each row's no-detection
        likelihood ``Σ_n w p(z | x)`` (1 for a cloud outside the view)."""
        sums = np.empty(rows.size)
        touched = np.zeros(rows.size, dtype=np.bool_)
        kern.miss_update(self.edge, self.s, self.w, self.count, rows, self.roads.tail_xy,
                         self.roads.step_xy,
                         float(uav_xy[0]), float(uav_xy[1]), self.sensor.negative_radius_m ** 2,
                         self.sensor.p_fn, sums, touched)
        if resample:
            self.resample(rows[touched], rng)
        return sums

    def resample(self, rows: IntArray, rng: np.random.Generator) -> None:
        """Low-variance resampling of those ``rows`` the policy says are due (and the
        roughening of their speeds, if any)."""
        if rows.size == 0:
            return
        rows = rows[self.resample_policy.due(self.w[rows], self.count[rows])]
        if rows.size:
            rkern.resample_rows(self.edge, self.s, self.v, self.w, self.count, rows,
                                rng.random(rows.size), self._bins, self._bin_m,
                                self._speed_bin, self._seen, self._table)
            self.roughen(rows, rng)

    def join(self, rows: IntArray, mass: FloatArray, edge: IntArray, s: FloatArray,
             v: FloatArray, w: FloatArray, rng: np.random.Generator) -> None:
        """Join draws ``(R, K)`` of weights ``w`` to ``rows``, whose normalized weights count
        ``mass`` ``(R,)`` each, and resample each union (low-variance, to ``N`` or the
        KLD-sampling count; not roughened); a row whose union weighs nothing is left as it
        is."""
        rkern.join_rows(self.edge, self.s, self.v, self.w, self.count,
                        np.ascontiguousarray(rows, dtype=np.int64),
                        np.ascontiguousarray(mass, dtype=np.float64),
                        np.ascontiguousarray(edge, dtype=self.edge.dtype),
                        np.ascontiguousarray(s, dtype=np.float64),
                        np.ascontiguousarray(v, dtype=np.float64),
                        np.ascontiguousarray(w, dtype=np.float64), rng.random(rows.size),
                        self._bins, self._bin_m, self._speed_bin, self._seen, self._table)

    def roughen(self, rows: IntArray, rng: np.random.Generator) -> None:
        """The roughening of ``rows``' speeds just resampled (nothing without one)."""
        if self.roughening is not None and self.speeds is not None:
            self.roughening.roughen(self.v, rows, self.speeds.min_speed_mps,
                                    self.speeds.max_speed_mps, rng, self.count)

    def take(self, rows: IntArray) -> None:
        """Replace the clouds by ``rows`` of themselves (a top-level resampling)."""
        self.edge, self.s, self.w, self.v = (self.edge[rows], self.s[rows], self.w[rows],
                                             self.v[rows])
        self.count = self.count[rows]

    def _courier(self, motion: CourierRoadMotion, dt_s: float,
                 rng: np.random.Generator) -> None:
        """:meth:`CourierRoadMotion.step` by the kernels, from the same draws, in place."""
        if self.speeds is None:
            raise InvalidInputError("motion", motion, "the clouds carry no speed state: build "
                                    "them with speeds=")
        stop, go = motion.switch_chances(dt_s)
        e, pos, v = self._flat()
        mode, u = rng.random(pos.size), rng.random(pos.size)
        over = kern.courier_move(e, pos, v, mode, u, stop, go, motion.min_speed_mps,
                                 motion.max_speed_mps, float(dt_s), self.roads.length,
                                 self.count)
        self._turn(e, pos, over, rng)

    def _flat(self) -> tuple[IntArray, FloatArray, FloatArray]:
        """Flat views of ``edge``, ``s`` and ``v`` (C-contiguous first) for the motion kernels,
        which update them in place."""
        self.edge, self.s, self.v = (np.ascontiguousarray(self.edge),
                                     np.ascontiguousarray(self.s), np.ascontiguousarray(self.v))
        return self.edge.reshape(-1), self.s.reshape(-1), self.v.reshape(-1)

    def _turn(self, e: IntArray, pos: FloatArray, over: IntArray,
              rng: np.random.Generator) -> None:
        """Carry the particles ``over`` (indices into the flat views ``e``, ``pos``) onto
        successor edges until none is past its edge's end (one uniform per crossing, as
        DirectedRoads.advance draws them)."""
        roads = self.roads
        while over.size:
            over = kern.turn(e, pos, over, rng.random(over.size), roads.length,
                             roads.successors, roads.successor_ptr)


def node_trackers(roads: DirectedRoads, edge: IntArray, s: FloatArray,
                  w: FloatArray) -> tuple[NodeTracker, ...]:
    """One :class:`~searchtrack.estimate.node_tracker.NodeTracker` per cloud of a ``(M, N)``
    batch (track id = row): each particle's weight goes to the nearer end node of its edge."""
    node = np.where(s < 0.5 * roads.length[edge], roads.tail[edge], roads.head[edge])
    n = roads.network.n_nodes
    key = (node + np.arange(edge.shape[0])[:, None] * n).ravel()
    mass = np.bincount(key, weights=w.ravel(), minlength=edge.shape[0] * n).reshape(-1, n)
    mass = mass / mass.sum(axis=1, keepdims=True)
    return tuple(NodeTracker(mass[m], m) for m in range(mass.shape[0]))


class RoadParticleFilter:
    """One target's particle filter on directed roads (paper §2.1), ``N`` particles.

    Parameters
    ----------
    roads
        The directed roads.
    n_particles
        ``N ≥ 1`` (500 in the paper).
    rng
        Draws the uniform initial cloud (Eq. 1).
    motion, sensor, resample
        Motion model (Eq. 9), measurement model (Eq. 10–11), resampling policy.
    """

    def __init__(self, roads: DirectedRoads, n_particles: int, rng: np.random.Generator, *,
                 motion: RoadMotion | None = None, sensor: DiscSensor | None = None,
                 resample: ResamplePolicy | None = None) -> None:
        self._start(RoadClouds.uniform(roads, 1, n_particles, rng, sensor=sensor or DiscSensor(),
                                       resample=resample or ResamplePolicy()), motion)

    def _start(self, clouds: RoadClouds, motion: RoadMotion | None) -> None:
        self.motion = motion or RoadMotion()
        self.clouds = clouds
        self._bins = RoadBins(clouds.roads)

    @classmethod
    def from_particles(cls, roads: DirectedRoads, edge: ArrayLike, s: ArrayLike,
                       w: ArrayLike | None = None, *, motion: RoadMotion | None = None,
                       sensor: DiscSensor | None = None,
                       resample: ResamplePolicy | None = None) -> RoadParticleFilter:
        """A filter holding the given ``(N,)`` particles (uniform weights if ``w`` is None)."""
        out = cls.__new__(cls)
        ww = None if w is None else np.asarray(w, dtype=np.float64)[None]
        out._start(RoadClouds(roads, np.asarray(edge)[None], np.asarray(s)[None], ww,
                              sensor=sensor or DiscSensor(), resample=resample or ResamplePolicy()),
                   motion)
        return out

    @property
    def roads(self) -> DirectedRoads:
        """The directed roads."""
        return self.clouds.roads

    @property
    def n_particles(self) -> int:
        """``N``."""
        return self.clouds.shape[1]

    def particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(edge, s, w)``, each ``(N,)`` (copies)."""
        c = self.clouds
        return c.edge[0].copy(), c.s[0].copy(), c.w[0].copy()

    def points(self) -> FloatArray:
        """``(N, 2)`` planar particle points ``G(x)``."""
        return np.asarray(self.clouds.points()[0], dtype=np.float64)

    def n_eff(self) -> float:
        """Effective sample size (Eq. 5)."""
        return float(effective_sample_size(self.clouds.w[0]))

    def predict(self, dt_s: float, rng: np.random.Generator) -> None:
        """Move every particle ``dt_s`` seconds on (Eq. 2, Eq. 9)."""
        self.clouds.predict(self.motion, dt_s, checks.generator("rng", rng))

    def likelihood_sum(self, y: ArrayLike, uav_xy: ArrayLike | None = None) -> float:
        """Eq. 16's sum for this filter: ``Σ_n w^n p(y | x^n)`` (Eq. 10), i.e.
        ``(1/N) Σ_n p(y | x^n)`` after resampling; ``uav_xy`` is needed by the ``"view"`` clutter
        convention only."""
        yy = checks.finite_array("y", y, (2,))
        c = self.clouds.sensor.clutter_density(self.roads, uav_xy)
        return float(self.clouds.detection_sums(yy, c)[0])

    def update(self, y: ArrayLike | None, uav_xy: ArrayLike, rng: np.random.Generator) -> float:
        """Weigh by a detection ``y`` ``(2,)`` (Eq. 10) or, if ``y`` is None, by the miss of a
        UAV at ``uav_xy`` (Eq. 11); resample as the policy says. Returns the measurement's
        likelihood ``Σ_n w p(· | x)`` before the update."""
        uav = checks.finite_array("uav_xy", uav_xy, (2,))
        checks.generator("rng", rng)
        rows = np.zeros(1, dtype=np.int64)
        if y is None:
            return float(self.clouds.miss(uav, rows, rng)[0])
        total = self.likelihood_sum(y, uav)
        self.clouds.weigh(rows, rng)
        return total

    def _bins_of(self, bin_m: float) -> RoadBins:
        """Road bins of ``bin_m`` metres (kept for the last size asked)."""
        if self._bins.bin_m != bin_m:
            self._bins = RoadBins(self.roads, bin_m)
        return self._bins

    def entropy(self, bin_m: float = 5.0) -> float:
        """Entropy (nats) on road bins of ``bin_m`` metres (Eq. 19)."""
        c = self.clouds
        return float(entropy(self._bins_of(bin_m), c.edge, c.s, c.w)[0])

    def map_position(self, bin_m: float = 5.0) -> FloatArray:
        """``(2,)`` centre of the densest bin."""
        c = self.clouds
        return np.asarray(map_positions(self._bins_of(bin_m), c.edge, c.s, c.w)[0],
                          dtype=np.float64)
