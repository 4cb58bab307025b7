"""EMD benchmark: graph flow vs distance matrix vs LP vs POT on a road-like graph.

    python benchmarks/emd.py                       # n = 200, 1000, 5000
    python benchmarks/emd.py --sizes 1000 --lp-max 1000 --repeat 5

The graph is a jittered 10 m lattice with 10 % of its streets removed (largest component kept),
edge lengths the Euclidean distances (≈ 10 m), or with ``--graph osm`` the n nodes of the
Aguascalientes OpenStreetMap network (resampled to 10 m) closest by road to a random node.
Cases:

* ``blobs``: two full-support Gaussian mixtures over all nodes (diffused tracker priors);
* ``random``: i.i.d. uniform weights on all nodes (the hardest, least structured case);
* ``support``: two 50-node signatures ~100 m apart (a truncated tracker vs a measurement, as in
  Algorithm 1), where a distance matrix only needs Dijkstra from 50 sources.

Reference: the cvxpy/HiGHS LP on the graph's arcs (exact). ``POT`` rows need ``pip install pot``
(a bench extra: searchtrack never imports it); its ``numItermax`` is raised so that it finishes.
``ortools`` rows scale to integers (supplies × 1e9, lengths in mm) and are therefore inexact.
Times are the best of ``--repeat`` runs for the fast methods, one run for the slow ones. Run on an
idle machine: timings depend on it.
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph
from threadpoolctl import threadpool_limits

from searchtrack.estimate.transport import emd, emd_on_graph
from searchtrack.models import read_osm
from searchtrack.sim.roads.scenario import bundled_map

SPACING_M = 10.0
SUPPORT = 50


@dataclass(frozen=True)
class Graph:
    """A road-like graph: CSR edge lengths (m) and planar node positions (m)."""

    adjacency: sp.csr_array
    xy: np.ndarray

    @property
    def n(self) -> int:
        return int(self.adjacency.shape[0])


def road_graph(n: int, rng: np.random.Generator) -> Graph:
    """A jittered lattice of about ``n`` nodes, 10 m apart, with 10 % of the streets removed."""
    side = max(2, round(math.sqrt(n / 0.97)))
    ij = np.array([(i, j) for i in range(side) for j in range(side)], dtype=float)
    xy = ij * SPACING_M + rng.normal(0.0, 1.5, ij.shape)
    idx = np.arange(side * side).reshape(side, side)
    pairs = np.vstack([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()],
                       np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()]])
    pairs = pairs[rng.random(len(pairs)) >= 0.1]
    ell = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    size = side * side
    adj = sp.csr_array((np.r_[ell, ell], (np.r_[pairs[:, 0], pairs[:, 1]],
                                          np.r_[pairs[:, 1], pairs[:, 0]])), shape=(size, size))
    _, label = csgraph.connected_components(adj, directed=False)
    keep = np.flatnonzero(label == np.bincount(label).argmax())
    return Graph(sp.csr_array(adj[keep][:, keep]), xy[keep])


def blobs(graph: Graph, rng: np.random.Generator, k: int, sigma_m: float) -> np.ndarray:
    """A mixture of ``k`` Gaussians at random nodes, positive everywhere."""
    centres = graph.xy[rng.choice(graph.n, k, replace=False)]
    d2 = ((graph.xy[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
    w = np.exp(-d2 / (2 * sigma_m**2)).sum(axis=1)
    return w + 1e-3 * w.max()


def truncated(graph: Graph, centre: int, size: int) -> np.ndarray:
    """A Gaussian (σ = 20 m) at ``centre`` kept on its ``size`` highest nodes, zero elsewhere."""
    d2 = ((graph.xy - graph.xy[centre]) ** 2).sum(axis=1)
    w = np.exp(-d2 / (2 * 20.0**2))
    out = np.zeros(graph.n)
    top = np.argsort(-w)[:size]
    out[top] = w[top]
    return out


def signatures(case: str, graph: Graph, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """``p`` and ``q`` for ``case``, both normalised."""
    if case == "blobs":
        p, q = blobs(graph, rng, 3, 60.0), blobs(graph, rng, 3, 60.0)
    elif case == "random":
        p, q = rng.random(graph.n), rng.random(graph.n)
    else:
        a = int(rng.integers(graph.n))
        near = np.flatnonzero(np.abs(np.linalg.norm(graph.xy - graph.xy[a], axis=1) - 100) < 10)
        p, q = truncated(graph, a, SUPPORT), truncated(graph, int(rng.choice(near)), SUPPORT)
    return p / p.sum(), q / q.sum()


def timed(fn: Callable[[], float], repeat: int) -> tuple[float, float]:
    """(value, best wall-clock seconds over ``repeat`` runs)."""
    best, value = math.inf, math.nan
    for _ in range(repeat):
        t0 = time.perf_counter()
        value = fn()
        best = min(best, time.perf_counter() - t0)
    return value, best


def objective(result: object) -> float:
    value = getattr(result, "objective", None)
    if value is None:
        raise RuntimeError(f"no objective: {getattr(result, 'message', result)}")
    return float(value)


def ortools_on_graph(adj: sp.csr_array, p: np.ndarray, q: np.ndarray) -> float:
    """OR-Tools SimpleMinCostFlow on the graph's arcs, integer-scaled (the baseline)."""
    from ortools.graph.python import min_cost_flow

    scale = 1e9
    coo = adj.tocoo()
    mcf = min_cost_flow.SimpleMinCostFlow()
    mcf.add_arcs_with_capacity_and_unit_cost(
        coo.row.astype(np.int32), coo.col.astype(np.int32),
        np.full(coo.nnz, 10**13, dtype=np.int64), np.round(coo.data * 1000).astype(np.int64))
    supply = np.round((p - q) * scale).astype(np.int64)
    supply[np.argmax(supply)] -= supply.sum()
    mcf.set_nodes_supplies(np.arange(adj.shape[0], dtype=np.int32), supply)
    if mcf.solve() != mcf.OPTIMAL:
        raise RuntimeError("OR-Tools min-cost flow failed")
    return float(mcf.optimal_cost()) / scale / 1000


