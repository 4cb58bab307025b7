"""SMC-PHD update (paper 003, eq. 5; paper 004, eq. A6), sequential over sensors.

For one sensor at pose ``q`` with measurements ``Z`` and particles ``(x_i, w_i)``::

    L_{z,i} = p_d(x_i|q) g(z|x_i,q) w_i,      C_z = c(z|q) + Σ_i L_{z,i}
    w_i ← (1 − p_d(x_i|q)) w_i + Σ_z L_{z,i} / C_z

Several sensors are applied one after another (the iterated corrector). Besides the weights the
update records, for the extraction and the next prediction:

- per measurement, the mass ``ρ_z = Σ_i A_{z,i}`` of its term ``A_{z,i} = L_{z,i} / C_z`` (the
  expected number of targets behind ``z``) and the term's weighted mean state;
- per measurement, a birth seed at ``h⁻¹(z)``: the seeds share ``birth_mass`` in proportion to
  the part ``1 − ρ_z`` the PHD does not explain (Ristic et al. 2012, adaptive birth). With
  ``adaptive_birth`` the seed is ``birth_mass · (1 − ρ_z)`` itself, not renormalised, so the
  births follow the unexplained measurements instead of a constant total. Without clutter
  ``C_z = Σ_i L_{z,i}``, so ``ρ_z`` is 1 for a measurement any particle explains and 0 for one no
  particle can (``C_z = 0``): the renormalised shares of such a scan are ratios of rounding
  errors that still sum to ``birth_mass``. In paper 004's clutter-free search that raised the
  mass of a seen target from about 1 to about 1.1 (a small part of the upward drift of its
  expected count, most of which came from found targets' detections passing a gate too tight
  for the sensor noise: see :mod:`searchtrack.estimate.phd.found`). The adaptive seeds add
  ``Σ_z (1 − ρ_z)`` per unit of ``birth_mass``, and the update plus the next births add
  ``Σ_z ρ_z + birth_mass Σ_z (1 − ρ_z) ≤ |Z|`` (equal for ``birth_mass = 1``);
- per *missed target*: particles carry the tag of the group they were assigned to at the last
  update. A group with predicted mass ``P`` of which measurements explain less than one half is a
  target that may have been missed. Treating the group as a Bernoulli component with existence
  ``r = min(P, 1)`` and miss probability ``q = M / P`` (``M`` its weight not attributed to any
  measurement), its posterior existence is ``r q / (1 − r + r q)`` — where the Poisson PHD keeps
  only ``r q``, the known cause of a PHD's under-count after missed detections. This is a
  read-out used by the extraction; the PHD weights themselves follow the equation above.

- *one estimate per target*: the PHD lets one unit of mass explain two measurements (a target's
  and a clutter point 2σ away both get ``ρ_z`` near 1). Each measurement is charged to the tagged
  group carrying most of its term; a group of predicted mass ``P`` keeps the ``max(1, round(P))``
  measurements of largest ``ρ_z`` as estimates and the record shows ``ρ_z = 0`` for the others.
  With several sensors this also merges their detections of one target.

Afterwards each particle is tagged with the measurement that explains most of its weight (if it
explains more than half; a suppressed measurement hands its particles to its group's keeper),
else with its missed group if that group's existence passes ``attribution_threshold``, else
``NO_TAG``. With several sensors the records are approximate: the attribution of a later sensor
uses the weights left by the earlier ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.kernel_threads import threads_for
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.phd import compiled, gated
from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.state import NO_TAG, PHDState, UpdateRecord
from searchtrack.models.particle_models import DetectionSensor


@dataclass(frozen=True)
class SensorScan:
    """One sensor's measurements of one scan.

    Parameters
    ----------
    sensor
        The sensor model (``p_d``, ``g``, clutter, ``h⁻¹``).
    pose
        The sensor pose (``[x, y, z, ...]``; ignored by pose-free sensors).
    measurements
        ``(k, meas_dim)`` measurements (``k`` may be 0).
    """

    sensor: DetectionSensor
    pose: FloatArray
    measurements: FloatArray

    def __post_init__(self) -> None:
        z = np.array(self.measurements, dtype=np.float64)
        dim = self.sensor.meas_dim
        if z.size == 0:
            z = z.reshape(0, dim)
        if z.ndim != 2 or z.shape[1] != dim or not np.all(np.isfinite(z)):
            raise InvalidInputError("measurements", self.measurements,
                                    f"must be a finite (k, {dim}) array")
        pose = np.array(self.pose, dtype=np.float64).reshape(-1)
        if not np.all(np.isfinite(pose)):
            raise InvalidInputError("pose", self.pose, "must be finite")
        z.setflags(write=False)
        pose.setflags(write=False)
        object.__setattr__(self, "measurements", z)
        object.__setattr__(self, "pose", pose)


@dataclass
class _Terms:
    """Accumulated per-particle and per-measurement results over the sensors."""

    attributed: FloatArray
    best_share: FloatArray
    owner: IntArray
    means: list[FloatArray]
    rhos: list[FloatArray]
    seeds: list[FloatArray]
    groups: list[IntArray]
    offset: int = 0


def _dominant_group(a: FloatArray, tags: IntArray) -> IntArray:
    """``(k,)`` the tag whose particles carry most of each measurement's term (-1: untagged)."""
    if tags.shape[0] == 0 or tags.max(initial=NO_TAG) < 0:
        return np.full(a.shape[0], NO_TAG, dtype=np.int64)
    slot = tags + 1
    per_group = np.zeros((a.shape[0], int(slot.max()) + 1))
    for z in range(a.shape[0]):
        per_group[z] = np.bincount(slot, weights=a[z], minlength=per_group.shape[1])
    return np.asarray(np.argmax(per_group, axis=1) - 1, dtype=np.int64)


