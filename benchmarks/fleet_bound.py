"""Paper 000's entropy lower bound reproduced: value, reference and difference for each check.

    python benchmarks/fleet_bound.py [--runs 100000]

B1: Eq. 30's round-trip ratios and S_node on 100 m grids (with and without the zero diagonal).
B2: P_D(t) on the 3 × 3 map with 50 m blocks at 10 m/s (Lemma 5 recursion), and the largest
    difference of a seeded Monte Carlo of ``--runs`` runs.
B3: B_L (Theorem 1) on the 3 × 3 map with 100 m blocks for M = 2 and 10 targets, Q = 1–4 UAVs,
    in the four variants (σ²_p0 by Eq. 37 or the authors' code × S_node with or without the
    diagonal); the reference values carry two decimals. Then Corollary 1 and the fleet size for
    a 16 m² requirement.
"""

from __future__ import annotations

import argparse
from fractions import Fraction

import numpy as np
from tables import table

from searchtrack.models import grid_network
from searchtrack.plan.fleet import (
    BoundConfig,
    BoundMap,
    chain_graph,
    entropy_bound,
    fleet_size,
    gaussian_entropy,
    mode_probabilities,
    mode_split_mc,
    round_trip_ratio,
    s_node,
    variance_bound,
)
from searchtrack.plan.fleet.entropy_bound import Growth

RATIOS = {2: 2.0, 3: 3.0, 4: 3.6095, 5: 4.0451, 10: 5.3047}
S_NODE = {(2, 3): (138.89, 166.67), (3, 3): (177.78, 200.00)}
TIMES = np.arange(1.0, 20.0, 2.0)
P_D = {
    Fraction(1): [0.867, 0.600, 0.333, 0.200, 0.067, 0, 0, 0, 0, 0],
    Fraction(1, 2): [0.100, 0.300, 0.500, 0.567, 0.633, 0.567, 0.367, 0.167, 0.100, 0.033],
    Fraction(1, 3): [0.033, 0.100, 0.167, 0.100, 0.033, 0, 0, 0, 0, 0],
    Fraction(1, 4): [0, 0, 0, 0, 0, 0.067, 0.200, 0.333, 0.333, 0.333],
    Fraction(1, 6): [0, 0, 0, 0.133, 0.267, 0.333, 0.333, 0.333, 0.200, 0.067],
    Fraction(1, 12): [0, 0, 0, 0, 0, 0.033, 0.100, 0.167, 0.367, 0.567],
}
B_L = {
    (2, 1): (2.80, 2.88, 2.68, 2.77),
    (10, 1): (3.54, 3.66, 3.49, 3.62),
    (10, 2): (2.97, 3.06, 2.88, 2.97),
    (10, 3): (2.74, 2.80, 2.61, 2.68),
    (10, 4): (2.59, 2.65, 2.44, 2.51),
}
VARIANTS: tuple[tuple[Growth, bool, str], ...] = (
    ("paper", True, "Eq. 37, incl."), ("paper", False, "Eq. 37, excl."),
    ("code", True, "code, incl."), ("code", False, "code, excl."))


def _row(name: str, value: float, reference: float, digits: int = 4) -> list[str]:
    return [name, f"{value:.{digits}f}", f"{reference:.{digits}f}",
            f"{value - reference:+.{digits}f}"]


def b1() -> None:
    """Round-trip ratios and S_node."""
    print("B1. Eq. 30 ratio S_avg/S_point and S_node (m) on 100 m grids")
    rows = [_row(f"ratio M={m}", round_trip_ratio(m), ref) for m, ref in RATIOS.items()]
    for (r, c), (incl, excl) in S_NODE.items():
        roads = grid_network(r, c, 100.0, 100.0)
        rows.append(_row(f"S_node {r}x{c} incl.", s_node(roads), incl, 2))
        rows.append(_row(f"S_node {r}x{c} excl.", s_node(roads, include_diagonal=False), excl, 2))
    table(["quantity", "value", "reference", "difference"], rows)


def b2(runs: int) -> None:
    """P_D(t) by the recursion against the reference table, and the Monte Carlo."""
    graph = chain_graph(grid_network(3, 3, 50.0, 50.0))
    exact = mode_probabilities(graph, 10.0, TIMES)
    mc = mode_split_mc(graph, 10.0, TIMES, runs, seed=0)
    print(f"\nB2. P_D(t), 3x3 map, 50 m blocks, 10 m/s: value / reference (recursion), "
          f"largest |recursion - Monte Carlo| over {runs} runs")
    rows = []
    for degree, reference in P_D.items():
        value = exact.of(degree)
        cells = [f"{v:.3f}/{r:.3f}" for v, r in zip(value, reference, strict=True)]
        rows.append([str(degree), *cells, f"{np.abs(value - reference).max():.4f}",
                     f"{np.abs(mc.of(degree) - value).max():.4f}"])
    table(["D", *(f"t={t:g}" for t in TIMES), "max |diff|", "max |MC|"], rows)
    print(f"sum of P_D: {exact.total.min():.12f} .. {exact.total.max():.12f}")


def b3() -> None:
    """B_L in the four variants, Corollary 1 and the fleet size."""
    roads = grid_network(3, 3, 100.0, 100.0)
    print("\nB3. B_L (nats), 3x3 map, 100 m blocks, v 10, V_a 40, σ_v 4, R 5, δ_t 0.1, 1 m bins")
    rows = []
    for (targets, uavs), reference in B_L.items():
        for (growth, diagonal, label), ref in zip(VARIANTS, reference, strict=True):
            config = BoundConfig(targets, growth=growth, include_diagonal=diagonal)
            bound = entropy_bound(BoundMap.from_network(roads, config), config, uavs)
            rows.append(_row(f"M={targets} Q={uavs} {label}", bound.bound, ref, 3))
    table(["case", "value", "reference", "difference"], rows)
    config = BoundConfig(10)
    h16, _ = gaussian_entropy(16.0, 1200.0)
    h19, _ = gaussian_entropy(19.0, 1200.0)
    sizing = fleet_size(BoundMap.from_network(roads, config), config, max_variance_m2=16.0)
    print("\nB4 and the worked example")
    table(["quantity", "value", "reference", "difference"], [
        _row("H(σ²=16) nats", float(h16), 2.805, 3),
        _row("H(σ²=19) nats", float(h19), 2.891, 3),
        _row("σ_p² for B_L=2.89 (m²)", variance_bound(2.89, 1200.0, config), 18.96, 2),
        _row("UAVs for 16 m², M=10", float(sizing.uavs or 0), 3.0, 0),
    ])


def main() -> None:
    """Print the B1–B4 reproduction tables."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    parser.add_argument("--runs", type=int, default=100_000, help="Monte Carlo runs for B2")
    args = parser.parse_args()
    b1()
    b2(args.runs)
    b3()


if __name__ == "__main__":
    main()