def clarabel_on_graph(adj: sp.csr_array, p: np.ndarray, q: np.ndarray) -> float:
    """The graph LP with cvxpy's default solver (Clarabel, interior point)."""
    import cvxpy as cp

    coo = adj.tocoo()
    k = coo.nnz
    inc = sp.csr_array((np.r_[np.ones(k), -np.ones(k)], (np.r_[coo.row, coo.col],
                                                          np.r_[np.arange(k), np.arange(k)])),
                       shape=(adj.shape[0], k))
    f = cp.Variable(k, nonneg=True)
    lp = cp.Problem(cp.Minimize(coo.data @ f), [inc @ f == p - q])
    lp.solve()
    return float(lp.value)


def pot_emd(p: np.ndarray, q: np.ndarray, dist: np.ndarray) -> float:
    """POT's network simplex with the distance matrix given."""
    import ot

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numItermax reached would be a wrong answer
        return float(ot.emd2(p, q, dist, numItermax=10**9))


def osm_graph(n: int, rng: np.random.Generator) -> Graph:
    """The ``n`` road nodes of the Aguascalientes map (10 m spacing) nearest, in road distance,
    to a random node: a connected piece of a real road network."""
    net = read_osm(bundled_map("aguascalientes"))
    adj = sp.csr_array((np.r_[net.lengths_m, net.lengths_m],
                        (np.r_[net.edges[:, 0], net.edges[:, 1]],
                         np.r_[net.edges[:, 1], net.edges[:, 0]])), shape=(net.n_nodes,) * 2)
    dist = csgraph.dijkstra(adj, indices=int(rng.integers(net.n_nodes)))
    keep = np.sort(np.argsort(dist, kind="stable")[:min(n, net.n_nodes)])
    return Graph(sp.csr_array(adj[keep][:, keep]), net.coords[keep])


