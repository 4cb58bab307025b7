"""The fixed-draw scenario every road-search backend scores: a time-expanded graph and the
particles propagated along it (Moore et al. 2021, §4.2 made exact).

**Time.** Look-ahead time runs in ticks of ``tick_s`` seconds; directed edge ``e`` takes ``k_e =
max(1, round(len(e) / (V_a tick_s)))`` ticks to fly (exact when every edge is a whole number of
ticks, as on the paper's grid with the default tick). UAV ``q`` reaching its node at tick
``t_q`` (0, or its delay in whole ticks) flies its path ``e_{q,0} … e_{q,L−1}``; it starts edge
``ℓ`` at tick ``t_{q,ℓ} = t_q + Σ_{i<ℓ} k_{e_{q,i}}``. The reachable ``(level, node, tick)``
states and the edges between them form one layered graph per UAV (:class:`Lattice`), the
time-expanded graph.

**Particles.** The particles are propagated tick by tick with the motion model (Eq. 9), all
``M × N`` of them at once with one generator seeded by ``draw_seed``; the propagation does not
depend on the paths, so every path is scored on the same trajectories (the scenario). A
particle at tick ``t`` is seen by an edge started at tick ``t`` when it lies on that edge's road
(both directions when ``both_directions``, else the edge itself); that is the paper's edge value
(Eq. 21) of the propagated particles at the start of the edge.

**Horizon.** With ``horizon_s`` set, a path ends at the first node it reaches at or after the
horizon tick (after one edge at least, ``L`` edges at most): the lattice gives such a state one
*hold* arc per remaining level, which flies no edge and sees nothing, so every path keeps ``L``
arcs and every backend searches the same layered graph.

**Objective.** With ``β(ℓ, e) = discount**ℓ`` (divided by ``len(e)`` when ``per_length``) and
particle value ``γ_m w_{mn}``::

    J = Σ_{m,n} γ_m w_{mn} · max_{q, ℓ : (q, ℓ) sees (m, n)} β(ℓ, e_{q,ℓ})

so each particle counts once, across UAVs too (a weighted maximum coverage objective, monotone
submodular in the set of flown ``(level, tick, road)`` elements). This is the paper's rule of
removing the particles counted on an edge whenever the value of a sighting does not grow along a
path: always without ``per_length`` (the discount only shrinks), and with it on maps whose edges
are equally long; otherwise a particle counts at its most valuable sighting, not its first.

**Aggregation.** Two particles seen by exactly the same elements are interchangeable: they are
merged into one group whose value is the sum of theirs, and particles no element can see are
dropped. ``cover[k, g]`` holds ``β_k`` when element ``k`` sees group ``g`` (else 0), so a set of
elements ``S`` scores ``Σ_g V_g max_{k ∈ S} cover[k, g]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from searchtrack.core.checks import readonly
from searchtrack.core.deadline import Deadline
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem

#: The edge of a hold arc: a path that has reached the time horizon stays at its last node.
HOLD = -1


@dataclass(frozen=True, eq=False)
class Lattice:
    """One UAV's time-expanded graph: states ``(level, node, tick)``, state 0 the start, and
    the arcs (an edge flown from a state), grouped by tail state: the arcs leaving state ``i``
    are ``out_ptr[i]:out_ptr[i + 1]``. With a time horizon, a state at or past it (after one
    edge at least) has one arc, a hold (edge :data:`HOLD`, an element that sees nothing), so
    every path still has ``L`` arcs."""

    state_level: IntArray
    state_node: IntArray
    state_tick: IntArray
    arc_tail: IntArray
    arc_head: IntArray
    arc_edge: IntArray
    arc_level: IntArray
    arc_tick: IntArray
    arc_element: IntArray
    out_ptr: IntArray

    @property
    def n_states(self) -> int:
        """Number of states."""
        return int(self.state_node.size)

    @property
    def n_arcs(self) -> int:
        """Number of arcs."""
        return int(self.arc_edge.size)


def _lattice_arcs(problem: RoadSearchProblem, start: int, start_tick: int) -> dict[str, IntArray]:
    """States and arcs of the time-expanded graph from ``start`` at ``start_tick``, level by
    level."""
    # A UAV may turn back: every directed edge leaving a node.
    node_ptr, node_out = problem.roads.out_ptr, problem.roads.out_edges
    ticks = problem.edge_ticks
    head = problem.roads.head
    levels, nodes = [np.zeros(1, np.int64)], [np.array([start])]
    times = [np.full(1, start_tick, dtype=np.int64)]
    tails, heads, edges, arc_levels = [], [], [], []
    first = 0
    span = start_tick + int(ticks.max()) * problem.lookahead + 1
    horizon = problem.horizon_tick
    for level in range(problem.lookahead):
        here, at = nodes[-1], times[-1]
        # A path that has reached the horizon holds (one arc, no edge) down to the last level.
        held = np.zeros(here.size, bool) if horizon is None or level == 0 else at >= horizon
        counts = np.where(held, 1, node_ptr[here + 1] - node_ptr[here])
        local = np.repeat(np.arange(here.size), counts)
        offset = np.arange(local.size) - np.repeat(np.cumsum(counts) - counts, counts)
        hold = held[local]
        edge = np.where(hold, HOLD, node_out[np.where(hold, 0, node_ptr[here][local] + offset)])
        key = np.where(hold, here[local] * span + at[local],
                       head[edge] * span + at[local] + ticks[edge])
        uniq, inverse = np.unique(key, return_inverse=True)
        next_first = first + here.size
        tails.append(first + local)
        heads.append(next_first + inverse.reshape(-1))
        edges.append(edge)
        arc_levels.append(np.full(edge.size, level))
        levels.append(np.full(uniq.size, level + 1))
        nodes.append(uniq // span)
        times.append(uniq % span)
        first = next_first
    state_tick = np.concatenate(times)
    arc_tail = np.concatenate(tails)
    out_ptr = np.zeros(state_tick.size + 1, dtype=np.int64)
    np.add.at(out_ptr, arc_tail + 1, 1)
    return {"state_level": np.concatenate(levels), "state_node": np.concatenate(nodes),
            "state_tick": state_tick, "arc_tail": arc_tail, "arc_head": np.concatenate(heads),
            "arc_edge": np.concatenate(edges), "arc_level": np.concatenate(arc_levels),
            "arc_tick": state_tick[arc_tail], "out_ptr": np.cumsum(out_ptr)}


@dataclass(frozen=True, eq=False)
class Scenario:
    """The time-expanded graphs, the elements they fly, the particle groups and who sees whom.

    Attributes
    ----------
    lattices
        One :class:`Lattice` per UAV.
    element_level, element_tick, element_road, element_beta
        ``(K,)`` the distinct ``(level, tick, road)`` triples any arc flies and their value
        factor ``β`` (a road is ``edge >> 1`` when ``both_directions``, else the edge); with
        hold arcs, a last null element (all :data:`HOLD`, ``β = 0``, seeing nothing).
    edge_at
        ``(T + 1, M·N)`` directed edge of every particle at every tick (targets row-major).
    group_of_particle
        ``(M·N,)`` group of each particle, ``-1`` for particles no element sees.
    group_value
        ``(G,)`` summed ``γ_m w_{mn}`` of each group.
    cover
        ``(K, G)`` ``β_k`` where element ``k`` sees group ``g``, else 0.
    """

    lattices: tuple[Lattice, ...]
    element_level: IntArray
    element_tick: IntArray
    element_road: IntArray
    element_beta: FloatArray
    edge_at: IntArray
    group_of_particle: IntArray
    group_value: FloatArray
    cover: FloatArray

    @property
    def n_groups(self) -> int:
        """``G``."""
        return int(self.group_value.size)

    @property
    def n_elements(self) -> int:
        """``K``."""
        return int(self.element_beta.size)

    def value_of(self, best: FloatArray) -> FloatArray:
        """``Σ_g V_g best[..., g]``: the objective of coverage vectors ``(..., G)``."""
        out: FloatArray = best @ self.group_value
        return out

    def coverage(self, elements: IntArray) -> FloatArray:
        """``(G,)`` best ``β`` each group gets from ``elements`` (0 if unseen)."""
        if elements.size == 0:
            return np.zeros(self.n_groups)
        out: FloatArray = self.cover[elements].max(axis=0)
        return out

    def upper_bound(self) -> float:
        """A bound no plan exceeds: the smaller of "every group at its most valuable sighting"
        and the additive bound ``Σ_q max_path Σ_ℓ value(element)`` (each element scored alone,
        so particles seen twice count twice; coverage is subadditive), the latter a longest
        path on each time-expanded graph."""
        return self._upper_bound

    @cached_property
    def _upper_bound(self) -> float:
        if self.n_elements == 0 or self.n_groups == 0:
            return 0.0
        everything = float(self.value_of(self.cover.max(axis=0)))
        alone = self.value_of(self.cover)
        additive = 0.0
        for lat in self.lattices:
            ahead = np.zeros(lat.n_states)  # best additive value from each state to the end
            for level in range(int(lat.state_level.max()) - 1, -1, -1):
                arcs = np.flatnonzero(lat.arc_level == level)
                gain = alone[lat.arc_element[arcs]] + ahead[lat.arc_head[arcs]]
                np.maximum.at(ahead, lat.arc_tail[arcs], gain)
            additive += float(ahead[0])
        return min(everything, additive)

    def arcs_of(self, uav: int, edges: tuple[int, ...]) -> IntArray:
        """Arc of each level of UAV ``uav``'s path (hold arcs after the horizon);
        ``ValueError`` if it is not a path of the look-ahead from the UAV's node."""
        lat = self.lattices[uav]
        depth = int(lat.state_level.max())
        state, out = 0, list[int]()
        for level in range(depth):
            lo, hi = lat.out_ptr[state], lat.out_ptr[state + 1]
            if lat.arc_edge[lo] == HOLD:
                arc = int(lo)
            elif level >= len(edges):
                raise ValueError(f"UAV {uav}: the path has {len(edges)} edges; the look-ahead "
                                 f"{depth} and its horizon ask for more")
            else:
                hit = np.flatnonzero(lat.arc_edge[lo:hi] == edges[level])
                if hit.size == 0:
                    raise ValueError(f"UAV {uav}: edge {edges[level]} does not leave node "
                                     f"{int(lat.state_node[state])} at level {level}")
                arc = int(lo + hit[0])
            out.append(arc)
            state = int(lat.arc_head[arc])
        flown = sum(1 for a in out if lat.arc_edge[a] != HOLD)
        if flown != len(edges):
            raise ValueError(f"UAV {uav}: the path has {len(edges)} edges, the look-ahead "
                             f"{depth} and its horizon allow {flown}")
        return np.array(out, dtype=np.int64)

    def elements_of(self, plan: RoadPlan) -> IntArray:
        """Every element the plan flies (all UAVs)."""
        if len(plan.edges) != len(self.lattices):
            raise ValueError(f"the plan has {len(plan.edges)} paths for {len(self.lattices)} UAVs")
        parts = [self.lattices[q].arc_element[self.arcs_of(q, p)]
                 for q, p in enumerate(plan.edges)]
        return np.concatenate(parts)

    def score(self, plan: RoadPlan) -> float:
        """The objective ``J`` of ``plan`` (module docstring)."""
        return float(self.value_of(self.coverage(self.elements_of(plan))))

    def plan_of(self, arcs: list[IntArray]) -> RoadPlan:
        """The plan flying the given arcs (one array per UAV; hold arcs fly nothing)."""
        arcs = [a[self.lattices[q].arc_edge[a] != HOLD] for q, a in enumerate(arcs)]
        edges = [self.lattices[q].arc_edge[a].tolist() for q, a in enumerate(arcs)]
        nodes = []
        for q, a in enumerate(arcs):
            lat = self.lattices[q]
            nodes.append((int(lat.state_node[0]),
                          *(int(v) for v in lat.state_node[lat.arc_head[a]])))
        return RoadPlan(tuple(nodes), tuple(tuple(int(e) for e in p) for p in edges))


