"""The Rao-Blackwellized particle filter of Moore et al. 2021 (§3): a particle filter over
association histories, each carrying a bank of road particle filters, one per target.

State: ``H`` history particles with weights ``W`` ``(H,)``; history ``h`` holds ``M`` clouds of
``N`` particles ``(edge, s, w)`` stored as one :class:`~searchtrack.estimate.road_pf.RoadClouds`
of ``H·M`` rows (row ``h·M + m``), so every step is vectorised over ``H·M·N`` particles.

One cycle (the paper gives no pseudo-code; §3.1–3.3 read together):

1. :meth:`RoadRBPF.predict`: every particle moves (Eq. 2, Eq. 9).
2. :meth:`RoadRBPF.update` with the scan's detections (possibly none):

   - No detection: negative update (Eq. 11) on every filter of every history (§3.1).
   - Each detection ``y`` in turn: per history, ``L_m = Σ_n w p(y | x^{h,m,n})`` (Eq. 16 with
     Eq. 10); the association ``c ~ Categorical(L / ΣL)`` (data association sampling, Eq. 15–16);
     filter ``(h, c)`` is weighed by Eq. 10 and resampled. With ``config.births`` (beyond the
     paper) ``L_m`` and the update are those of the prior regularised near ``y``, with draws
     there (:mod:`searchtrack.estimate.road_births`).
   - Optionally (``miss_undetected``, as the authors' code does when one target is seen) the
     filters that got no detection in the scan get the negative update.
   - Top-level weights, which the paper does not give: with DAS as the proposal, the importance
     weight of a sampled association is ``p(y, c) / q(c) = (1/M) Σ_m L_m``, the marginal
     likelihood (``history_weight="marginal"``, default); ``"sampled"`` multiplies by ``L_c``
     instead. With ``weigh_misses`` (default) a history is also weighed by the no-detection
     likelihood ``Π_m Σ_n w p(z | x^{h,m,n})`` of its missed targets, as the factorisation of
     Eq. 13 requires (the clutter-free factor ``1 − P_FA`` is common to all histories and
     cancels).
   - ``W`` is normalized and the histories are resampled (low-variance, every scan or
     ``N_eff``-gated).

Symmetry breaking: the targets are exchangeable under the uniform prior, so the first detection
ever is assigned to target 0 in every history (as the authors' code does).

Several detections in one scan (the paper processes them one by one and may give two to one
target): ``association="sequential"`` does exactly that; ``association="joint"`` samples one
assignment per history without duplicates, each detection choosing by DAS among the targets not
yet used in the scan (importance weight ``Σ_avail L_m / |avail|``, a uniform prior over
one-to-one assignments); once every target is used, further detections of the scan are taken as
clutter (no filter update, no weight change).

The planner and metrics use the best history, the one of highest weight at the last update
(before resampling evened the weights), as the authors' code does.
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.estimate.road_births import birth_draws, join_births
from searchtrack.estimate.road_entropy import (
    RoadBins,
    combined_entropy,
    entropy,
    map_positions,
    summary,
)
from searchtrack.estimate.road_jumps import (
    detection_prior_likelihood,
    jump_detection,
    jump_miss,
    miss_prior_likelihood,
)
from searchtrack.estimate.road_pf import RoadClouds, node_trackers
from searchtrack.estimate.road_rbpf_config import RBPFConfig as RBPFConfig
from searchtrack.models.road_particles import DirectedRoads

log = logging.getLogger("searchtrack.estimate.road_rbpf")


class RoadRBPF:
    """Rao-Blackwellized particle filter over association histories (paper §3.2–3.3); a
    :class:`~searchtrack.estimate.belief.RoadParticleBelief` through its best history.

    Parameters
    ----------
    roads
        The directed roads.
    config
        Sizes, models and options.
    rng
        Draws the uniform initial clouds (Eq. 1).
    """

    def __init__(self, roads: DirectedRoads, config: RBPFConfig,
                 rng: np.random.Generator) -> None:
        if not isinstance(config, RBPFConfig):
            raise InvalidInputError("config", config, "must be an RBPFConfig")
        self._start(config, RoadClouds.uniform(
            roads, config.n_histories * config.n_targets, config.n_particles,
            checks.generator("rng", rng), sensor=config.sensor, resample=config.resample,
            speeds=config.speeds, roughening=config.roughening, counts=config.counts))

    def _start(self, config: RBPFConfig, clouds: RoadClouds) -> None:
        roads, h = clouds.roads, config.n_histories
        self.config, self.clouds = config, clouds
        self.bins = RoadBins(roads, config.bin_m)
        self.weights = np.full(h, 1.0 / h)
        self.scores = self.weights.copy()
        self.last_association = np.empty((h, 0), dtype=np.int64)
        self._history = np.empty((h, 0), dtype=np.int64)
        self._detected_before = not config.break_symmetry
        self._since_update_s = 0.0   # time predicted since the last update (for the jumps)

    @classmethod
    def from_particles(cls, roads: DirectedRoads, config: RBPFConfig, edge: ArrayLike,
                       s: ArrayLike, w: ArrayLike | None = None) -> RoadRBPF:
        """A filter whose every history starts from the given target clouds ``(M, N)``
        (uniform weights if ``w`` is None), e.g. an informative prior; with the drive-and-stop
        motion the particles start stopped."""
        if not isinstance(config, RBPFConfig):
            raise InvalidInputError("config", config, "must be an RBPFConfig")
        shape = (config.n_targets, config.n_particles)
        arrays = [np.asarray(edge), np.asarray(s)] + ([] if w is None else [np.asarray(w)])
        for name, a in zip(("edge", "s", "w"), arrays, strict=False):
            if a.shape != shape:
                raise InvalidInputError(name, a.shape, f"must have shape {shape}")
        h = config.n_histories
        out = cls.__new__(cls)
        out._start(config, RoadClouds(roads, np.tile(arrays[0], (h, 1)),
                                      np.tile(arrays[1], (h, 1)),
                                      None if w is None else np.tile(arrays[2], (h, 1)),
                                      sensor=config.sensor, resample=config.resample,
                                      speeds=config.speeds, roughening=config.roughening,
                                      counts=config.counts))
        return out

    @property
    def roads(self) -> DirectedRoads:
        """The directed roads."""
        return self.clouds.roads

    @property
    def n_targets(self) -> int:
        """``M``."""
        return self.config.n_targets

    @property
    def n_histories(self) -> int:
        """``H``."""
        return self.config.n_histories

    def _grid(self, a: np.ndarray) -> np.ndarray:
        return a.reshape(self.n_histories, self.n_targets, -1)

    # -- the cycle ------------------------------------------------------------------------------

    def predict(self, dt_s: float, rng: np.random.Generator) -> None:
        """Move every particle of every filter ``dt_s`` seconds on (Eq. 2 with the config's
        motion, Eq. 9 by default); with ``config.jumps`` the next update also weighs a jump
        anywhere on the roads, with chance ``1 − exp(−λ t)`` for the time ``t`` predicted since
        the last update."""
        self.clouds.predict(self.config.motion, dt_s, checks.generator("rng", rng))
        self._since_update_s += dt_s

    def step(self, dt_s: float, detections: ArrayLike, uav_xy: ArrayLike,
             rng: np.random.Generator) -> None:
        """:meth:`predict` then :meth:`update`."""
        self.predict(dt_s, rng)
        self.update(detections, uav_xy, rng)

    def update(self, detections: ArrayLike, uav_xy: ArrayLike, rng: np.random.Generator) -> None:
        """One scan of a UAV at ``uav_xy`` ``(2,)``: ``detections`` ``(k, 2)``, ``k ≥ 0``.

        Raises
        ------
        InvalidInputError
            Detections not finite ``(k, 2)``, ``uav_xy`` not finite ``(2,)``, ``rng`` not a
            ``numpy.random.Generator``.
        """
        ys = checks.points("detections", detections)
        uav = checks.finite_array("uav_xy", uav_xy, (2,))
        checks.generator("rng", rng)
        density = self.config.sensor.clutter_density(self.roads, uav) if ys.shape[0] else 0.0
        jumps = self.config.jumps
        eps = jumps.probability(self._since_update_s) if jumps is not None else 0.0
        self._since_update_s = 0.0
        if ys.shape[0] and density == 0.0:
            # No road in view: no target and no clutter can be there (Eq. 10 is 0 for every
            # history); the scan is read as seeing nothing.
            log.debug("%d detections with no road in view of %s: taken as clutter and the "
                      "scan as a miss", ys.shape[0], uav.tolist())
            self.last_association = np.full((self.n_histories, ys.shape[0]), -1, dtype=np.int64)
            self._miss(uav, np.arange(self.n_histories * self.n_targets), eps, rng)
        elif ys.shape[0]:
            self._detections(ys, uav, density, eps, rng)
        else:
            self.last_association = np.empty((self.n_histories, 0), dtype=np.int64)
            self._miss(uav, np.arange(self.n_histories * self.n_targets), eps, rng)
        self._resample_histories(rng)

    def _miss(self, uav: FloatArray, rows: IntArray, eps: float,
              rng: np.random.Generator) -> None:
        """Eq. 11 on ``rows``; with a jump chance ``eps > 0`` the jump draws are joined and the
        union is the one resampling."""
        jumps = self.config.jumps if eps > 0.0 else None
        sums = self.clouds.miss(uav, rows, rng, resample=jumps is None)
        if jumps is not None:
            jump_miss(self.clouds, jumps, eps, rows, sums, uav, rng)
            sums = (1.0 - eps) * sums + eps * miss_prior_likelihood(self.roads,
                                                                    self.config.sensor, uav)
        if self.config.weigh_misses:
            factor = np.ones(self.n_histories * self.n_targets)
            factor[rows] = sums
            self.weights *= factor.reshape(self.n_histories, self.n_targets).prod(axis=1)

    def _detections(self, ys: FloatArray, uav: FloatArray, density: float, eps: float,
                    rng: np.random.Generator) -> None:
        h, m = self.n_histories, self.n_targets
        joint = self.config.association == "joint"
        used = np.zeros((h, m), dtype=bool)
        assigned = np.full((h, ys.shape[0]), -1, dtype=np.int64)
        hist = np.arange(h)
        jumps = self.config.jumps if eps > 0.0 else None
        births = self.config.births
        for j, y in enumerate(ys):
            sums = self.clouds.detection_sums(y, density)
            draws = None
            if births is not None:   # each cloud's prior regularised near y
                k = births.draws(self.config.n_particles)
                draws = birth_draws(self.clouds, births, y, density, rng.random((3, h * m, k)))
                sums = draws.sums
            lik = sums.reshape(h, m)
            if jumps is not None:   # the robust prior: a target anywhere may explain y
                lik = (1.0 - eps) * lik + eps * detection_prior_likelihood(
                    self.roads, self.config.sensor, y, density)
            avail = ~used if joint else np.ones((h, m), dtype=bool)
            if not self._detected_before:
                c = np.zeros(h, dtype=np.int64)
                factor = lik[:, 0]
                self._detected_before = True
            else:
                c, factor = self._sample(lik, avail, rng)
            live = c >= 0
            self.weights[live] *= factor[live]
            rows = hist[live] * m + c[live]
            if draws is not None:
                join_births(self.clouds, rows, draws, rng)
            else:
                self.clouds.weigh(rows, rng, resample=jumps is None)
                if jumps is not None:
                    jump_detection(self.clouds, jumps, eps, rows, sums[rows], y, density, rng)
            used[hist[live], c[live]] = True
            assigned[:, j] = c
        self.last_association = assigned
        if self.config.keep_history:
            self._history = np.concatenate([self._history, assigned], axis=1)
        if self.config.miss_undetected:
            self._miss(uav, np.flatnonzero(~used.ravel()), eps, rng)

    def _sample(self, lik: FloatArray, avail: np.ndarray,
                rng: np.random.Generator) -> tuple[IntArray, FloatArray]:
        """DAS (Eq. 15–16): one target per history among ``avail`` (−1 if none), and the
        history's weight factor."""
        n_avail = avail.sum(axis=1)
        p = np.where(avail, lik, 0.0)
        total = p.sum(axis=1)
        flat = (total <= 0.0) & (n_avail > 0)
        p[flat] = avail[flat]
        cdf = np.cumsum(p, axis=1)
        u = rng.random(lik.shape[0]) * cdf[:, -1]
        c = np.minimum((cdf <= u[:, None]).sum(axis=1), lik.shape[1] - 1)
        c = np.where(n_avail > 0, c, -1)
        if self.config.history_weight == "marginal":
            factor = total / np.maximum(n_avail, 1)
        else:
            factor = lik[np.arange(lik.shape[0]), np.maximum(c, 0)]
        return c.astype(np.int64), factor

    def _resample_histories(self, rng: np.random.Generator) -> None:
        total = float(self.weights.sum())
        if not np.isfinite(total) or total <= 0.0:
            log.warning("every association history has weight 0; weights reset to uniform")
            self.weights[:] = 1.0
            total = float(self.n_histories)
        self.weights /= total
        self.scores = self.weights.copy()
        if not self.config.history_resample.due(self.weights[None])[0]:
            return
        idx = kern.systematic_row(self.weights, float(rng.random(1)[0]))
        if not np.array_equal(idx, np.arange(self.n_histories)):
            m = self.n_targets
            self.clouds.take((idx[:, None] * m + np.arange(m)).ravel())
            self.last_association = self.last_association[idx]
            self._history = self._history[idx]
            self.scores = self.scores[idx]
        self.weights[:] = 1.0 / self.n_histories

    # -- outputs --------------------------------------------------------------------------------

    def best(self) -> int:
        """Index of the best history: the highest weight at the last update (lowest on ties)."""
        return int(np.argmax(self.scores))

    def history_particles(self, h: int) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(edge, s, w)`` of history ``h``, each ``(M, N)`` (copies)."""
        k = checks.count("h", h)
        if k >= self.n_histories:
            raise InvalidInputError("h", h, f"histories are 0…{self.n_histories - 1}")
        c = self.clouds
        return (self._grid(c.edge)[k].copy(), self._grid(c.s)[k].copy(),
                self._grid(c.w)[k].copy())

    def target_particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(edge, s, w)`` of the best history, each ``(M, N)`` (copies)."""
        return self.history_particles(self.best())

    def target_entropy(self) -> FloatArray:
        """``(M,)`` entropy (nats) of each target of the best history on bins of ``bin_m``."""
        return entropy(self.bins, *self.target_particles())

    def history_entropy(self) -> FloatArray:
        """``(H, M)`` entropy (nats) of every filter of every history."""
        c = self.clouds
        return entropy(self.bins, c.edge, c.s, c.w).reshape(self.n_histories, self.n_targets)

    def combined_entropy(self, bin_m: float | None = None) -> float:
        """Entropy (nats) of the best history's targets pooled (the paper's Fig. 10–11)."""
        bins = self.bins if bin_m is None else RoadBins(self.roads, bin_m)
        return combined_entropy(bins, *self.target_particles())

    def map_positions(self) -> FloatArray:
        """``(M, 2)`` centre of each target's densest bin in the best history."""
        return map_positions(self.bins, *self.target_particles())

    def summary(self) -> tuple[FloatArray, float, FloatArray]:
        """:meth:`target_entropy`, :meth:`combined_entropy` and :meth:`map_positions` at once
        (the best history's particles taken, checked and binned once)."""
        return summary(self.bins, *self.target_particles())

    def best_association(self) -> IntArray:
        """``(k,)`` the best history's target for each detection of the last scan (−1:
        clutter)."""
        return np.array(self.last_association[self.best()], copy=True)

    def association_probabilities(self) -> FloatArray:
        """``(k, M)``: for each detection of the last scan, the posterior weight of the histories
        that gave it to each target (after resampling, the share of the histories; rows sum to
        1 unless some histories took the detection as clutter)."""
        a = self.last_association
        out = np.zeros((a.shape[1], self.n_targets))
        for j in range(a.shape[1]):
            ok = a[:, j] >= 0
            np.add.at(out[j], a[ok, j], self.weights[ok])
        return out

    def association_history(self) -> IntArray:
        """``(H, K)`` every history's association of each of the ``K`` detections so far."""
        if not self.config.keep_history:
            raise InvalidInputError("keep_history", False, "the config does not keep histories")
        return np.array(self._history, copy=True)

    def node_beliefs(self) -> tuple[NodeTracker, ...]:
        """One node belief per target of the best history (each particle's weight on the
        nearer end node of its edge); track id = target index."""
        return node_trackers(self.roads, *self.target_particles())

    def belief_bank(self) -> TrackerBank:
        """:meth:`node_beliefs` as a :class:`~searchtrack.estimate.belief.BeliefBank`."""
        return TrackerBank(self.roads.network.n_nodes, self.node_beliefs(), self.n_targets)

    def particle_belief(self) -> WeightedParticles:
        """The best history's particles as planar points, each target's weights summing to 1
        (a :class:`~searchtrack.estimate.particle_belief.ParticleBelief` of mass ``M``)."""
        edge, s, w = self.target_particles()
        return WeightedParticles(self.roads.point(edge, s).reshape(-1, 2), w.ravel())