def run(case: str, n: int, args: argparse.Namespace, rng: np.random.Generator) -> list[list[str]]:
    """Rows of the table for one case and size."""
    graph = osm_graph(n, rng) if args.graph == "osm" else road_graph(n, rng)
    adj = graph.adjacency
    p, q = signatures(case, graph, rng)
    rows: list[list[str]] = []
    ref, t_ref = timed(
        lambda: objective(emd_on_graph(adj, p, q, backend="lp", time_limit_s=600)), 1)

    def add(method: str, fn: Callable[[], float], repeat: int, note: str = "") -> float:
        try:
            value, seconds = timed(fn, repeat)
        except Exception as exc:  # a failing baseline is a row, not a crash
            rows.append([case, str(graph.n), method, "-", "-", "-", f"{type(exc).__name__}: "
                         f"{str(exc)[:60]}"])
            return math.nan
        rel = abs(value - ref) / abs(ref)
        rows.append([case, str(graph.n), method, f"{value:.6f}", f"{rel:.1e}", f"{seconds:.4f}",
                     note])
        return seconds

    t_graph = add("graph network simplex", lambda: objective(emd_on_graph(adj, p, q)),
                  args.repeat, "emd_on_graph (no distance matrix)")
    rows.append([case, str(graph.n), "graph cvxpy+HiGHS LP", f"{ref:.6f}", "(reference)",
                 f"{t_ref:.4f}", "emd_on_graph(backend='lp')"])
    if n <= args.lp_max:
        add("graph cvxpy+Clarabel", lambda: clarabel_on_graph(adj, p, q), 1, "cvxpy default")
    add("graph OR-Tools min-cost flow", lambda: ortools_on_graph(adj, p, q), args.repeat,
        "integer-scaled")
    rows_i, cols_j = np.flatnonzero(p), np.flatnonzero(q)
    t0 = time.perf_counter()
    if case == "support":
        dist = csgraph.dijkstra(adj, directed=True, indices=rows_i)[:, cols_j]
        what = f"Dijkstra from {rows_i.size} sources"
    else:
        dist = csgraph.dijkstra(adj, directed=True)
        what = "all-pairs Dijkstra"
    t_dij = time.perf_counter() - t0
    rows.append([case, str(graph.n), "distance matrix", "-", "-", f"{t_dij:.4f}",
                 f"{what} {dist.shape[0]}x{dist.shape[1]}"])
    ps, qs = p[rows_i], q[cols_j]
    t_mat = add("matrix network simplex", lambda: objective(emd(ps, qs, dist)),
                args.repeat if graph.n <= 1000 else 1, "emd, matrix given")
    if not args.no_pot:
        add("matrix POT ot.emd", lambda: pot_emd(ps, qs, dist),
            args.repeat if graph.n <= 1000 else 1, "matrix given")
    if ps.size * qs.size <= args.lp_max**2 or (case != "support" and n <= args.lp_max):
        add("matrix cvxpy+HiGHS LP",
            lambda: objective(emd(ps, qs, dist, backend="lp", time_limit_s=600)), 1,
            "(4.3)-(4.7)")
    if t_mat < t_graph:
        pays = f"pays off after {math.ceil(t_dij / (t_graph - t_mat))} EMDs on one matrix"
    else:
        pays = "never pays off: the graph flow is faster per EMD"
    rows.append([case, str(graph.n), "=> reuse a distance matrix?", "", "", "", pays])
    return rows


def warm_up() -> None:
    """Compile the numba kernels and import cvxpy before anything is timed."""
    emd([1.0, 0.0], [0.0, 1.0], [[0.0, 1.0], [1.0, 0.0]])
    emd([1.0, 0.0], [0.0, 1.0], [[0.0, 1.0], [1.0, 0.0]], backend="lp")
    emd_on_graph(sp.csr_array(np.array([[0.0, 1.0], [1.0, 0.0]])), [1.0, 0.0], [0.0, 1.0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[200, 1000, 5000])
    parser.add_argument("--cases", nargs="+", default=["blobs", "random", "support"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--lp-max", type=int, default=200,
                        help="largest n for the dense cvxpy LP (n² variables: 36-230 s at n = 1000)"
                        " and Clarabel")
    parser.add_argument("--no-pot", action="store_true")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--graph", choices=["lattice", "osm"], default="lattice",
                        help="jittered lattice, or a connected piece of the Aguascalientes map")
    args = parser.parse_args()
    warm_up()
    header = ["case", "n", "method", "cost (m)", "rel. diff", "time (s)", "note"]
    table = [header]
    with threadpool_limits(limits=1):
        for n in args.sizes:
            for case in args.cases:
                table += run(case, n, args, np.random.default_rng([args.seed, n]))
    widths = [max(len(r[k]) for r in table) for k in range(len(header))]
    for k, r in enumerate(table):
        print("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
        if k == 0:
            print("  ".join("-" * w for w in widths))


if __name__ == "__main__":
    main()
