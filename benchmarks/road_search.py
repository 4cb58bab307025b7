"""Road-search planners (Moore et al. 2021, §4): decision time and objective against the
exhaustive receding-horizon controller.

Part 1, the paper's 3×3 grid (100 m roads, V_a = 40 m/s), M = 2 targets of N = 500 particles
(one tracked cloud, one still spread over the map), L = 1..5. Part 2, the Aguascalientes OSM map
(resampled to 10 m nodes) with M = 4 tracked clouds, planning over intersections (degree-2
chains merged, :class:`~searchtrack.plan.road_search.ChainGraph`) and, for contrast, over the
raw 10 m edges. A decision is the problem built from the belief (particles mapped, scenario
propagated and grouped) plus the solve; ``ms`` is its mean (and max) wall time. Part 3, the
West-Oakland map of the paper-000 OSM campaign (one edge per segment between junctions), M = 4
(two tracked clouds, two spread over the map), two UAVs planned jointly, the second still
1–5 s from its node (as when one UAV decides while the other flies): paths of L = 3 edges (the
paper's) and paths up to a 15 s time horizon of at most 6 edges (the campaign's RHC).
``ratio`` is the mean objective over the exhaustive one on the same decisions, ``bound/obj``
the mean proven bound over the objective (over the decisions with a plan; ``no plan``: the
decisions whose time limit ran out first), ``gap`` the mean of :attr:`Result.gap` (relative to
``max(1, objective)``, so absolute here where objectives are below 1). With four targets the
entropy weights use ``normalization="max"`` (with ``"sum"`` every weight falls below 1/2).

Run: ``.venv/bin/python benchmarks/road_search.py [--decisions 10] [--skip-osm]``
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.tables import table
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.road_search import ChainGraph, RoadSearchProblem, RoadSearchSettings, solve
from searchtrack.sim.road_particles.experiment import ROAD_MAPS
from searchtrack.sim.roads.experiment import MAPS

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

BACKENDS = [("exhaustive", 10.0), ("beam", 10.0), ("greedy", 10.0), ("exact", 2.0),
            ("auto", 0.05), ("random", 10.0), ("ideal", 10.0)]
"""Backends and their time limits (s); ``auto`` gets a 50 ms decision budget."""


@dataclass
class Belief:
    """A RoadParticleBelief of fixed clouds, with histogram entropies (10 m bins per edge)."""

    roads: DirectedRoads
    edge: IntArray
    s: FloatArray
    w: FloatArray

    @property
    def n_targets(self) -> int:
        return int(self.edge.shape[0])

    def target_particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        return self.edge.copy(), self.s.copy(), self.w.copy()

    def target_entropy(self) -> FloatArray:
        out = []
        for e, s in zip(self.edge, self.s, strict=True):
            _, counts = np.unique(e * 10_000 + (s // 10.0).astype(np.int64), return_counts=True)
            p = counts / counts.sum()
            out.append(float(-(p * np.log(p)).sum()))
        return np.array(out)


def cloud(roads: DirectedRoads, n: int, spread_m: float,
          rng: np.random.Generator) -> tuple[IntArray, FloatArray, tuple[int, float]]:
    """``n`` particles up to ``spread_m`` ahead of a random true position, and that position."""
    e0, s0 = roads.uniform(1, rng)
    e = np.repeat(e0, n)
    s = np.repeat(s0, n)
    e, s = roads.advance(e, s, rng.uniform(0.0, spread_m, n), rng)
    truth_e, truth_s = roads.advance(e0, s0, np.array([0.5 * spread_m]), rng)
    return e, s, (int(truth_e[0]), float(truth_s[0]))


def belief(roads: DirectedRoads, targets: int, n: int, spreads: list[float | None],
           rng: np.random.Generator) -> tuple[Belief, tuple[IntArray, FloatArray]]:
    """Clouds of the given spreads (``None``: uniform over the map) and true positions."""
    edges, ss, te, ts = [], [], [], []
    for m in range(targets):
        spread = spreads[m % len(spreads)]
        if spread is None:
            e, s = roads.uniform(n, rng)
            truth = (int(e[0]), float(s[0]))
        else:
            e, s, truth = cloud(roads, n, spread, rng)
        edges.append(e)
        ss.append(s)
        te.append(truth[0])
        ts.append(truth[1])
    return (Belief(roads, np.stack(edges), np.stack(ss), np.full((targets, n), 1.0 / n)),
            (np.array(te), np.array(ts)))


@dataclass
class Row:
    objective: list[float]
    ratio: list[float]
    bound: list[float]
    bound_ratio: list[float]
    gap: list[float]
    ms: list[float]
    optimal: int = 0
    no_plan: int = 0


Case = tuple[Belief, tuple[IntArray, FloatArray], list[int]]
"""A decision: the belief, the true positions and the UAVs' nodes."""


