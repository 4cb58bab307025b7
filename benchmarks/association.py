"""EMD association benchmark on the Aguascalientes map: ms per call, support sizes, truncation.

    python benchmarks/association.py                 # 3 seeds, 5 repeats
    python benchmarks/association.py --seeds 1 --repeat 3 --no-graph

Scenes (4 trackers × 3 measurements, as one UAV scan of the mission):

* ``spread``: trackers born at 4 random nodes; fixes near trackers 0 and 1 plus one near a
  random node (a false alarm). Most pairs are far apart, so the gate bounds skip them.
* ``close``: 4 trackers born within 250 m (road) of one node; fixes near trackers 0, 1 and 2.
  Every pair is a gate candidate: the worst case for the gated matrix.

Trackers are point masses diffused ``steps`` times by ``GraphDiffusion.on_network(network,
alpha=0.447, dt_s=0.3)``; fixes are ``position_log_likelihood`` + ``measurement_density`` with
noise ``s``. Times are in ms, the best of ``--repeat`` calls after one warm-up (the graph
column: one call), averaged over the seeds, with one BLAS thread: ``EMDAssociator`` with the
``greedy`` and ``optimal`` backends and ``method="transport"`` (the default), and greedy with
``method="graph"`` (min-cost flow on the whole road graph). ``|S|`` are mean truncated support
sizes at ``support_mass=0.999``; ``pairs`` counts the pairs solved (not skipped by a bound).

The second table: the EMD of a few nearby pairs at ``support_mass`` < 1 against the exact EMD of
the untruncated distributions (``support_mass=1``, graph flow on all 8602 nodes).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from tables import table_with_header as table
from threadpoolctl import threadpool_limits

from searchtrack.estimate.association import Associator
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.emd_matrix import emd_matrix
from searchtrack.estimate.node_tracker import (
    NodeTracker,
    TrackerBank,
    measurement_density,
    position_log_likelihood,
)
from searchtrack.estimate.signatures import truncate_signature
from searchtrack.models import RoadNetwork, read_osm
from searchtrack.models.road_metric import RoadMetric
from searchtrack.sim.roads.scenario import bundled_map

OSM = str(bundled_map("aguascalientes"))
STEPS = (10, 50, 200)
NOISE_M = (5.0, 10.0, 20.0)
ALPHA, DT_S = 0.447, 0.3


def diffused(diffusion: GraphDiffusion, nodes: np.ndarray, steps: int) -> np.ndarray:
    """``(len(nodes), n)`` point masses at ``nodes`` after ``steps`` diffusion steps."""
    p = np.zeros((diffusion.n_nodes, nodes.size))
    p[nodes, np.arange(nodes.size)] = 1.0
    for _ in range(steps):
        p = diffusion.propagate(p)
    np.maximum(p, 0.0, out=p)
    return (p / p.sum(axis=0)).T


def scene(net: RoadNetwork, metric: RoadMetric, kind: str,
          rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Tracker birth nodes (4) and true positions (3, 2) of the fixes."""
    if kind == "spread":
        births = rng.choice(net.n_nodes, 4, replace=False)
        truth = np.vstack([net.coords[births[:2]], net.coords[rng.integers(net.n_nodes)]])
        return births, truth
    centre = int(rng.integers(net.n_nodes))
    near = np.flatnonzero(metric.distances([centre], np.arange(net.n_nodes))[0] <= 250.0)
    births = rng.choice(near, 4, replace=False)
    return births, net.coords[births[:3]]


def best_ms(associator: Associator, bank: TrackerBank, dens: np.ndarray, repeat: int) -> float:
    """Best wall-clock ms of ``repeat`` association calls after one warm-up."""
    associator.associate(bank, dens)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        associator.associate(bank, dens)
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times)