def _one_per_target(rho: FloatArray, group: IntArray, prior_mass: FloatArray) -> IntArray:
    """``(k,)`` for each measurement the measurement that keeps its estimate: within a tagged
    group of predicted mass ``P`` only the ``max(1, round(P))`` measurements of largest ``ρ`` keep
    theirs (a target yields at most one measurement); the others map to the group's first."""
    keeper = np.arange(rho.shape[0])
    for t in np.unique(group[group >= 0]):
        members = np.flatnonzero(group == t)
        cap = max(1, round(float(prior_mass[t]))) if t < prior_mass.shape[0] else 1
        if members.size > cap:
            order = members[np.argsort(-rho[members], kind="stable")]
            keeper[order[cap:]] = order[0]
    return keeper


def _correct(states: FloatArray, weights: FloatArray, tags: IntArray, position_dim: int,
             scan: SensorScan, acc: _Terms) -> FloatArray:
    """One sensor's update of ``weights``; appends its terms to ``acc``."""
    pos = states[:, :position_dim]
    pd = scan.sensor.detection_probability(scan.pose, pos)
    z = scan.measurements
    k = z.shape[0]
    if k == 0:
        return (1.0 - pd) * weights
    a = scan.sensor.likelihood(scan.pose, z, pos)
    a *= pd * weights
    c = scan.sensor.clutter_intensity(scan.pose, z) + a.sum(axis=1)
    a /= np.where(c > 0.0, c, 1.0)[:, None]
    per_particle = a.sum(axis=0)
    rho = a.sum(axis=1)
    means = a @ states
    means /= np.where(rho > 0.0, rho, 1.0)[:, None]
    if states.shape[0]:
        j = np.argmax(a, axis=0)
        share = a[j, np.arange(states.shape[0])]
        better = share > acc.best_share
        acc.owner[better] = j[better] + acc.offset
        acc.best_share[better] = share[better]
    acc.attributed += per_particle
    acc.groups.append(_dominant_group(a, tags))
    acc.means.append(means)
    acc.rhos.append(rho)
    acc.seeds.append(scan.sensor.to_position(scan.pose, z))
    acc.offset += k
    return np.asarray((1.0 - pd) * weights + per_particle, dtype=np.float64)


def _missed(state: PHDState, weights: FloatArray, acc: _Terms,
            threshold: float) -> tuple[FloatArray, FloatArray, IntArray]:
    """Missed groups' mean states and existence, and each particle's missed-group index (-1)."""
    n = state.n_particles
    group = state.tags
    none = np.full(n, -1, dtype=np.int64)
    if n == 0 or group.max(initial=NO_TAG) < 0:
        return np.empty((0, state.state_dim)), np.empty(0), none
    g = group.max() + 2
    slot = group + 1  # slot 0: untagged
    prior = np.bincount(slot, weights=state.weights, minlength=g)[1:]
    found = np.bincount(slot, weights=acc.attributed, minlength=g)[1:]
    rest = np.clip(weights - acc.attributed, 0.0, None)
    miss = np.bincount(slot, weights=rest, minlength=g)[1:]
    cand = np.flatnonzero((prior > 0.0) & (found < 0.5) & (miss > 0.0))
    if cand.size == 0:
        return np.empty((0, state.state_dim)), np.empty(0), none
    r = np.minimum(prior[cand], 1.0)
    q = miss[cand] / prior[cand]
    existence = r * q / (1.0 - r + r * q)
    index = np.full(g - 1, -1, dtype=np.int64)
    index[cand] = np.arange(cand.size)
    means = np.empty((cand.size, state.state_dim))
    for col in range(state.state_dim):
        means[:, col] = np.bincount(slot, weights=rest * state.states[:, col],
                                    minlength=g)[1:][cand] / miss[cand]
    member = np.where(group >= 0, index[np.maximum(group, 0)], -1)
    member[(member >= 0) & (existence[np.maximum(member, 0)] <= threshold)] = -1
    return means, existence, member


