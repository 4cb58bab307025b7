"""Point estimates from a particle PHD: measurement attribution or weighted k-means.

- ``"attribution"`` (Ristic, Clark & Vo 2010): the update splits each measurement's unit of
  evidence over the particles; a measurement whose term carries mass ``ρ_z`` above the threshold
  (0.5) yields the weighted mean of that term as one target. No clustering, O(k) after the update.
  With ``report_missed`` the targets of the previous scan that no measurement explained are
  added when their Bernoulli existence passes the threshold (see
  :mod:`searchtrack.estimate.phd.update`).
- ``"kmeans"``: ``K = round(λ)`` clusters, seeded greedily at the highest-weight particles (each
  seed bars particles within ``kmeans_seed_radius_m`` from seeding again), refined by weighted
  Lloyd iterations that ignore particles beyond that radius; the centres are the estimates.
  Its clusters also feed the found-target bookkeeping of paper 004
  (:mod:`searchtrack.estimate.phd.found`).

Run it on the updated weights, before resampling (k-means seeds need unequal weights).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.state import PHDState


@dataclass(frozen=True)
class Estimates:
    """Estimated targets: ``(k, d)`` states and the ``(k,)`` PHD mass behind each."""

    states: FloatArray
    masses: FloatArray
    position_dim: int

    @property
    def positions(self) -> FloatArray:
        """``(k, position_dim)`` estimated positions."""
        return self.states[:, : self.position_dim]

    def __len__(self) -> int:
        return int(self.masses.shape[0])


@dataclass(frozen=True)
class Clusters:
    """A weighted k-means partition of the particles.

    Attributes
    ----------
    centres
        ``(K, d)`` weighted mean state of each cluster.
    masses
        ``(K,)`` summed particle weight.
    radii_m
        ``(K,)`` weighted root-mean-square distance of the cluster's particle positions to its
        centre (m).
    members
        ``(N,)`` cluster index of each particle (``-1``: farther than the seed radius from
        every centre).
    """

    centres: FloatArray
    masses: FloatArray
    radii_m: FloatArray
    members: IntArray


def _merge(states: FloatArray, masses: FloatArray, p: int,
           radius_m: float) -> tuple[FloatArray, FloatArray]:
    """Greedy merge, heaviest first, of estimates closer than ``radius_m`` (mass-weighted)."""
    order = np.argsort(-masses, kind="stable")
    states, masses = states[order], masses[order]
    used = np.zeros(masses.shape[0], dtype=bool)
    out_s: list[FloatArray] = []
    out_m: list[float] = []
    for i in range(masses.shape[0]):
        if used[i]:
            continue
        near = ~used & (np.linalg.norm(states[:, :p] - states[i, :p], axis=1) <= radius_m)
        used |= near
        m = masses[near]
        out_s.append(m @ states[near] / m.sum())
        out_m.append(float(m.sum()))
    d = states.shape[1]
    return (np.array(out_s).reshape(-1, d), np.array(out_m, dtype=np.float64))


def extract_attribution(state: PHDState, config: PHDConfig) -> Estimates:
    """Estimates from the measurement terms of the last update with mass above the threshold,
    plus (``report_missed``) the missed targets whose existence passes it."""
    rec, thr = state.record, config.attribution_threshold
    keep = rec.detection_masses > thr
    states, masses = rec.detection_states[keep], rec.detection_masses[keep]
    if config.report_missed:
        more = rec.missed_existence > thr
        states = np.vstack([states, rec.missed_states[more]])
        masses = np.concatenate([masses, rec.missed_existence[more]])
    if config.merge_radius_m > 0.0 and masses.shape[0] > 1:
        states, masses = _merge(states, masses, state.position_dim, config.merge_radius_m)
    return Estimates(states, masses, state.position_dim)


def kmeans_clusters(state: PHDState, k: int, config: PHDConfig) -> Clusters:
    """Weighted k-means with ``k`` clusters seeded at the highest-weight particles.

    Particles farther than ``kmeans_seed_radius_m`` from every centre are outliers: they belong
    to no cluster (member ``-1``) and do not pull the centres (a trimmed k-means; without it the
    thin birth mass spread over the area drags every centre away from its target).
    """
    x, w, p = state.states, state.weights, state.position_dim
    n, d = x.shape
    k = min(k, n)
    if k <= 0:
        return Clusters(np.empty((0, d)), np.empty(0), np.empty(0),
                        np.full(n, -1, dtype=np.int64))
    pos = x[:, :p]
    free = w.copy()
    seeds = np.empty(k, dtype=np.int64)
    r2 = config.kmeans_seed_radius_m**2
    for j in range(k):
        i = int(np.argmax(free))
        seeds[j] = i
        free[((pos - pos[i]) ** 2).sum(axis=1) <= r2] = -1.0
    centres = pos[seeds].copy()
    slot = np.zeros(n, dtype=np.int64)
    for _ in range(config.kmeans_iterations):
        d2 = ((pos[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
        slot = np.argmin(d2, axis=1).astype(np.int64)
        slot[d2[np.arange(n), slot] > r2] = k  # outlier slot
        m = np.bincount(slot, weights=w, minlength=k + 1)[:k]
        for c in range(p):
            s = np.bincount(slot, weights=w * pos[:, c], minlength=k + 1)[:k]
            centres[:, c] = np.where(m > 0.0, s / np.where(m > 0.0, m, 1.0), centres[:, c])
    mass = np.asarray(np.bincount(slot, weights=w, minlength=k + 1)[:k], dtype=np.float64)
    safe = np.where(mass > 0.0, mass, 1.0)
    full = np.empty((k, d))
    for c in range(d):
        full[:, c] = np.bincount(slot, weights=w * x[:, c], minlength=k + 1)[:k] / safe
    full[:, :p] = centres
    sq = ((pos - np.vstack([centres, np.zeros((1, p))])[slot]) ** 2).sum(axis=1)
    radii = np.sqrt(np.bincount(slot, weights=w * sq, minlength=k + 1)[:k] / safe)
    return Clusters(full, mass, radii, np.where(slot < k, slot, -1))


def extract_kmeans(state: PHDState, config: PHDConfig) -> tuple[Estimates, Clusters]:
    """``round(λ)`` weighted k-means centres as estimates, and the clusters behind them."""
    clusters = kmeans_clusters(state, round(state.expected_count()), config)
    return Estimates(clusters.centres, clusters.masses, state.position_dim), clusters


def extract(state: PHDState, config: PHDConfig) -> Estimates:
    """Estimates by ``config.extraction`` (``"attribution"`` or ``"kmeans"``)."""
    if config.extraction == "kmeans":
        return extract_kmeans(state, config)[0]
    return extract_attribution(state, config)
