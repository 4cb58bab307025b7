"""A whole scan's EMD matrix on a 10⁵-node road graph: the current path against a baseline.

    python benchmarks/association_city.py                      # before (HEAD~n) and after
    python benchmarks/association_city.py --before REV         # baseline from git revision REV
    python benchmarks/association_city.py --no-before --gates 300
    python benchmarks/association_city.py --graph grid      # a city grid, 10 m chains

Graph (``--graph``, about ``--nodes`` nodes, as a :class:`RoadNetwork`):

* ``lattice``: the jittered 10 m lattice of ``benchmarks/emd.py`` (10 % of the streets
  removed, the largest component kept). Every lattice node is a junction, so
  :class:`RoadMetric` gains nothing from chains here;
* ``grid``: a square city grid of 100 m blocks resampled every 10 m (``grid_network``): degree-2
  chains of 9 nodes between junctions, more junctions than :class:`RoadMetric` tabulates;
* ``osm``: the bundled Aguascalientes map resampled to the spacing that gives ``--nodes`` nodes
  (8602 nodes at the thesis' 10 m, so ~0.86 m for 10⁵): real chains and junctions, few enough
  junctions for :class:`RoadMetric`'s table. The scene is in hops, so supports are shorter in
  metres than on the 10 m graphs.

Scene (one UAV scan of Algorithm 1): ``--trackers`` point masses at random nodes diffused by
``--steps`` steps of the graph heat equation (explicit steps of ``α Δt = 0.134`` hop², as the
association benchmark's ``α = 0.447``, ``Δt = 0.3`` s), and ``--detections`` measurement
densities (noise ``--noise`` m): 70 % near a tracker's birth node, the rest at random nodes
(false alarms). ``support_mass = 0.999``.

Columns: ``before`` is :func:`emd_matrix` of the module at ``--before`` (loaded from git, one
call: it is slow), ``after`` the working tree's (best of ``--repeat`` calls after a warm-up),
both with the same scene and gate, one BLAS thread; ``max |Δ|`` compares the two matrices on
the pairs finite in either (the ``+inf`` patterns must agree). ``POT`` solves the same pairs'
transportation problems with ``ot.emd2`` given the dense distance block of each pair (POT needs
the matrix; the blocks are computed untimed by SciPy's Dijkstra, so only ``--pot-pairs`` pairs
are timed), beside the library's network simplex on the same blocks.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import math
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
from tables import table_with_header as table
from threadpoolctl import threadpool_limits

from searchtrack.estimate.node_tracker import measurement_density, position_log_likelihood
from searchtrack.estimate.signatures import truncate_signature
from searchtrack.estimate.transport import emd
from searchtrack.models import RoadNetwork, read_osm
from searchtrack.models.road_metric import RoadMetric
from searchtrack.models.road_synthetic import grid_network
from searchtrack.sim.roads.scenario import bundled_map

current = importlib.import_module("searchtrack.estimate.emd_matrix")
ROOT = Path(__file__).resolve().parent.parent
HEAT_STEP = 0.134  # α Δt in hop² per step: 0.447 × 0.3
SUBSTEPS = 2  # explicit heat steps per diffusion step (stable below 1/8 on a lattice)


def lattice(n: int, rng: np.random.Generator) -> RoadNetwork:
    """The jittered 10 m lattice of ``benchmarks/emd.py`` as a road network."""
    side = max(2, round(math.sqrt(n / 0.97)))
    ij = np.stack(np.meshgrid(np.arange(side), np.arange(side), indexing="ij"), -1)
    ij = ij.reshape(-1, 2).astype(float)
    xy = ij * 10.0 + rng.normal(0.0, 1.5, ij.shape)
    idx = np.arange(side * side).reshape(side, side)
    pairs = np.vstack([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()],
                       np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()]])
    pairs = pairs[rng.random(len(pairs)) >= 0.1]
    ell = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    return RoadNetwork(xy, pairs, ell, source=f"jittered 10 m lattice, {side}x{side}"
                       ).largest_component()


def city_grid(n: int) -> RoadNetwork:
    """A square grid of 100 m blocks, 10 m spacing, with about ``n`` nodes (19 per junction)."""
    side = max(2, round(math.sqrt(n / 19.0)))
    return grid_network(side, side, 100.0, 10.0)


def osm_map(n: int) -> RoadNetwork:
    """The bundled Aguascalientes map resampled to about ``n`` nodes."""
    path = bundled_map("aguascalientes")
    return read_osm(path, 10.0 * read_osm(path, 10.0).n_nodes / n)


def graph(kind: str, n: int, rng: np.random.Generator) -> RoadNetwork:
    """The road network of ``--graph``."""
    return lattice(n, rng) if kind == "lattice" else city_grid(n) if kind == "grid" else osm_map(n)


def scene(net: RoadNetwork, args: argparse.Namespace,
          rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``(k, n)`` diffused tracker distributions and ``(q, n)`` measurement densities."""
    births = rng.choice(net.n_nodes, args.trackers, replace=False)
    p = np.zeros((net.n_nodes, args.trackers))
    p[births, np.arange(args.trackers)] = 1.0
    lap = net.laplacian
    for _ in range(args.steps * SUBSTEPS):
        p -= (HEAT_STEP / SUBSTEPS) * (lap @ p)
    np.maximum(p, 0.0, out=p)
    trackers = (p / p.sum(axis=0)).T
    near = round(0.7 * args.detections)
    truth = np.vstack([net.coords[rng.choice(births, near)],
                       net.coords[rng.integers(net.n_nodes, size=args.detections - near)]])
    xy = truth + rng.normal(0.0, args.noise, truth.shape)
    return trackers, measurement_density(position_log_likelihood(net, xy, args.noise))


