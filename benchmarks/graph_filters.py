"""Time one predict + update step of the graph filters at about 8600 nodes.

    python benchmarks/graph_filters.py [--network aguascalientes|grid] [--repeats 200]

Rows: the LRT (3 UAV disc updates, detection check, prediction (3.8)) and a bank of 4 node
trackers (4 Gaussian position updates, batched prediction (4.2)), each with the cached sparse
operator and with ``expm_multiply``, under a one-thread and the default BLAS pool. The closed
loop budget (predict + update + associate + plan, 3 UAVs, 4 trackers) is 50 ms per step.
Run on an idle machine: timings depend on it.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from searchtrack.estimate import (
    GraphDiffusion,
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    TrackerBank,
    TrackerPredictor,
    position_log_likelihood,
    update_likelihood_field,
    update_tracker,
)
from searchtrack.estimate.diffusion import Method
from searchtrack.models import RoadNetwork, grid_network, read_osm
from searchtrack.sim.roads.scenario import bundled_map

OSM = bundled_map("aguascalientes")
ALPHA, DT_S, DECAY_C, M, RHO_M, S_M = 0.447, 0.3, 50.0, 2.9264, 120.0, 5.0


def network(name: str) -> RoadNetwork:
    """The Aguascalientes OSM extract at 10 m (8602 nodes) or a 30 × 30 grid (8581 nodes)."""
    if name == "aguascalientes":
        return read_osm(OSM, spacing_m=10.0)
    return grid_network(30, 30, block_m=50.0, spacing_m=10.0)


def median_ms(step: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Median wall and median CPU time of ``step`` (ms), after two warm-up calls.

    On a shared machine the wall time includes being descheduled; the process CPU time does
    not, so it is the better estimate of the cost itself (for one-thread work).
    """
    step()
    step()
    wall, cpu = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        step()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return 1e3 * statistics.median(wall), 1e3 * statistics.median(cpu)


def timings(
    net: RoadNetwork,
    method: Method,
    field: LikelihoodField,
    bank: TrackerBank,
    footprints: list[NDArray[np.int64]],
    fixes: NDArray[np.float64],
    repeats: int,
) -> list[tuple[float, float]]:
    """(wall, CPU) median ms of LRT predict, update, step, then tracker predict, update, step."""
    n = net.n_nodes
    initiator = LRTInitiator(net)
    lrt_pred = LRTPredictor(GraphDiffusion.on_network(net, ALPHA, DT_S, decay_c=DECAY_C,
                                                      method=method))
    trk_pred = TrackerPredictor(GraphDiffusion.on_network(net, ALPHA, DT_S, method=method))

    def lrt_update() -> LikelihoodField:
        f = field
        for fp in footprints:
            f = update_likelihood_field(f, 0.3, fp, M)
        return initiator.initiate(f, TrackerBank(n))[0]

    def trk_update() -> TrackerBank:
        ll = position_log_likelihood(net, fixes, S_M)
        return bank.with_trackers(tuple(update_tracker(t, ll[k])
                                        for k, t in enumerate(bank.trackers)))

    steps: list[Callable[[], object]] = [
        lambda: lrt_pred.predict(field),
        lrt_update,
        lambda: lrt_pred.predict(lrt_update()),
        lambda: trk_pred.predict(bank),
        trk_update,
        lambda: trk_pred.predict(trk_update()),
    ]
    return [median_ms(step, repeats) for step in steps]


def main() -> None:
    """Print the timing table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--network", choices=["aguascalientes", "grid"], default="aguascalientes")
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args()
    net = network(args.network)
    n = net.n_nodes
    rng = np.random.default_rng(0)
    uavs = net.coords[rng.choice(n, 3, replace=False)]
    footprints = [np.flatnonzero(np.hypot(*(net.coords - c).T) <= RHO_M) for c in uavs]
    targets = rng.choice(n, 4, replace=False)
    fixes = net.coords[targets] + rng.normal(0.0, S_M, (4, 2))
    field = LikelihoodField(rng.normal(0.0, 2.0, n))
    bank = TrackerBank(n)
    for t in targets:
        bank = bank.with_birth(np.eye(1, n, int(t))[0])

    t0 = time.perf_counter()
    cached_lrt = GraphDiffusion.on_network(net, ALPHA, DT_S, decay_c=DECAY_C)
    op = cached_lrt.operator
    build_s = time.perf_counter() - t0
    nnz = 0 if op is None else op.nnz / n
    print(f"{net!r}\ncached operator: built in {build_s:.2f} s, {nnz:.1f} entries per node "
          f"(αΔt = {ALPHA * DT_S:.3f} per hop²)\n")

    rows: list[tuple[str, str, list[tuple[float, float]]]] = []
    methods: tuple[Method, ...] = ("cached", "expm_multiply")
    for method in methods:
        for threads in ("1", "default"):
            ctx: AbstractContextManager[object] = (
                threadpool_limits(1) if threads == "1" else nullcontext())
            with ctx:
                times = timings(net, method, field, bank, footprints, fixes, args.repeats)
            rows.append((method, threads, times))

    head = ("method", "BLAS", "LRT pred", "LRT upd", "LRT step", "4trk pred", "4trk upd",
            "4trk step", "both")
    for which, title in ((1, "median CPU time per call"), (0, "median wall time per call")):
        print(f"{title} (ms):")
        print("  ".join(f"{h:>10}" if k > 1 else f"{h:<13}" for k, h in enumerate(head)))
        for name, threads, t in rows:
            cells = [x[which] for x in t]
            cells.append(cells[2] + cells[5])
            print(f"{name:<13}  {threads:<13}  " + "  ".join(f"{x:10.3f}" for x in cells))
        print()

if __name__ == "__main__":
    main()
