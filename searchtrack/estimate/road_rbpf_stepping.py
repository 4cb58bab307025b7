"""The road RBPF of Moore et al. 2021 as a :class:`~searchtrack.estimate.stepping.SteppedFilter`.

:class:`~searchtrack.estimate.road_rbpf.RoadRBPF` takes a generator at every call (predict,
update); a closed loop steps any filter by the two verbs of
:mod:`~searchtrack.estimate.stepping` with the generator owned by the filter.
:class:`SteppedRoadRBPF` is that: :meth:`~SteppedRoadRBPF.predict` moves every particle on,
:meth:`~SteppedRoadRBPF.update` takes one UAV's scan (its detections, from its position). It is
also the :class:`~searchtrack.estimate.belief.RoadParticleBelief` the road-search planners and
the RL policy read, and gives the paper's read-outs (:meth:`~SteppedRoadRBPF.summary`: the
entropy per target, the pooled entropy of Fig. 10–11, the MAP positions). Built from a
generator, it draws exactly what the bare filter draws with that generator passed to every
call.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.models.road_particles import DirectedRoads


class SteppedRoadRBPF:
    """A :class:`RoadRBPF` with its generator: stepped by predict and update.

    Parameters
    ----------
    roads
        The directed roads.
    config
        The filter's configuration.
    rng
        The filter's generator: the initial particles, the motion noise, the association
        draws and the resampling.
    """

    def __init__(self, roads: DirectedRoads, config: RBPFConfig,
                 rng: np.random.Generator) -> None:
        self._rng = checks.generator("rng", rng)
        self.filter = RoadRBPF(roads, config, self._rng)
        """The filter stepped (its histories, weights and association read-outs)."""

    @property
    def roads(self) -> DirectedRoads:
        """The directed roads."""
        return self.filter.roads

    @property
    def n_targets(self) -> int:
        """``M``."""
        return self.filter.n_targets

    def predict(self, dt_s: float) -> None:
        """Move every particle of every filter ``dt_s`` seconds on (Eq. 2, Eq. 9)."""
        self.filter.predict(dt_s, self._rng)

    def update(self, scan: ArrayLike, pose: ArrayLike) -> None:
        """One scan: ``scan`` the ``(k, 2)`` detections (``k ≥ 0``) of a UAV at ``pose``
        ``(2,)`` (Eq. 10–11, 15–16)."""
        self.filter.update(scan, pose, self._rng)

    def target_particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(edge, s, w)`` of the best history, each ``(M, N)`` (copies)."""
        return self.filter.target_particles()

    def target_entropy(self) -> FloatArray:
        """``(M,)`` entropy (nats) of each target of the best history."""
        return self.filter.target_entropy()

    def combined_entropy(self) -> float:
        """Entropy (nats) of the best history's targets pooled (Fig. 10–11)."""
        return self.filter.combined_entropy()

    def summary(self) -> tuple[FloatArray, float, FloatArray]:
        """Entropy per target, pooled entropy and ``(M, 2)`` MAP positions at once."""
        return self.filter.summary()
