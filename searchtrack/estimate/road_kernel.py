"""A Gaussian kernel along the roads: node beliefs read at a sensor's resolution.

A particle cloud read as a node belief (each particle's weight on the nearer end node of its
edge) resolves a target as finely as its particles sit. After a run of detections a cloud of
Moore et al.'s RBPF sits within a few metres, finer than one detection places the target
(the sensor's position noise ``s``), so on a map cut into cells of about 10 m its node peak
``𝒫`` is close to 1 while the target is seen, and it stays there while the cloud drives on as
one pack. The thesis's node trackers (Ch. 4) cannot be sharper than their update's Gaussian of
``s`` allows, and the Ch. 5 guidance laws read ``𝒫`` on that scale: a UAV leaves a tracker while
``𝒫 > ϱ`` (5.16) and comes back when it falls to ``ϱ``. A cloud read at its own resolution keeps
the UAV away until it has split at junctions, by which time it is as likely lost as found.

Reading the cloud at the sensor's resolution puts both beliefs on the thesis's scale: the node
belief ``p`` becomes ``p K`` with

``K[u, v] = exp(−d(u, v)² / 2σ²) / Σ_w exp(−d(u, w)² / 2σ²)`` for road distances ``d ≤ 3σ``,

``σ`` the sensor's position noise: each node's mass is spread over the nodes within ``3σ`` by
road, as a detection of a target there would place it (total mass kept, the kernel's rows sum
to 1). A tight cloud then reads ``𝒫`` of about the node spacing over ``σ√(2π)``, and ``𝒫`` falls
as soon as the cloud spreads beyond ``σ``. The cloud itself (its updates, its MAP position)
does not change.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.types import FloatArray
from searchtrack.models.roads import RoadNetwork

#: The kernel is cut at this many standard deviations of road distance.
TRUNCATION_SIGMAS = 3.0

#: Sources per Dijkstra call when the kernel is built (bounds the dense ``(block, n)`` rows).
BLOCK = 256


class RoadKernel:
    """The row-normalised Gaussian kernel ``K`` on road distance (module docstring).

    Parameters
    ----------
    network
        The road network.
    sigma_m
        The kernel's standard deviation ``σ`` (m), finite and > 0.

    Attributes
    ----------
    matrix
        ``K``, a sparse ``(n, n)`` matrix whose rows sum to 1.
    """

    def __init__(self, network: RoadNetwork, sigma_m: float) -> None:
        self.sigma_m = checks.positive("sigma_m", sigma_m)
        n = network.n_nodes
        row, col, dist = [], [], []
        for start in range(0, n, BLOCK):
            d = network.shortest_paths(np.arange(start, min(start + BLOCK, n)),
                                       limit_m=TRUNCATION_SIGMAS * self.sigma_m)
            r, c = np.nonzero(np.isfinite(d))
            row.append(r + start)
            col.append(c)
            dist.append(d[r, c])
        weight = np.exp(-0.5 * (np.concatenate(dist) / self.sigma_m) ** 2)
        k = sp.csr_array((weight, (np.concatenate(row), np.concatenate(col))), shape=(n, n))
        # each row holds its own node (d = 0), so no row sums to 0
        self.matrix: sp.csr_array = sp.csr_array(
            sp.diags_array(1.0 / np.asarray(k.sum(axis=1)).ravel()) @ k)
        self.n_nodes = n

    def smooth(self, probability: ArrayLike) -> FloatArray:
        """``p K`` for a node vector ``p`` ``(n,)`` (its total kept)."""
        p = checks.node_vector("probability", probability, self.n_nodes)
        return np.asarray(self.matrix.T @ p, dtype=np.float64)
