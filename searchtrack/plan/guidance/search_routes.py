"""Searching as an orienteering problem over the search field (a strategy of this library beside
the thesis's gradient search, thesis 001 Ch. 5).

The thesis's searching UAV climbs the local gradient of the LRT field (5.6)–(5.7); it sees only
its own footprint, so it can wander over searched road while unexplored road lies a few hundred
metres away. Here a searching UAV instead plans a route over the unexplored belief mass, the
same OPTW as search-and-reacquire's (§5.5, :mod:`~searchtrack.plan.guidance.reacquire`) with
other prizes:

- the mass of the search field is its softmax, ``w ∝ exp(score)``: for the LRT, whose score is
  the log-likelihood ratio ``φ``, the location of one undetected target under a uniform prior
  (as :meth:`~searchtrack.estimate.lrt.LikelihoodField.node_probability`), read through the
  :class:`~searchtrack.estimate.belief.SearchField` protocol only; the positive score within
  a footprint radius of a live tracker's peak is left out (:func:`search_mass`'s
  ``explained``): there the LRT's evidence keeps building from the target already tracked,
  whose loitering UAV looks at it every step (up to ``φ_max`` before the initiator resets it),
  and counted as mass it would draw every searching UAV to the known target;
- the road nodes are binned into square cells of side ``√2 ρ`` (a footprint centred on a cell
  covers it; :class:`SearchCells`); a cell's prize is its mass, its vertex the cell's node
  nearest to the cell's mass centroid;
- the instance (:func:`search_instance`) keeps the ``max_nodes`` heaviest cells the UAV can
  reach within the look-ahead ``horizon_s`` (ties: nearer first), leaving out the cells already
  in the UAV's serving radius, those claimed by the other UAVs' routes and those holding less
  than ``min_share`` of the heaviest cell's mass (searched road: the OPTW values prizes
  collected early and late alike, so a route with time to spare would otherwise pick up
  searched road on its way), and is solved by the OPTW family
  (:mod:`searchtrack.plan.optw`).

A :class:`SearchRoute` is what a UAV keeps flying between steps: it springs toward the route's
first node and plans again once it is within the serving radius of it or the route is older
than the re-planning period (the strategies of :mod:`~searchtrack.plan.guidance.route_strategies`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.checks import count, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import SearchField
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance.reacquire import reacquisition_instance
from searchtrack.plan.guidance.search_partition import discounted_prize
from searchtrack.plan.optw.instance import OPTWInstance


def search_mass(field: SearchField, explained: ArrayLike | None = None) -> FloatArray:
    """The field's mass on each node, ``exp(score − max) / Σ exp(score − max)`` (sums to 1).

    For the LRT field this is the location of one undetected target under a uniform prior: 1
    part per unexplored node (``φ = 0``), next to nothing where the UAVs just looked, more where
    evidence for a target built up. ``explained`` (a boolean per node, or ``None``) marks the
    nodes whose positive score a tracked target explains: there the score counts at most 0.
    """
    if not isinstance(field, SearchField):
        raise InvalidInputError("field", field, "must be a SearchField (n_nodes, node_score)")
    score = np.asarray(field.node_score(), dtype=np.float64)
    if explained is not None:
        known = np.asarray(explained)
        if known.dtype != np.bool_ or known.shape != score.shape:
            raise InvalidInputError("explained", explained,
                                    f"must be one boolean per node, shape {score.shape}")
        score = np.where(known, np.minimum(score, 0.0), score)
    w = np.exp(score - score.max())
    return np.asarray(w / w.sum(), dtype=np.float64)


def near_peaks(network: RoadNetwork, peaks: ArrayLike, radius_m: float) -> NDArray[np.bool_]:
    """Per road node, whether it lies within ``radius_m`` of one of the nodes ``peaks`` (e.g.
    the live trackers' peak nodes): :func:`search_mass`'s ``explained``."""
    nodes = np.asarray(peaks, dtype=np.int64).reshape(-1)
    near = np.zeros(network.n_nodes, dtype=bool)
    if nodes.size == 0:
        return near
    if np.any((nodes < 0) | (nodes >= network.n_nodes)):
        raise InvalidInputError("peaks", peaks, f"must be node indices in [0, {network.n_nodes})")
    _, within = network.nodes_within(network.coords[np.unique(nodes)],
                                     positive("radius_m", radius_m))
    near[within] = True
    return near


@dataclass(frozen=True, eq=False)
class SearchCells:
    """The road nodes binned into square cells of side ``cell_m`` (built once per network).

    Parameters
    ----------
    network
        The road network.
    cell_m
        Side of a cell (m); ``√2 ρ`` puts a cell inside a footprint centred on it.
    """

    network: RoadNetwork
    cell_m: float
    cell_of: IntArray = field(init=False, repr=False)
    n_cells: int = field(init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        side = positive("cell_m", self.cell_m)
        xy = self.network.coords
        ij = np.floor((xy - xy.min(axis=0)) / side).astype(np.int64)
        _, cell_of = np.unique(ij[:, 0] * (int(ij[:, 1].max()) + 1) + ij[:, 1],
                               return_inverse=True)
        set_ = object.__setattr__
        set_(self, "cell_m", side)
        set_(self, "cell_of", cell_of.astype(np.int64).reshape(-1))
        set_(self, "n_cells", int(cell_of.max()) + 1)

    def prizes(self, mass: ArrayLike) -> tuple[FloatArray, IntArray]:
        """Per cell, its mass and its vertex: the cell's node nearest to the cell's mass
        centroid (its plain centroid when it holds no mass; the lowest index on ties)."""
        w = np.asarray(mass, dtype=np.float64)
        n = self.network.n_nodes
        if w.shape != (n,) or not np.all(np.isfinite(w)) or np.any(w < 0.0):
            raise InvalidInputError("mass", mass, f"must be non-negative and finite, shape ({n},)")
        cell, xy, k = self.cell_of, self.network.coords, self.n_cells
        total = np.asarray(np.bincount(cell, weights=w, minlength=k), dtype=np.float64)
        size = np.bincount(cell, minlength=k).astype(np.float64)
        weighted = total > 0.0
        centroid = np.empty((k, 2))
        for d in range(2):
            plain = np.bincount(cell, weights=xy[:, d], minlength=k) / size
            heavy = np.bincount(cell, weights=w * xy[:, d], minlength=k)
            centroid[:, d] = np.where(weighted, heavy / np.where(weighted, total, 1.0), plain)
        off = xy - centroid[cell]
        dist = np.hypot(off[:, 0], off[:, 1])
        order = np.lexsort((np.arange(n), dist, cell))
        first = np.flatnonzero(np.r_[True, cell[order][1:] != cell[order][:-1]])
        vertex = np.empty(k, dtype=np.int64)
        vertex[cell[order][first]] = order[first]
        return total, vertex


def search_instance(
    cells: SearchCells,
    mass: ArrayLike,
    uav_xy_m: ArrayLike,
    speed_mps: float,
    horizon_s: float,
    *,
    max_nodes: int = 40,
    serve_m: float = 0.0,
    exclude: ArrayLike = (),
    min_share: float = 1e-3,
    keep: ArrayLike | None = None,
    discount_s: float | None = None,
) -> tuple[OPTWInstance, NDArray[np.int64]]:
    """The search OPTW of one UAV and the road node of each vertex (module docstring).

    Vertex 0 is the UAV (score 0, ``node_ids[0]`` = −1); the others are the vertices of the
    ``max_nodes`` heaviest cells whose vertex lies within ``speed_mps · horizon_s`` of the UAV
    and farther than ``serve_m``, leaving out the cells of the road nodes in ``exclude`` and
    the cells with less than ``min_share`` of the heaviest cell's mass (anywhere), scored by
    their mass. Windows ``[0, horizon_s]``, Euclidean travel at
    ``speed_mps``, open end (as :func:`~searchtrack.plan.guidance.reacquire.
    reacquisition_instance`, which builds it).

    The partitioned route strategies (:mod:`~searchtrack.plan.guidance.search_partition`)
    pass ``keep``, a boolean per cell (only those cells may be candidates: the UAV's part of
    the partition), and ``discount_s``, the discount time ``τ``: the candidates are then the
    heaviest by their discounted prize ``m / (1 + d/(S τ))`` (``d`` the straight-line distance
    to the cell's vertex, ``S`` = ``speed_mps``), which is also their score.
    """
    xy = np.asarray(uav_xy_m, dtype=np.float64)
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise InvalidInputError("uav_xy_m", uav_xy_m, "must be one finite point (x, y) (m)")
    speed = positive("speed_mps", speed_mps)
    if not (isinstance(horizon_s, (int, float)) and math.isfinite(horizon_s) and horizon_s >= 0):
        raise InvalidInputError("horizon_s", horizon_s, "must be finite and ≥ 0 (s)")
    k = count("max_nodes", max_nodes, least=1)
    if not (isinstance(serve_m, (int, float)) and math.isfinite(serve_m) and serve_m >= 0):
        raise InvalidInputError("serve_m", serve_m, "must be finite and ≥ 0 (m)")
    net = cells.network
    skip = np.asarray(exclude, dtype=np.int64).reshape(-1)
    if np.any((skip < 0) | (skip >= net.n_nodes)):
        raise InvalidInputError("exclude", exclude, f"must be node indices in [0, {net.n_nodes})")
    total, vertex = cells.prizes(mass)
    off = net.coords[vertex] - xy
    dist = np.hypot(off[:, 0], off[:, 1])
    if not (isinstance(min_share, (int, float)) and 0.0 <= min_share <= 1.0):
        raise InvalidInputError("min_share", min_share, "must be in [0, 1]")
    ok = (total > 0.0) & (dist <= speed * float(horizon_s)) & (dist > serve_m)
    ok[cells.cell_of[skip]] = False
    ok &= total >= min_share * total.max()
    if keep is not None:
        mine = np.asarray(keep)
        if mine.dtype != np.bool_ or mine.shape != total.shape:
            raise InvalidInputError("keep", keep, f"must be one boolean per cell, shape "
                                    f"{total.shape}")
        ok &= mine
    score = total if discount_s is None else discounted_prize(total, dist / speed, discount_s)
    chosen = np.flatnonzero(ok)
    chosen = chosen[np.lexsort((chosen, dist[chosen], -score[chosen]))][:k]
    prize = np.zeros(net.n_nodes)
    prize[vertex[chosen]] = score[chosen]
    return reacquisition_instance(net, prize, xy, speed, float(horizon_s), max_nodes=k,
                                  support_mass=1.0)


@dataclass(frozen=True)
class SearchRoute:
    """A search route being flown: what the route strategies keep between steps.

    Parameters
    ----------
    uav
        Index of the UAV flying it.
    nodes
        The route's road nodes in visiting order (the start excluded), non-empty.
    planned_s
        Mission time (s) at which it was planned.
    """

    uav: int
    nodes: tuple[int, ...]
    planned_s: float

    def __post_init__(self) -> None:
        nodes = tuple(int(v) for v in self.nodes)
        if not nodes or any(v < 0 for v in nodes):
            raise InvalidInputError("nodes", self.nodes, "must be one or more node indices ≥ 0")
        if not math.isfinite(self.planned_s):
            raise InvalidInputError("planned_s", self.planned_s, "must be finite (s)")
        object.__setattr__(self, "uav", count("uav", self.uav))
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "planned_s", float(self.planned_s))

    def due(self, network: RoadNetwork, uav_xy_m: FloatArray, time_s: float, serve_m: float,
            replan_s: float) -> bool:
        """True when the UAV at ``uav_xy_m[uav]`` is within ``serve_m`` of the first node or
        the route is ``replan_s`` old: time to plan again."""
        d = network.coords[self.nodes[0]] - uav_xy_m[self.uav]
        return bool(math.hypot(d[0], d[1]) <= serve_m or time_s - self.planned_s >= replan_s)
