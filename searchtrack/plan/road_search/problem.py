"""The road-search planning problem of Moore et al. 2021 (§4) and its plan.

``Q`` UAVs sit at road nodes and each chooses a path of ``L`` directed edges (the look-ahead);
the first edge is flown, then the planner runs again (receding horizon, §4.2). A UAV still
flying towards its node joins the plan when it gets there (``uav_delay_s``): a UAV that reaches
a node re-plans jointly with the others in flight, which the paper's per-UAV controller does
not. The targets are ``M`` weighted particle clouds on the directed roads (Eq. 8), each with an
entropy ``H_m`` (Eq. 19) that sets its weight ``γ_m`` (Eq. 20). The objective, shared by every
backend, is the discounted weighted particle mass the paths see, each particle counted once
(:mod:`searchtrack.plan.road_search.scenario` gives the exact definition): a maximum coverage
problem on a time-expanded graph, with the particles propagated during the look-ahead by the
motion model (Eq. 9) with random draws fixed by ``draw_seed``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from searchtrack.core import checks
from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.registry import check_seed
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.plan.road_search.chains import ChainGraph
from searchtrack.plan.road_search.weights import (
    NORMALIZATIONS,
    WEIGHTINGS,
    Normalization,
    Weighting,
    target_weights,
)

if TYPE_CHECKING:
    from searchtrack.plan.road_search.scenario import Scenario


#: The default tick is never shorter than the longest edge's flight time over this.
MAX_TICKS_PER_EDGE = 64


@dataclass(frozen=True)
class RoadSearchSettings:
    """How paths are scored: the look-ahead, the value conventions and the fixed draws.

    Parameters
    ----------
    lookahead
        ``L``, edges per path (≥ 1; 3 in the paper's hardware runs).
    uav_speed_mps
        ``V_a`` (m/s), the UAV's speed along the roads (40 in the paper's simulation).
    motion
        The target motion model (Eq. 9) used to propagate particles during the look-ahead
        (default 10 m/s with σ_ν = 4 m/s, the paper's simulation and filter).
    discount
        Value at look-ahead level ``ℓ`` (0 for the first edge) is multiplied by
        ``discount**ℓ``; in ``(0, 1]`` (0.8 in the authors' code and Table 1).
    gain
        Sigmoid gain ``a`` of Eq. 20 (10 in the paper).
    normalization
        Entropy normaliser ``η`` of Eq. 20: ``"sum"`` (the authors' code) or ``"max"``.
    weighting
        ``"entropy"`` (Eq. 20) or ``"uniform"`` (``γ = 1``: the naive value, Eq. 17).
    per_length
        Divide an edge's value by its length (Eq. 17/21 as printed); the code does not.
    both_directions
        A UAV over a road sees the particles of both its directions (the code's rule).
    draw_seed
        Seed of the random draws that propagate the particles (the scenario every backend
        scores).
    horizon_s
        Plan over a time horizon rather than a count of edges (beyond the paper): a path ends at
        the first node it reaches ``horizon_s`` seconds or more from now (rounded to whole
        ticks), after at least one edge and at most ``lookahead``. ``None``: every path has
        ``lookahead`` edges (the paper's). A 3-edge look-ahead is 300 m on the paper's grid
        and up to kilometres on a city map; a horizon is the same time everywhere.
    tick_s
        Time step (s) of the look-ahead: particles are propagated tick by tick and an edge takes
        ``max(1, round(length / (V_a · tick_s)))`` ticks. ``None``: the time to fly the
        shortest edge (exact on maps whose edges are all equally long, such as the paper's grid),
        but no less than the longest edge's flight over :data:`MAX_TICKS_PER_EDGE` (a map with
        one very short edge would otherwise need thousands of propagation steps).
    """

    lookahead: int = 3
    uav_speed_mps: float = 40.0
    motion: RoadMotion = field(default_factory=RoadMotion)
    discount: float = 0.8
    gain: float = 10.0
    normalization: Normalization = "sum"
    weighting: Weighting = "entropy"
    per_length: bool = False
    both_directions: bool = True
    draw_seed: int = 0
    tick_s: float | None = None
    horizon_s: float | None = None

    def __post_init__(self) -> None:
        checks.count("lookahead", self.lookahead, 1)
        checks.positive("uav_speed_mps", self.uav_speed_mps)
        if not isinstance(self.motion, RoadMotion):
            raise InvalidInputError("motion", self.motion, "must be a RoadMotion")
        checks.real("discount", self.discount, low=0.0, high=1.0, low_open=True)
        checks.non_negative("gain", self.gain)
        checks.choice("normalization", self.normalization, NORMALIZATIONS)
        checks.choice("weighting", self.weighting, WEIGHTINGS)
        for name in ("per_length", "both_directions"):
            checks.boolean(name, getattr(self, name))
        try:
            check_seed(self.draw_seed)
        except InvalidInputError as err:
            raise InvalidInputError("draw_seed", self.draw_seed, err.reason) from None
        if self.tick_s is not None:
            checks.positive("tick_s", self.tick_s)
        if self.horizon_s is not None:
            checks.positive("horizon_s", self.horizon_s)


@dataclass(frozen=True, eq=False)
class RoadSearchProblem:
    """Choose a path of ``L`` directed edges (or up to a time horizon) for each UAV to see the
    most weighted particles.

    Parameters
    ----------
    roads
        The directed roads the particles and UAVs move on.
    uav_nodes
        ``Q ≥ 1`` nodes, one per UAV: where each plans from.
    uav_delay_s
        ``(Q,)`` seconds before each UAV reaches its node (≥ 0; empty: all there now). Its path
        starts that late, rounded to whole look-ahead ticks.
    particle_edge, particle_s, particle_weight
        ``(M, N)`` particles of each target: directed edge, arc length (m) from its tail,
        non-negative weight (normalised here to sum 1 per target).
    entropy
        ``(M,)`` target entropies (nats, Eq. 19), ≥ 0.
    settings
        Look-ahead, speeds and value conventions.
    truth_edge, truth_s
        Optional ``(M,)`` true target positions (for the ``ideal`` baseline only).
    chains
        Set by :meth:`from_belief` when the belief's network was merged into intersections:
        ``roads`` is then the merged network and :meth:`network_nodes` maps plans back.
    name
        Free label for logs.

    Raises
    ------
    InvalidInputError
        Naming the field at fault.
    """

    roads: DirectedRoads
    uav_nodes: tuple[int, ...]
    particle_edge: IntArray
    particle_s: FloatArray
    particle_weight: FloatArray
    entropy: FloatArray
    settings: RoadSearchSettings = field(default_factory=RoadSearchSettings)
    truth_edge: IntArray | None = None
    truth_s: FloatArray | None = None
    chains: ChainGraph | None = None
    name: str = "road-search"
    uav_delay_s: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.roads, DirectedRoads):
            raise InvalidInputError("roads", self.roads, "must be a DirectedRoads")
        if not isinstance(self.settings, RoadSearchSettings):
            raise InvalidInputError("settings", self.settings, "must be a RoadSearchSettings")
        n_nodes = self.roads.network.n_nodes
        nodes = checks.index_array("uav_nodes", list(np.atleast_1d(self.uav_nodes)), n_nodes)
        if nodes.size == 0:
            raise InvalidInputError("uav_nodes", self.uav_nodes, "needs at least one UAV")
        out = self.roads.out_ptr
        stuck = [int(v) for v in nodes if out[v + 1] == out[v]]
        if stuck:
            raise InvalidInputError("uav_nodes", self.uav_nodes, f"nodes {stuck} have no road")
        edge = np.array(self.particle_edge, copy=True)
        if edge.ndim != 2 or edge.shape[0] < 1 or edge.shape[1] < 1 or edge.dtype.kind not in "iu":
            raise InvalidInputError("particle_edge", edge.shape,
                                    "must be an (M, N) integer array with M, N >= 1")
        edge = edge.astype(np.int64)
        s = checks.finite_array("particle_s", self.particle_s, edge.shape)
        try:
            self.roads.check_positions(edge, s)
        except InvalidInputError as err:
            raise InvalidInputError(f"particle_{err.field}", err.value, err.reason) from None
        w = np.array(checks.finite_array("particle_weight", self.particle_weight, edge.shape))
        if np.any(w < 0.0):
            raise InvalidInputError("particle_weight", "negative", "weights must be >= 0")
        totals = w.sum(axis=1)
        if np.any(totals <= 0.0):
            bad = int(np.flatnonzero(totals <= 0.0)[0])
            raise InvalidInputError("particle_weight", f"target {bad}",
                                    "every target needs a positive total weight")
        w /= totals[:, None]
        h = checks.finite_array("entropy", self.entropy, (edge.shape[0],))
        if np.any(h < 0.0):
            raise InvalidInputError("entropy", self.entropy, "entropies must be >= 0")
        set_ = object.__setattr__
        if (self.truth_edge is None) != (self.truth_s is None):
            raise InvalidInputError("truth_s", self.truth_s, "give truth_edge and truth_s together")
        if self.truth_edge is not None:
            t_edge = np.array(self.truth_edge, copy=True)
            if t_edge.shape != (edge.shape[0],) or t_edge.dtype.kind not in "iu":
                raise InvalidInputError("truth_edge", self.truth_edge,
                                        f"must be ({edge.shape[0]},) directed edge indices")
            t_s = checks.finite_array("truth_s", np.asarray(self.truth_s), (edge.shape[0],))
            try:
                self.roads.check_positions(t_edge.astype(np.int64), t_s)
            except InvalidInputError as err:
                raise InvalidInputError(f"truth_{err.field}", err.value, err.reason) from None
            set_(self, "truth_edge", checks.readonly(t_edge.astype(np.int64)))
            set_(self, "truth_s", t_s)
        if self.chains is not None and not isinstance(self.chains, ChainGraph):
            raise InvalidInputError("chains", self.chains, "must be a ChainGraph or None")
        set_(self, "uav_nodes", tuple(int(v) for v in nodes))
        delay = np.zeros(nodes.size)
        if np.size(self.uav_delay_s):  # type: ignore[arg-type]
            delay = checks.finite_array("uav_delay_s", self.uav_delay_s, (nodes.size,))
        if np.any(delay < 0.0):
            raise InvalidInputError("uav_delay_s", self.uav_delay_s, "delays must be >= 0")
        set_(self, "uav_delay_s", tuple(float(d) for d in delay))
        set_(self, "particle_edge", checks.readonly(edge))
        set_(self, "particle_s", s)
        set_(self, "particle_weight", checks.readonly(w))
        set_(self, "entropy", h)

    @classmethod
    def from_belief(cls, belief: RoadParticleBelief, uav_nodes: Sequence[int], *,
                    settings: RoadSearchSettings | None = None,
                    chains: ChainGraph | None = None,
                    truth: tuple[IntArray, FloatArray] | None = None,
                    uav_delay_s: Sequence[float] = (),
                    name: str = "road-search") -> RoadSearchProblem:
        """The problem for a belief's particles and entropies.

        Parameters
        ----------
        belief
            Any :class:`~searchtrack.estimate.belief.RoadParticleBelief`.
        uav_nodes
            The UAVs' nodes in the belief's network.
        chains
            Plan over intersections: a :class:`ChainGraph` of the belief's network; the UAVs'
            nodes must be among its kept nodes, particles and truth are mapped onto it.
        truth
            Optional ``(edge, s)`` true target positions on the belief's roads.
        uav_delay_s
            Seconds before each UAV reaches its node (empty: all there now).
        """
        if not isinstance(belief, RoadParticleBelief):
            raise InvalidInputError("belief", belief, "must implement RoadParticleBelief")
        edge, s, w = belief.target_particles()
        roads = belief.roads
        nodes = [int(v) for v in np.atleast_1d(np.asarray(uav_nodes))]
        t_edge, t_s = (None, None) if truth is None else truth
        if chains is not None:
            if not isinstance(chains, ChainGraph):
                raise InvalidInputError("chains", chains, "must be a ChainGraph")
            if chains.fine is not roads.network:
                raise InvalidInputError("chains", chains,
                                        "must be built on the belief's road network")
            bad = [v for v in nodes if not 0 <= v < chains.coarse_of_node.size
                   or chains.coarse_of_node[v] < 0]
            if bad:
                raise InvalidInputError("uav_nodes", bad, "must be intersections, dead ends or "
                                        "nodes kept by the ChainGraph (keep=...)")
            nodes = [int(chains.coarse_of_node[v]) for v in nodes]
            edge, s = chains.to_coarse(edge, s)
            if t_edge is not None and t_s is not None:
                t_edge, t_s = chains.to_coarse(t_edge, t_s)
            roads = chains.roads
        return cls(roads, tuple(nodes), edge, s, w, belief.target_entropy(),
                   settings if settings is not None else RoadSearchSettings(),
                   t_edge, t_s, chains, name, tuple(uav_delay_s))

    @property
    def n_uavs(self) -> int:
        """``Q``."""
        return len(self.uav_nodes)

    @property
    def n_targets(self) -> int:
        """``M``."""
        return int(self.particle_edge.shape[0])

    @property
    def lookahead(self) -> int:
        """``L``."""
        return self.settings.lookahead

    @cached_property
    def gamma(self) -> FloatArray:
        """``(M,)`` target weights (Eq. 20, or ones for ``weighting="uniform"``)."""
        st = self.settings
        return checks.readonly(target_weights(self.entropy, gain=st.gain,
                                              normalization=st.normalization,
                                              weighting=st.weighting), copy=False)

    @cached_property
    def tick_s(self) -> float:
        """The look-ahead time step (s): ``settings.tick_s``, or the shortest edge's flight
        time, at least the longest's over :data:`MAX_TICKS_PER_EDGE`."""
        st = self.settings
        if st.tick_s is not None:
            return st.tick_s
        length = self.roads.length
        return float(max(length.min(), length.max() / MAX_TICKS_PER_EDGE) / st.uav_speed_mps)

    @cached_property
    def start_ticks(self) -> IntArray:
        """``(Q,)`` the tick at which each UAV starts its path: its delay in whole ticks."""
        delay = np.asarray(self.uav_delay_s, dtype=np.float64) / self.tick_s
        return checks.readonly(np.rint(delay).astype(np.int64), copy=False)

    @cached_property
    def horizon_tick(self) -> int | None:
        """The tick at or after which a path ends (``settings.horizon_s`` in whole ticks), or
        ``None`` for paths of ``L`` edges."""
        h = self.settings.horizon_s
        return None if h is None else round(h / self.tick_s)

    def path_ends(self, tick: int, edges: int) -> bool:
        """Whether a path that has flown ``edges`` edges and reached its node at ``tick`` ends
        there: ``L`` edges, or (with a horizon) at least one edge and the horizon reached."""
        h = self.horizon_tick
        return edges >= self.lookahead or (h is not None and edges >= 1 and tick >= h)

    @cached_property
    def edge_ticks(self) -> IntArray:
        """``(E,)`` ticks to fly each directed edge: ``max(1, round(length / (V_a tick_s)))``."""
        raw = self.roads.length / (self.settings.uav_speed_mps * self.tick_s)
        return checks.readonly(np.maximum(1, np.rint(raw)).astype(np.int64), copy=False)

    @cached_property
    def scenario(self) -> Scenario:
        """The fixed-draw scenario every backend scores (built on first use)."""
        from searchtrack.plan.road_search.scenario import build_scenario

        return build_scenario(self)

    def scenario_within(self, deadline: Deadline) -> bool:
        """Build :attr:`scenario` unless built, stopping at ``deadline``: whether it is built
        (``False``: the deadline expired first, nothing kept)."""
        from searchtrack.plan.road_search.scenario import BuildTimeout, build_scenario

        if "scenario" in self.__dict__:
            return True
        try:
            self.__dict__["scenario"] = build_scenario(self, deadline)
        except BuildTimeout:
            return False
        return True

    def network_nodes(self, plan: RoadPlan) -> tuple[IntArray, ...]:
        """Each UAV's path as nodes of the belief's network (every node along merged chains)."""
        if self.chains is None:
            return tuple(np.array(p, dtype=np.int64) for p in plan.nodes)
        return tuple(self.chains.fine_path(p) for p in plan.nodes)


@dataclass(frozen=True)
class RoadPlan:
    """Per UAV a path of directed edges from its node (``L`` of them, or 1 to ``L`` with a time
    horizon); the first edge is what is flown.

    Parameters
    ----------
    nodes
        Per UAV one node more than edges, its own node first.
    edges
        Per UAV its directed edges, ``edges[q][i]`` from ``nodes[q][i]`` to
        ``nodes[q][i + 1]``.
    """

    nodes: tuple[tuple[int, ...], ...]
    edges: tuple[tuple[int, ...], ...]

    @classmethod
    def from_edges(cls, roads: DirectedRoads, edges: Sequence[Sequence[int]]) -> RoadPlan:
        """The plan flying ``edges[q]`` (directed edges, consecutive) for each UAV ``q``."""
        paths = tuple(tuple(int(e) for e in path) for path in edges)
        nodes = tuple((int(roads.tail[p[0]]), *(int(roads.head[e]) for e in p)) if p else ()
                      for p in paths)
        return cls(nodes, paths)

    @property
    def next_nodes(self) -> tuple[int, ...]:
        """The node each UAV flies to now (the head of its first edge)."""
        return tuple(p[1] for p in self.nodes)

    @property
    def first_edges(self) -> tuple[int, ...]:
        """The directed edge each UAV flies now."""
        return tuple(p[0] for p in self.edges)


def meets_bound(value: float, bound: float, rel_tol: float = 1e-9) -> bool:
    """True when ``bound`` exceeds ``value`` by at most ``rel_tol · |value|`` (proven optimal)."""
    return bound - value <= rel_tol * abs(value)