class BuildTimeout(Exception):
    """A scenario build ran past its deadline (or a stop was requested)."""


def _check(deadline: Deadline | None) -> None:
    if deadline is not None and deadline.expired():
        raise BuildTimeout


def propagate(problem: RoadSearchProblem, ticks: int,
              deadline: Deadline | None = None) -> IntArray:
    """``(ticks + 1, M·N)`` directed edge of every particle at ticks ``0 … ticks``: the motion
    model stepped ``tick_s`` at a time with one generator seeded by ``draw_seed``.

    Raises
    ------
    BuildTimeout
        ``deadline`` expired (checked every tick).
    """
    rng = np.random.default_rng(problem.settings.draw_seed)
    edge, s = problem.particle_edge, problem.particle_s
    out = np.empty((ticks + 1, edge.size), dtype=np.int64)
    out[0] = edge.reshape(-1)
    motion, roads, dt = problem.settings.motion, problem.roads, problem.tick_s
    for t in range(1, ticks + 1):
        _check(deadline)
        edge, s = motion.step(roads, edge, s, dt, rng)
        out[t] = edge.reshape(-1)
    return out


def build_scenario(problem: RoadSearchProblem, deadline: Deadline | None = None) -> Scenario:
    """Build the time-expanded graphs, propagate the particles and group them.

    Raises
    ------
    BuildTimeout
        ``deadline`` expired (checked after each UAV's graph, every propagation tick and
        before the grouping); nothing is kept.
    """
    st = problem.settings
    raw = []
    for v, t in zip(problem.uav_nodes, problem.start_ticks, strict=True):
        _check(deadline)
        raw.append(_lattice_arcs(problem, v, int(t)))
    _check(deadline)
    both = st.both_directions
    n_roads = problem.roads.n_edges // 2 if both else problem.roads.n_edges
    road_length = problem.roads.length[0::2] if both else problem.roads.length
    span = int(max(r["state_tick"].max() for r in raw)) + 1
    codes = []
    for r in raw:
        flown = np.maximum(r["arc_edge"], 0)
        codes.append(np.where(r["arc_edge"] == HOLD, -1, (r["arc_level"] * span + r["arc_tick"])
                              * n_roads + (flown >> 1 if both else flown)))
    code = np.concatenate(codes)
    elements, inverse = np.unique(code[code >= 0], return_inverse=True)
    element_of = np.full(code.size, elements.size, dtype=np.int64)  # holds: the null element
    element_of[code >= 0] = inverse.reshape(-1)
    e_road = elements % n_roads
    e_tick = (elements // n_roads) % span
    e_level = elements // (n_roads * span)
    beta = st.discount ** e_level.astype(np.float64)
    if st.per_length:
        beta = beta / road_length[e_road]
    lattices, start = [], 0
    for r, c in zip(raw, codes, strict=True):
        arc_element = element_of[start:start + c.size]
        start += c.size
        lattices.append(Lattice(**{k: readonly(v, copy=False) for k, v in r.items()},
                                arc_element=readonly(arc_element)))
    last = int(max(lat.arc_tick[lat.arc_edge != HOLD].max() for lat in lattices))
    edge_at = propagate(problem, last, deadline)
    _check(deadline)
    road_at = edge_at >> 1 if both else edge_at
    # Slots: the distinct (tick, road) pairs; a particle's key is its slot at each used tick.
    slots, slot_of_element = np.unique(e_tick * n_roads + e_road, return_inverse=True)
    used, column_of_element = np.unique(e_tick, return_inverse=True)
    table = np.full((used.size, n_roads), -1, dtype=np.int64)
    table[np.searchsorted(used, slots // n_roads), slots % n_roads] = np.arange(slots.size)
    keys = table[np.arange(used.size)[None, :], road_at[used].T]  # (P, ticks used)
    value = (problem.gamma[:, None] * problem.particle_weight).reshape(-1)
    live = np.flatnonzero(np.any(keys >= 0, axis=1) & (value > 0.0))
    group_of = np.full(value.size, -1, dtype=np.int64)
    group_value: FloatArray = np.zeros(0)
    cover: FloatArray = np.zeros((elements.size, 0))
    if live.size:
        rows, group = np.unique(keys[live], axis=0, return_inverse=True)
        group = group.reshape(-1)
        group_of[live] = group
        group_value = np.bincount(group, weights=value[live],
                                  minlength=rows.shape[0]).astype(np.float64)
        sees = slot_of_element.reshape(-1)[:, None] == rows[:, column_of_element.reshape(-1)].T
        cover = np.where(sees, beta[:, None], 0.0)
    if np.any(code < 0):  # the null element of the hold arcs: sees nothing, worth nothing
        e_level, e_tick, e_road = (np.append(a, HOLD) for a in (e_level, e_tick, e_road))
        beta = np.append(beta, 0.0)
        cover = np.vstack([cover, np.zeros((1, cover.shape[1]))])
    return Scenario(tuple(lattices), readonly(e_level, copy=False), readonly(e_tick, copy=False),
                    readonly(e_road, copy=False), readonly(beta, copy=False),
                    readonly(edge_at, copy=False), readonly(group_of, copy=False),
                    readonly(group_value, copy=False), readonly(cover, copy=False))
