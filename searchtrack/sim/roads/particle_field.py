"""The search field of a particle belief on roads: per node, how much of the untracked targets'
mass lies around it against what the uniform prior puts there (the particle counterpart of the
thesis 001 LRT's ``φ`` (3.3), read by the Ch. 5 guidance as a
:class:`~searchtrack.estimate.belief.SearchField`)."""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models import RoadNetwork

#: Lowest search score: where the particles left no mass (the LRT's default ``llr_floor``, so the
#: gradient force (5.7) keeps the scale its spring constants were chosen for).
SCORE_FLOOR = -20.0


class ParticleSearchField:
    """A :class:`~searchtrack.estimate.belief.SearchField` holding a finite score per node.

    Parameters
    ----------
    score
        ``(n,)`` finite scores (copied, read-only).
    """

    def __init__(self, score: FloatArray) -> None:
        self.score = checks.node_vector("score", score)

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        return int(self.score.size)

    def node_score(self) -> FloatArray:
        """The ``(n,)`` score (read-only, not a copy)."""
        return self.score



class ParticleFieldBuilder:
    """Turns node masses into a :class:`ParticleSearchField` on one network.

    The score of node ``v`` is ``log(max(S q / (k · S u), e^floor))``: ``q`` the pooled node
    mass of ``k`` targets, ``u`` the node mass of the uniform prior (each node holds half the
    length of its edges, as the nearer-end-node beliefs count), and ``S`` the sum over a
    neighbourhood of ``v`` the size of a disc of radius ``radius_m``: the plane is cut into
    square cells of side ``√π · radius_m / 3`` and ``S`` sums the 3 × 3 block of cells around
    ``v``'s cell (area ``π · radius_m²``). The ratio is 1 in expectation under the prior; summing
    over a neighbourhood tames the sampling noise of particles that sit on few of the nodes. The
    cells make a step cost linear in the nodes whatever the radius (summing over the exact disc
    costs one term per pair of nodes within it: 8 million on the bundled Aguascalientes map at
    ``ρ`` = 374 m).

    Parameters
    ----------
    network
        The road network.
    radius_m
        Radius (m) of the disc the neighbourhood stands for, > 0 (a mission uses the footprint
        ``ρ``: the score is then about the mass a UAV over ``v`` would see).
    floor
        The lowest score, finite and < 0.
    """

    def __init__(self, network: RoadNetwork, radius_m: float,
                 floor: float = SCORE_FLOOR) -> None:
        if not (math.isfinite(radius_m) and radius_m > 0.0):
            raise InvalidInputError("radius_m", radius_m, "must be finite and > 0 (m)")
        if not (math.isfinite(floor) and floor < 0.0):
            raise InvalidInputError("floor", floor, "must be finite and < 0")
        xy = network.coords
        cell = math.sqrt(math.pi) * radius_m / 3.0
        ij = np.floor((xy - xy.min(axis=0)) / cell)
        cells, node_cell = np.unique(ij, axis=0, return_inverse=True)
        index = {(a, b): k for k, (a, b) in enumerate(cells.tolist())}
        blank = len(cells)  # an always-empty cell for the neighbours no node falls in
        self._cell = np.asarray(node_cell, dtype=np.int64).ravel()
        self._block = np.array([[index.get((a + da, b + db), blank)
                                 for da in (-1.0, 0.0, 1.0) for db in (-1.0, 0.0, 1.0)]
                                for a, b in cells.tolist()], dtype=np.int64).reshape(-1, 9)
        half = 0.5 * np.asarray(network.lengths_m, dtype=np.float64)
        share = np.bincount(network.edges.ravel(), weights=np.repeat(half, 2),
                            minlength=network.n_nodes)
        self.uniform: FloatArray = self.neighbourhood_sum(share / share.sum())
        self.n_nodes = network.n_nodes
        self.floor = float(floor)

    def neighbourhood_sum(self, values: FloatArray) -> FloatArray:
        """``S values``: per node, the sum of ``values`` ``(n,)`` over its neighbourhood."""
        sums = np.bincount(self._cell, weights=values, minlength=self._block.shape[0] + 1)
        return np.asarray(sums[self._block].sum(axis=1)[self._cell], dtype=np.float64)

    def field(self, mass: FloatArray, n_targets: int) -> ParticleSearchField:
        """The field of ``n_targets`` targets' pooled node ``mass`` ``(n,)`` (summing to
        ``n_targets``); all 0 (the prior's value) when ``n_targets`` is 0."""
        if n_targets <= 0:
            return ParticleSearchField(np.zeros(self.n_nodes))
        near = self.neighbourhood_sum(np.asarray(mass, dtype=np.float64))
        ratio = near / (n_targets * self.uniform)
        return ParticleSearchField(np.log(np.maximum(ratio, math.exp(self.floor))))