def timing_table(net: RoadNetwork, args: argparse.Namespace) -> None:
    metric = RoadMetric(net)
    diffusion = GraphDiffusion.on_network(net, alpha=ALPHA, dt_s=DT_S)
    greedy, optimal = EMDAssociator(net, "greedy"), EMDAssociator(net, "optimal")
    graph = EMDAssociator(net, "greedy", method="graph", time_limit_s=30.0)
    rows = [["scene", "steps", "s (m)", "|S| trk", "|S| meas", "pairs", "greedy ms",
             "optimal ms", "graph ms", "agree"]]
    for kind in ("spread", "close"):
        for steps in STEPS:
            for noise in NOISE_M:
                g_ms, o_ms, f_ms, st, sq = [], [], [], [], []
                pairs, agree = 0, True
                for seed in range(args.seeds):
                    rng = np.random.default_rng([seed, steps, int(noise)])
                    births, truth = scene(net, metric, kind, rng)
                    p = diffused(diffusion, births, steps)
                    bank = TrackerBank(net.n_nodes, tuple(NodeTracker(row, k)
                                                          for k, row in enumerate(p)), 4)
                    xy = truth + rng.normal(0.0, noise, size=truth.shape)
                    dens = measurement_density(position_log_likelihood(net, xy, noise))
                    st += [truncate_signature(r).size for r in p]
                    sq += [truncate_signature(r).size for r in dens]
                    assoc, costs = greedy.associate_with_costs(bank, dens)
                    pairs += int(np.isfinite(costs).sum())
                    g_ms.append(best_ms(greedy, bank, dens, args.repeat))
                    o_ms.append(best_ms(optimal, bank, dens, args.repeat))
                    if not args.no_graph:
                        f_ms.append(best_ms(graph, bank, dens, 1))
                        agree &= graph.associate(bank, dens).pairs == assoc.pairs
                rows.append([kind, str(steps), f"{noise:g}", f"{np.mean(st):.0f}",
                             f"{np.mean(sq):.0f}", f"{pairs}/{12 * args.seeds}",
                             f"{np.mean(g_ms):.2f}", f"{np.mean(o_ms):.2f}",
                             f"{np.mean(f_ms):.1f}" if f_ms else "-",
                             ("yes" if agree else "NO") if f_ms else "-"])
    table(rows)


def truncation_table(net: RoadNetwork, args: argparse.Namespace) -> None:
    metric = RoadMetric(net)
    diffusion = GraphDiffusion.on_network(net, alpha=ALPHA, dt_s=DT_S)
    masses = (0.99, 0.999, 0.9999)
    rows = [["steps", "s (m)", "EMD full (m)", "full ms"]
            + [f"rel.err {m:g}" for m in masses] + [f"ms {m:g}" for m in masses]]
    rng = np.random.default_rng(args.seeds)
    for steps, noise in ((10, 5.0), (50, 10.0), (200, 20.0)):
        births, truth = scene(net, metric, "close", rng)
        p = diffused(diffusion, births[:1], steps)
        xy = truth[:1] + np.array([[noise, 0.0]]) + rng.normal(0.0, noise, size=(1, 2))
        dens = measurement_density(position_log_likelihood(net, xy, noise))
        t0 = time.perf_counter()
        full = float(emd_matrix(metric, p, dens, support_mass=1.0, method="graph",
                                time_limit_s=600.0)[0, 0])
        full_ms = 1e3 * (time.perf_counter() - t0)
        errs, times = [], []
        for m in masses:
            t0 = time.perf_counter()
            value = float(emd_matrix(metric, p, dens, support_mass=m)[0, 0])
            times.append(1e3 * (time.perf_counter() - t0))
            errs.append(abs(value - full) / full)
        rows.append([str(steps), f"{noise:g}", f"{full:.3f}", f"{full_ms:.0f}"]
                    + [f"{e:.1e}" for e in errs] + [f"{t:.2f}" for t in times])
    table(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--no-graph", action="store_true", help="skip the method='graph' column")
    args = parser.parse_args()
    net = read_osm(OSM)
    t0 = time.perf_counter()
    metric = RoadMetric(net)
    print(f"{net!r}\nRoadMetric: {metric.junctions.size} junctions, built in "
          f"{1e3 * (time.perf_counter() - t0):.0f} ms\n")
    with threadpool_limits(limits=1):
        timing_table(net, args)
        print()
        truncation_table(net, args)


if __name__ == "__main__":
    main()