def _missed_from_sums(slot_sums: FloatArray, state_dim: int, threshold: float,
                      ) -> tuple[FloatArray, FloatArray, IntArray]:
    """Missed groups' mean states and existence, and per slot (tag + 1) the missed-group index
    of its particles (-1), from the per-slot sums ``[prior, attributed, rest, rest · x]``."""
    none = np.full(slot_sums.shape[0], -1, dtype=np.int64)
    prior, found, miss = slot_sums[1:, 0], slot_sums[1:, 1], slot_sums[1:, 2]
    cand = np.flatnonzero((prior > 0.0) & (found < 0.5) & (miss > 0.0))
    if cand.size == 0:
        return np.empty((0, state_dim)), np.empty(0), none
    r = np.minimum(prior[cand], 1.0)
    q = miss[cand] / prior[cand]
    existence = r * q / (1.0 - r + r * q)
    means = slot_sums[1:, 3:][cand] / miss[cand][:, None]
    member = none.copy()
    member[cand + 1] = np.where(existence > threshold, np.arange(cand.size), -1)
    return means, existence, member


def _update_compiled(state: PHDState, scans: Sequence[SensorScan], config: PHDConfig,
                     ) -> tuple[FloatArray, _Terms, FloatArray, FloatArray, FloatArray,
                                IntArray]:
    """The corrections by the gated passes of :mod:`searchtrack.estimate.phd.compiled`: the new
    weights, the terms, the missed groups and the tags before the one-estimate quota."""
    cor = compiled.gated_corrections(state.states, state.weights, state.tags, scans)
    acc = _Terms(cor.attributed, cor.best_share, cor.owner, cor.means, cor.rhos, cor.seeds,
                 cor.groups, sum(r.shape[0] for r in cor.rhos))
    missed_states, existence, member = _missed_from_sums(cor.slot_sums, state.state_dim,
                                                         config.attribution_threshold)
    return cor.weights, acc, missed_states, existence, cor.slot_sums[1:, 0], member


def update(state: PHDState, scans: Sequence[SensorScan], config: PHDConfig) -> PHDState:
    """The posterior PHD after the scans of every sensor (applied in order), with its record."""
    n, d, p = state.n_particles, state.state_dim, state.position_dim
    fast = config.backend == "numba" and compiled.gated_supported(state.states, scans)
    if fast:
        weights, acc, missed_states, existence, slot_mass, member = _update_compiled(
            state, scans, config)
    else:
        acc = _Terms(np.zeros(n), np.zeros(n), np.full(n, NO_TAG, dtype=np.int64), [], [], [],
                     [])
        weights = np.asarray(state.weights, dtype=np.float64)
        for scan in scans:
            weights = _correct(state.states, weights, state.tags, p, scan, acc)
        missed_states, existence, member = _missed(state, weights, acc,
                                                   config.attribution_threshold)
        slot_mass = np.asarray(np.bincount(state.tags + 1, weights=state.weights)[1:] if n else
                               np.empty(0), dtype=np.float64)
    rho = np.concatenate(acc.rhos) if acc.rhos else np.empty(0)
    keeper = _one_per_target(rho, np.concatenate(acc.groups) if acc.groups else
                             np.empty(0, dtype=np.int64), slot_mass)
    kept_rho = np.where(keeper == np.arange(rho.shape[0]), rho, 0.0)
    if fast:
        with threads_for(weights.size):
            tags = gated.final_tags(acc.best_share, weights, acc.owner, keeper, member,
                                    state.tags, acc.offset)
    else:
        owner = np.where(acc.owner >= 0, keeper[np.maximum(acc.owner, 0)], NO_TAG) \
            if rho.shape[0] else acc.owner
        tags = np.where(acc.best_share > 0.5 * weights, owner, NO_TAG)
        coast = (tags == NO_TAG) & (member >= 0)
        tags[coast] = acc.offset + member[coast]
    unexplained = np.clip(1.0 - rho, 0.0, None)
    if config.adaptive_birth:
        seed_mass = config.birth_mass * unexplained
    else:
        total = unexplained.sum()
        seed_mass = config.birth_mass * unexplained / total if total > 0.0 else unexplained * 0.0
    record = UpdateRecord(
        np.vstack(acc.means) if acc.means else np.empty((0, d)), kept_rho, missed_states,
        existence, np.vstack(acc.seeds) if acc.seeds else np.empty((0, p)), seed_mass)
    return PHDState(state.states, weights, state.labels, tags.astype(np.int64, copy=False), p,
                    record)