def run(label: str, cases: list[Case], settings: RoadSearchSettings, chains: ChainGraph | None,
        rows: list[list[str]], delays: list[list[float]] | None = None) -> None:
    """Every backend on every decision of one instance; one table row per backend
    (``delays``: per decision, the seconds before each UAV reaches its node)."""
    stats = {name: Row([], [], [], [], [], []) for name, _ in BACKENDS}
    for i, (b, truth, nodes) in enumerate(cases):
        reference = None
        for name, limit in BACKENDS:
            start = time.perf_counter()
            problem = RoadSearchProblem.from_belief(b, nodes, settings=settings, chains=chains,
                                                    truth=truth,
                                                    uav_delay_s=delays[i] if delays else ())
            res = solve(problem, backend=name, time_limit_s=limit)
            ms = (time.perf_counter() - start) * 1e3
            row = stats[name]
            if res.objective is None or res.bound is None:  # no plan within the time limit
                assert name != "exhaustive" or reference is not None, res.message
                row.no_plan += 1
                row.ms.append(ms)
                continue
            if name == "exhaustive":
                reference = res.objective
            assert reference is not None
            row.objective.append(res.objective)
            row.ratio.append(res.objective / reference if reference > 0 else 1.0)
            row.bound.append(res.bound)
            row.bound_ratio.append(res.bound / res.objective if res.objective > 0 else 1.0)
            row.gap.append(res.gap if res.gap is not None else np.nan)
            row.ms.append(ms)
            row.optimal += res.status.name == "OPTIMAL"
    for name, _ in BACKENDS:
        r = stats[name]
        rows.append([label, name, f"{np.mean(r.objective):.4f}", f"{np.mean(r.ratio):.3f}",
                     f"{np.mean(r.bound):.4f}", f"{np.mean(r.bound_ratio):.3f}",
                     f"{np.nanmean(r.gap):.4f}",
                     f"{r.optimal}/{len(r.ms)}", f"{r.no_plan}", f"{np.mean(r.ms):.1f}",
                     f"{np.max(r.ms):.1f}"])


HEADER = ["instance", "backend", "objective", "ratio", "bound", "bound/obj", "gap", "optimal",
          "no plan", "ms", "max ms"]


def grid_part(decisions: int, particles: int) -> None:
    """The paper's 3×3 grid, L = 1..5, one UAV (and two at L = 3), the paper's settings."""
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    rng = np.random.default_rng(0)
    cases = []
    for _ in range(decisions):
        b, truth = belief(roads, 2, particles, [150.0, None], rng)
        cases.append((b, truth, [int(rng.integers(roads.network.n_nodes))]))
    rows: list[list[str]] = []
    for lookahead in (1, 2, 3, 4, 5):
        run(f"grid M=2 Q=1 L={lookahead}", cases, RoadSearchSettings(lookahead=lookahead),
            None, rows)
    two = [(b, t, [*nodes, int((nodes[0] + 4) % 9)]) for b, t, nodes in cases]
    run("grid M=2 Q=2 L=3", two, RoadSearchSettings(lookahead=3), None, rows)
    print(f"\n3x3 grid, 100 m roads, V_a 40 m/s, N = {particles}, {decisions} decisions each")
    table(HEADER, rows)


