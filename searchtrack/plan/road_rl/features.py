"""The observation of the deep-RL road planner (Moore et al. 2021, §4.3, Eq. 22–26).

The paper feeds the policy one flat vector ``F_net`` (Eq. 26):

* the UAVs' positions ``A^q_{x,y}`` (here scaled to ``[0, 1]`` by the map's bounding box);
* per target a particle histogram over ``B`` road bins (Eq. 22): each directed edge is cut into
  ``bins_per_edge`` equal parts (10 in the authors' code), and a bin holds the target's particle
  mass there, scaled by ``B`` so that a uniform belief reads 1 in every bin;
* the targets' sigmoid weights ``γ`` (Eq. 20, 23);
* the map: node coordinates (Eq. 24, scaled like the UAV) and the edges (Eq. 25, each directed
  edge's tail and head node index over the number of nodes). They are constant for one map (a
  policy is trained per map) and can be left out (``include_map=False``).

Beyond the paper, two more blocks: the one-hot of the node the UAV is at (the action ``k`` is
the ``k``-th road leaving it, modulo its degree, so every action is valid), and, per action
slot ``k``, the weighted value (Eq. 21, both directions of the road) of the ``k``-th road leaving
the node and the best value one road further (zero for slots the node does not have), scaled
by the number of roads so that a uniform belief reads about 1 (``road_values``). The paper's
network must infer these from the histograms; given them, a small network trained briefly
learns what the one-step value says and where it misleads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_search.weights import edge_values, target_weights


@dataclass(frozen=True, eq=False)
class RoadFeatures:
    """Builds the flat observation of a policy for one map, ``M`` targets and ``Q`` UAVs.

    Parameters
    ----------
    roads
        The map.
    n_targets, n_uavs
        ``M`` and ``Q`` (≥ 1).
    bins_per_edge
        Histogram bins per directed edge (Eq. 22), ≥ 1.
    gain
        Sigmoid gain ``a`` of the weights (Eq. 20).
    include_map
        Append the node coordinates and edges (Eq. 24–25).
    road_values
        Append the per-slot road values (see the module docstring).
    """

    roads: DirectedRoads
    n_targets: int
    n_uavs: int = 1
    bins_per_edge: int = 10
    gain: float = 10.0
    include_map: bool = True
    road_values: bool = True
    _low: FloatArray = field(init=False, repr=False)
    _span: FloatArray = field(init=False, repr=False)
    _map_block: FloatArray = field(init=False, repr=False)
    _slots: int = field(init=False, repr=False)

    def __post_init__(self) -> None:
        checks.count("n_targets", self.n_targets, 1)
        checks.count("n_uavs", self.n_uavs, 1)
        checks.count("bins_per_edge", self.bins_per_edge, 1)
        checks.non_negative("gain", self.gain)
        coords = self.roads.network.coords
        low = coords.min(axis=0)
        span = np.maximum(coords.max(axis=0) - low, 1e-9)
        object.__setattr__(self, "_low", low)
        object.__setattr__(self, "_span", span)
        n = self.roads.network.n_nodes
        block = (np.concatenate([((coords - low) / span).ravel(),
                                 self.roads.tail / n, self.roads.head / n])
                 if self.include_map else np.zeros(0))
        object.__setattr__(self, "_map_block", block.astype(np.float32))
        object.__setattr__(self, "_slots", int(np.diff(self.roads.out_ptr).max()))

    @property
    def n_bins(self) -> int:
        """``B``, road bins per target."""
        return self.roads.n_edges * self.bins_per_edge

    @property
    def size(self) -> int:
        """Length of the observation vector."""
        return (2 * self.n_uavs + self.n_targets * self.n_bins + self.n_targets
                + self.roads.network.n_nodes + self._map_block.size
                + (2 * self._slots if self.road_values else 0))

    def histograms(self, edge: IntArray, s: FloatArray, w: FloatArray) -> FloatArray:
        """``(M, B)`` particle mass per road bin (Eq. 22), scaled by ``B``."""
        k = self.bins_per_edge
        frac = np.clip(s / self.roads.length[edge], 0.0, 1.0 - 1e-12)
        idx = edge * k + (frac * k).astype(np.int64)
        m = edge.shape[0]
        rows = np.repeat(np.arange(m), edge.shape[1]) * self.n_bins
        hist = np.bincount((rows + idx.ravel()), weights=w.ravel(),
                           minlength=m * self.n_bins).reshape(m, self.n_bins)
        total = np.maximum(hist.sum(axis=1, keepdims=True), 1e-300)
        out: FloatArray = hist / total * self.n_bins
        return out

    def observe(self, belief: RoadParticleBelief, uav_xy: FloatArray,
                node: int) -> FloatArray:
        """The observation (``float32``, length :attr:`size`) for the UAV at ``node``
        (``uav_xy``: every UAV's position, ``(Q, 2)``)."""
        if belief.n_targets != self.n_targets:
            raise InvalidInputError("belief", belief.n_targets,
                                    f"has {belief.n_targets} targets, the policy {self.n_targets}")
        uav = checks.finite_array("uav_xy", np.asarray(uav_xy, dtype=np.float64).reshape(-1, 2),
                                  (self.n_uavs, 2))
        n_nodes = self.roads.network.n_nodes
        if not 0 <= node < n_nodes:
            raise InvalidInputError("node", node, f"must be in [0, {n_nodes})")
        edge, s, w = belief.target_particles()
        hist = self.histograms(edge, s, w)
        gamma = target_weights(belief.target_entropy(), gain=self.gain)
        here = np.zeros(n_nodes)
        here[node] = 1.0
        blocks = [((uav - self._low) / self._span).ravel(), hist.ravel(), gamma, here,
                  self._map_block]
        if self.road_values:
            blocks.append(self._slot_values(edge, w, gamma, node))
        return np.concatenate(blocks).astype(np.float32)

    def _slot_values(self, edge: IntArray, w: FloatArray, gamma: FloatArray,
                     node: int) -> FloatArray:
        """Per action slot: the road's Eq. 21 value and the best value one road further."""
        roads = self.roads
        value = edge_values(roads.length, edge, w, gamma) * (roads.n_edges / 2)
        out = np.zeros(2 * self._slots)
        for k, e in enumerate(roads.leaving(node)):
            nxt = roads.successors[roads.successor_ptr[e]:roads.successor_ptr[e + 1]]
            out[2 * k] = value[e]
            out[2 * k + 1] = value[nxt].max() if nxt.size else 0.0
        return out

    def signature(self) -> dict[str, int | float | bool]:
        """What a policy trained on these features must match."""
        net = self.roads.network
        return {"n_nodes": net.n_nodes, "n_edges": self.roads.n_edges,
                "total_length_m": round(float(self.roads.total_length_m), 3),
                "n_targets": self.n_targets, "n_uavs": self.n_uavs,
                "bins_per_edge": self.bins_per_edge, "gain": self.gain,
                "include_map": self.include_map, "road_values": self.road_values,
                "size": self.size}