def baseline(rev: str) -> ModuleType:
    """``searchtrack/estimate/emd_matrix.py`` as it was at git revision ``rev``."""
    source = subprocess.run(["git", "show", f"{rev}:searchtrack/estimate/emd_matrix.py"],
                            cwd=ROOT, check=True, capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / "emd_matrix_before.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("emd_matrix_before", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def best(fn: Callable[[], np.ndarray], repeat: int) -> tuple[np.ndarray, float]:
    """The last value and the best wall-clock seconds of ``repeat`` calls."""
    out, times = np.empty(0), []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, min(times)


def pot_rows(net: RoadNetwork, trackers: np.ndarray, dets: np.ndarray, costs: np.ndarray,
             count: int) -> list[str]:
    """``ot.emd2`` and the library's ``emd`` on the first ``count`` finite pairs' blocks."""
    try:
        import ot
    except ImportError:
        return ["-", "-", "POT not installed"]
    pairs = np.argwhere(np.isfinite(costs))[:count]
    if not pairs.size:
        return ["-", "-", "no pair timed"]
    t_pot = t_lib = err = 0.0
    for i, j in pairs:
        a, b = truncate_signature(trackers[i]), truncate_signature(dets[j])
        block = np.ascontiguousarray(net.shortest_paths(b.nodes)[:, a.nodes].T)
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            value = float(ot.emd2(a.weights, b.weights, block, numItermax=10**9))
        t_pot += time.perf_counter() - t0
        t0 = time.perf_counter()
        mine = emd(a.weights, b.weights, block).objective
        t_lib += time.perf_counter() - t0
        err = max(err, abs(value - costs[i, j]), abs(float(mine or math.nan) - costs[i, j]))
    return [f"{1e3 * t_pot:.0f}", f"{1e3 * t_lib:.0f}",
            f"{len(pairs)} pairs, max |Δ| {err:.1e} m"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--graph", choices=["lattice", "grid", "osm"], default="lattice")
    parser.add_argument("--nodes", type=int, default=100_000)
    parser.add_argument("--trackers", type=int, default=100)
    parser.add_argument("--detections", type=int, default=100)
    parser.add_argument("--steps", type=int, default=50)
    parser.add_argument("--noise", type=float, default=10.0)
    parser.add_argument("--gates", type=float, nargs="+", default=[300.0, math.inf])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--before", default="HEAD", help="git revision of the baseline")
    parser.add_argument("--no-before", action="store_true")
    parser.add_argument("--pot-pairs", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    net = graph(args.graph, args.nodes, rng)
    trackers, dets = scene(net, args, rng)
    metric = RoadMetric(net)
    sizes = [truncate_signature(r).size for r in trackers], [truncate_signature(r).size
                                                            for r in dets]
    table_note = "tabulated" if metric.junction_distances is not None else "not tabulated"
    print(f"{net!r}\n{metric.junctions.size} junctions ({table_note}); "
          f"|S| tracker {np.mean(sizes[0]):.0f}, "
          f"detection {np.mean(sizes[1]):.0f} nodes (mean)\n")
    before = None if args.no_before else baseline(args.before)
    rows = [["gate (m)", "finite pairs", "before (s)", "after (s)", "speed-up", "max |Δ| (m)",
             "POT (ms)", "simplex (ms)", "POT note"]]
    with threadpool_limits(limits=1):
        current.emd_matrix(metric, trackers[:2], dets[:2], gate_m=300.0)  # warm-up
        for gate in args.gates:
            after, t_after = best(lambda g=gate: current.emd_matrix(
                metric, trackers, dets, gate_m=g, time_limit_s=3600.0), args.repeat)
            t_before, diff = math.nan, "-"
            if before is not None:
                old, t_before = best(lambda g=gate: before.emd_matrix(
                    metric, trackers, dets, gate_m=g, time_limit_s=3600.0), 1)
                same = np.array_equal(np.isfinite(old), np.isfinite(after))
                both = np.isfinite(old) & np.isfinite(after)
                gap = float(np.abs(old[both] - after[both]).max()) if both.any() else 0.0
                diff = f"{gap:.1e}" + ("" if same else " (inf pattern differs)")
            rows.append([f"{gate:g}", str(int(np.isfinite(after).sum())), f"{t_before:.3f}",
                         f"{t_after:.3f}", f"{t_before / t_after:.1f}x", diff,
                         *pot_rows(net, trackers, dets, after, args.pot_pairs)])
    table(rows)


if __name__ == "__main__":
    main()