def osm_part(decisions: int, particles: int) -> None:
    """Aguascalientes, M = 4 tracked clouds, UAVs at intersections near the first clouds."""
    net = MAPS["aguascalientes"].build()
    fine = DirectedRoads(net)
    start = time.perf_counter()
    chains = ChainGraph(net)
    build_ms = (time.perf_counter() - start) * 1e3
    chains.roads  # noqa: B018  (built once per map, like the chain graph)
    rng = np.random.default_rng(1)
    kept = chains.node_ids
    cases, fine_cases = [], []
    for _ in range(decisions):
        b, truth = belief(fine, 4, particles, [200.0], rng)
        near = fine.point(b.edge[:, 0], b.s[:, 0])
        nodes = []
        for q in range(2):
            d = np.linalg.norm(net.coords[kept] - near[q], axis=1)
            nodes.append(int(kept[np.argmin(d)]))
        cases.append((b, truth, nodes[:1]))
        fine_cases.append((b, truth, nodes))
    rows: list[list[str]] = []
    for lookahead in (3, 4, 5):
        run(f"osm merged M=4 Q=1 L={lookahead} tick 1 s", cases,
            RoadSearchSettings(lookahead=lookahead, tick_s=1.0, normalization="max"), chains,
            rows)
    run("osm merged M=4 Q=1 L=4 tick auto", cases,
        RoadSearchSettings(lookahead=4, normalization="max"), chains, rows)
    run("osm merged M=4 Q=2 L=4 tick 1 s", fine_cases,
        RoadSearchSettings(lookahead=4, tick_s=1.0, normalization="max"), chains, rows)
    run("osm 10 m edges M=4 Q=1 L=5", cases,
        RoadSearchSettings(lookahead=5, normalization="max"), None, rows)
    print(f"\nAguascalientes ({net.n_nodes} nodes at 10 m; merged: {chains.network.n_nodes} "
          f"nodes, {chains.network.n_edges} roads, built in {build_ms:.0f} ms once), "
          f"N = {particles}, {decisions} decisions each")
    table(HEADER, rows)


def oakland_part(decisions: int, particles: int) -> None:
    """West-Oakland, M = 4, two UAVs jointly (one in flight): L = 3 and a 15 s horizon."""
    roads = DirectedRoads(ROAD_MAPS["West-Oakland"].build())
    rng = np.random.default_rng(2)
    cases: list[Case] = []
    delays: list[list[float]] = []
    for _ in range(decisions):
        b, truth = belief(roads, 4, particles, [200.0, None], rng)
        nodes = [int(v) for v in rng.integers(roads.network.n_nodes, size=2)]
        cases.append((b, truth, nodes))
        delays.append([0.0, float(rng.uniform(1.0, 5.0))])
    rows: list[list[str]] = []
    run("W-Oakland M=4 Q=2 L=3", cases, RoadSearchSettings(lookahead=3, normalization="max"),
        None, rows, delays)
    run("W-Oakland M=4 Q=2 15 s, L<=6", cases,
        RoadSearchSettings(lookahead=6, horizon_s=15.0, normalization="max"), None, rows, delays)
    one = [(b, t, nodes[:1]) for b, t, nodes in cases]
    run("W-Oakland M=4 Q=1 15 s, L<=6", one,
        RoadSearchSettings(lookahead=6, horizon_s=15.0, normalization="max"), None, rows)
    print(f"\nWest-Oakland ({roads.network.n_nodes} nodes, {roads.n_edges // 2} roads), "
          f"N = {particles}, {decisions} decisions each; the second UAV 1-5 s from its node")
    table(HEADER, rows)


def warm_up() -> None:
    """Import every backend's solver once (OR-Tools' first import is not a decision's cost)."""
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    b, truth = belief(roads, 2, 50, [100.0], np.random.default_rng(99))
    problem = RoadSearchProblem.from_belief(b, [4], truth=truth)
    for name, _ in BACKENDS:
        solve(problem, backend=name, time_limit_s=1.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else "")
    parser.add_argument("--decisions", type=int, default=10)
    parser.add_argument("--particles", type=int, default=500)
    parser.add_argument("--skip-osm", action="store_true")
    args = parser.parse_args()
    with threadpool_limits(limits=1):
        warm_up()
        grid_part(args.decisions, args.particles)
        if not args.skip_osm:
            osm_part(max(1, args.decisions // 2), args.particles)
            oakland_part(args.decisions, args.particles)


if __name__ == "__main__":
    main()
