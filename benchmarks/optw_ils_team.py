"""Benchmark the team OPTW iterated local search against the literature's best known values.

Usage: ``python benchmarks/optw_ils_team.py [LIMIT_S ...] [--seed N] [--vehicles 1 2 3 4]
[--instances pr11 pr12 ...]`` (default limits 1 and 10 s, Cordeau pr01–pr20, m = 1…4).

For each (instance, m) it prints the profit, the best known value of ``toptw_best_known.csv`` and
the gap ``(best known − profit) / best known`` in %, then the mean gap per m and overall. Every
plan is re-checked by the independent validator. A profit above the best known value is flagged
and its routes printed: a possible new best known value, or a sign that the list uses another
distance convention (see ``toptw_best_known.md``).

Some listed values exceed an upper bound the library's exact solvers prove under its reading of
the files (``toptw_bounds.csv``; most are proven optima): no plan can reach them there. The table
therefore also prints the *reachable reference*, the lesser of the two, and the gap to it; a
profit above a proven bound is flagged as an error. Run serially on an idle machine.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from optw_ils import solve_checked, timed_warm_up

from searchtrack.plan.optw import read_optw

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "searchtrack" / "data"
FOLDERS = (DATA / "optw" / "cordeau", DATA / "toptw" / "cordeau")
INSTANCES = [f"pr{i:02d}" for i in range(1, 21)]


def best_known() -> dict[tuple[str, int], float]:
    """The literature's best known values by (instance, m) (``toptw_best_known.csv``)."""
    with (HERE / "toptw_best_known.csv").open(encoding="utf-8") as fh:
        return {(r["instance"], int(r["vehicles"])): float(r["best_known"])
                for r in csv.DictReader(fh)}


def _path(name: str) -> Path:
    for folder in FOLDERS:
        p = folder / f"{name}.txt"
        if p.exists():
            return p
    raise SystemExit(f"unknown instance {name!r}")


def bounds() -> dict[tuple[str, int], float]:
    """Upper bounds proved by the library under its reading of the files, where they are below
    the listed value (``toptw_bounds.csv``)."""
    with (HERE / "toptw_bounds.csv").open(encoding="utf-8") as fh:
        return {(r["instance"], int(r["vehicles"])): float(r["bound"])
                for r in csv.DictReader(fh)}


def run(limit_s: float, seed: int, names: list[str], vehicles: list[int]) -> float:
    """Solve every (instance, m) within ``limit_s`` seconds; print the table; return the mean
    gap."""
    bk, opt = best_known(), bounds()
    gaps: dict[int, list[float]] = {m: [] for m in vehicles}
    reach: dict[int, list[float]] = {m: [] for m in vehicles}
    print(f"\n== time limit {limit_s:g} s, seed {seed}")
    print(f"{'instance':9} {'m':>2} {'profit':>7} {'best':>7} {'gap %':>7} {'ref':>7} "
          f"{'gap ref':>7} {'time s':>7} {'iters':>8}")
    for name in names:
        for m in vehicles:
            if (name, m) not in bk:
                continue
            res, check, elapsed = solve_checked(read_optw(_path(name), vehicles=m), limit_s,
                                                seed, f"{name} m={m}")
            assert res.plan is not None and res.objective is not None
            best = bk[(name, m)]
            gap = 100.0 * (best - res.objective) / best
            ref = min(best, opt.get((name, m), best))
            gaps[m].append(gap)
            reach[m].append(100.0 * (ref - res.objective) / ref)
            flag = "  ABOVE BEST KNOWN" if res.objective > best + 1e-9 else ""
            if res.objective > opt.get((name, m), res.objective) + 1e-9:
                flag += "  ABOVE A PROVEN BOUND: AN ERROR"
            print(f"{name:9} {m:2d} {res.objective:7g} {best:7g} {gap:7.2f} {ref:7g} "
                  f"{reach[m][-1]:7.2f} {elapsed:7.2f} "
                  f"{int(res.stats.get('iterations', 0)):8d}{flag}", flush=True)
            if flag:
                for route in res.plan:
                    print(f"    route {list(route)}")
                print(f"    validated: feasible, profit {check.profit:g}")
    every = [g for m in vehicles for g in gaps[m]]
    to_ref = [g for m in vehicles for g in reach[m]]
    for m in vehicles:
        if gaps[m]:
            print(f"mean gap m={m}: {sum(gaps[m]) / len(gaps[m]):.3f} % over {len(gaps[m])} "
                  f"(to the reachable reference {sum(reach[m]) / len(reach[m]):.3f} %)")
    mean = sum(every) / max(1, len(every))
    print(f"mean gap overall: {mean:.3f} % over {len(every)} "
          f"({sum(g > 0 for g in every)} below best known); to the reachable reference "
          f"{sum(to_ref) / max(1, len(to_ref)):.3f} % ({sum(g > 0 for g in to_ref)} below)")
    return mean


def main() -> None:
    """Parse the command line and run the benchmark for each time limit."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("limits", nargs="*", type=float, default=[1.0, 10.0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--vehicles", nargs="+", type=int, default=[1, 2, 3, 4])
    ap.add_argument("--instances", nargs="+", default=INSTANCES)
    args = ap.parse_args()
    timed_warm_up()
    for limit in args.limits:
        run(limit, args.seed, args.instances, args.vehicles)


if __name__ == "__main__":
    main()
