"""Guidance benchmark on the Aguascalientes map: ms per guidance solve and the reacquisition OPTW.

    python benchmarks/guidance.py                 # 20 calls per backend
    python benchmarks/guidance.py --calls 5

Scene: 3 UAVs, 4 trackers made by diffusing point masses at random nodes ``STEPS`` times with
``GraphDiffusion.on_network(network, 0.447, 0.3)`` (unweighted, as the trackers), so their
peaks straddle ``ϱ`` = 0.3; the UAVs start 300 m from random tracker peaks; the LRT field is
N(0, 1) noise. Times are the median wall-clock ms of ``--calls`` calls with one BLAS thread.
``search_and_reacquire`` is timed twice: ``first`` solves the problem without routes every call
(so each call plans its routes: ``T_r`` simulation, instance, OPTW solve within the 30 ms
``time_limit_s``) and ``steady`` passes each answer's routes to the next problem (the per-step
cost while following them).

The second table solves the reacquisition OPTW of the tracker whose peak is highest below ϱ, from
a start 300 m and 550 m east of its peak, with 40 and 80 candidate nodes (``support_mass=1``),
for each backend and budget; ``mass`` is the candidates' total probability, ``route`` the
number of nodes visited, ``ms`` the wall-clock time of ``solve``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from tables import table_with_header as table
from threadpoolctl import threadpool_limits

from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models import RoadNetwork, read_osm
from searchtrack.plan.guidance import (
    BACKENDS,
    GuidanceProblem,
    GuidanceView,
    StrategyConfig,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance import solve as guide
from searchtrack.plan.optw.solve import solve, warm_up
from searchtrack.sim.roads.scenario import bundled_map

OSM = str(bundled_map("aguascalientes"))
STEPS = (2, 8, 20, 60)
ALPHA, DT_S = 0.447, 0.3




def scene(net: RoadNetwork, diffusion: GraphDiffusion,
          rng: np.random.Generator) -> tuple[TrackerBank, np.ndarray, np.ndarray]:
    """The trackers, the UAV positions (3, 2) and an LRT field."""
    births = rng.choice(net.n_nodes, len(STEPS), replace=False)
    trackers = []
    for k, (node, steps) in enumerate(zip(births, STEPS, strict=True)):
        p = np.zeros(net.n_nodes)
        p[node] = 1.0
        for _ in range(steps):
            p = diffusion.propagate(p)
        p = np.maximum(p, 0.0)
        trackers.append(NodeTracker(p / p.sum(), k))
    bank = TrackerBank(net.n_nodes, tuple(trackers), len(trackers))
    angle = rng.uniform(0, 2 * np.pi, 3)
    peaks = net.coords[[trackers[k].peak_node() for k in rng.permutation(4)[:3]]]
    uav = peaks + 300.0 * np.column_stack([np.cos(angle), np.sin(angle)])
    return bank, uav, rng.normal(size=net.n_nodes)


def strategy_table(net: RoadNetwork, diffusion: GraphDiffusion, bank: TrackerBank,
                   uav: np.ndarray, llr: np.ndarray, calls: int) -> None:
    view = GuidanceView(net, uav, np.zeros(3), np.full(3, 35.76), LikelihoodField(llr), bank,
                        0.0)
    fresh = GuidanceProblem(view, StrategyConfig(), diffusion)
    rows = [["strategy", "modes", "median ms", "max ms", "plan ms"]]
    for name in BACKENDS.names():
        variants = ["first", "steady"] if name == "search_and_reacquire" else [""]
        for variant in variants:
            answer = guide(fresh, backend=name, time_limit_s=0.03, seed=0).plan  # warm-up
            assert answer is not None
            problem = fresh.following(view, answer)
            times, plan = [], []
            for k in range(calls):
                if variant == "first":
                    problem = fresh
                t0 = time.perf_counter()
                g = guide(problem, backend=name, time_limit_s=0.03, seed=k + 1).plan
                times.append(1e3 * (time.perf_counter() - t0))
                assert g is not None
                plan.append(g.plan_ms)
                problem = problem.following(view, g)
            label = f"{name} ({variant})" if variant else name
            rows.append([label, ",".join(m[0] for m in g.mode), f"{statistics.median(times):.2f}",
                         f"{max(times):.2f}", f"{statistics.median(plan):.2f}"])
    table(rows)


def optw_table(net: RoadNetwork, diffusion: GraphDiffusion, bank: TrackerBank,
               uav: np.ndarray) -> None:
    rows = [["UAV m", "T_r s", "nodes", "mass", "backend", "budget s", "status", "objective",
             "route", "ms"]]
    tracker = max((t for t in bank if t.peak_probability <= 0.3),
                  key=lambda t: t.peak_probability)
    peak = net.coords[tracker.peak_node()]
    for distance in (300.0, 550.0):
        optw_rows(net, diffusion, tracker, peak + np.array([distance, 0.0]), rows)
    table(rows)


def optw_rows(net: RoadNetwork, diffusion: GraphDiffusion, tracker: NodeTracker,
              start: np.ndarray, rows: list[list[str]]) -> None:
    t0 = time.perf_counter()
    horizon = reacquire_time(diffusion, tracker.probability, p_min=0.07)
    tr_ms = 1e3 * (time.perf_counter() - t0)
    print(f"tracker {tracker.track_id}: peak {tracker.peak_probability:.3f}, T_r = "
          f"{horizon:.1f} s ({tr_ms:.1f} ms to simulate), UAV "
          f"{np.hypot(*(start - net.coords[tracker.peak_node()])):.0f} m from the peak")
    for cap in (40, 80):
        inst, _ = reacquisition_instance(net, tracker.probability, start, 35.76, horizon,
                                           max_nodes=cap, support_mass=1.0)
        mass = float(inst.profit.sum())
        for backend in ("ils", "auto"):
            for budget in (0.01, 0.03, 0.1):
                t0 = time.perf_counter()
                res = solve(inst, backend=backend, time_limit_s=budget, seed=0)
                ms = 1e3 * (time.perf_counter() - t0)
                length = len(res.plan[0]) - 1 if res.plan else 0
                away = np.hypot(*(start - net.coords[tracker.peak_node()]))
                rows.append([f"{away:.0f}", f"{horizon:.1f}", str(inst.n - 1), f"{mass:.4f}",
                             backend, f"{budget:g}",
                             res.status.name, f"{res.objective or 0.0:.5f}", str(length),
                             f"{ms:.1f}"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    net = read_osm(OSM)
    diffusion = GraphDiffusion.on_network(net, ALPHA, DT_S)
    warm_up("auto")
    bank, uav, llr = scene(net, diffusion, np.random.default_rng(args.seed))
    print(f"{net.n_nodes} nodes, {net.n_edges} edges; tracker peaks "
          + ", ".join(f"{t.peak_probability:.3f}" for t in bank))
    with threadpool_limits(1):
        strategy_table(net, diffusion, bank, uav, llr, args.calls)
        print()
        optw_table(net, diffusion, bank, uav)


if __name__ == "__main__":
    main()
