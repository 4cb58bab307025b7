"""Benchmark the exact OPTW labelling solver on the instances with a known optimum (m = 1).

Usage: ``python benchmarks/optw_exact.py [NAME ...] [--limit S] [--open] [--root DIR]``
(default: every instance of ``optima.csv`` whose optimum is proven, 60 s each; ``--open`` adds
the instances whose optimum is still open). Every plan is re-checked with the independent
validator; a proof that contradicts a known optimum aborts the run.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

from searchtrack.core.result import Status
from searchtrack.plan.optw import read_optw, validate
from searchtrack.plan.optw.labelling import solve_labelling, warm_up

BENCH = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"


def instances(root: Path, with_open: bool) -> list[tuple[Path, float | None]]:
    """(instance file, optimum or ``None`` when open) for the rows of ``optima.csv``."""
    rows: list[tuple[Path, float | None]] = []
    with (root / "optima.csv").open(encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            known = row["status"] == "proven"
            if known or with_open:
                best = float(row["optimum"]) if known else None
                rows.append((root / row["set"] / f"{row['instance']}.txt", best))
    return rows


def run(root: Path, limit_s: float, names: set[str], with_open: bool) -> int:
    """Solve the selected instances; print one row each and return how many were proven."""
    print(f"== labelling, time limit {limit_s:g} s")
    print(f"{'instance':9} {'profit':>7} {'bound':>7} {'optimum':>7} {'status':>11} "
          f"{'time s':>7} {'passes':>6} {'labels':>9}")
    proven = known = 0
    for path, best in instances(root, with_open or bool(names)):
        if names and path.stem not in names:
            continue
        inst = read_optw(path)
        started = time.perf_counter()
        res = solve_labelling(inst, time_limit_s=limit_s)
        elapsed = time.perf_counter() - started
        if res.plan is not None:
            check = validate(inst, res.plan)
            if not check.feasible or abs(check.profit - (res.objective or 0.0)) > 1e-6:
                raise SystemExit(f"{path.stem}: invalid plan {check.violations} {check.profit}")
        if best is not None:
            known += 1
            if res.bound is not None and res.bound < best - 1e-6:
                raise SystemExit(f"{path.stem}: bound {res.bound} below the optimum {best}")
            if res.status is Status.OPTIMAL:
                if res.objective is None or abs(res.objective - best) > 1e-6:
                    raise SystemExit(f"{path.stem}: 'optimal' {res.objective} ≠ optimum {best}")
                proven += 1
        shown = "open" if best is None else f"{best:g}"
        profit = "-" if res.objective is None else f"{res.objective:g}"
        bound = "-" if res.bound is None else f"{res.bound:g}"
        print(f"{path.stem:9} {profit:>7} {bound:>7} {shown:>7} {res.status.name:>11} "
              f"{elapsed:7.2f} {int(res.stats.get('passes', 0)):6d} "
              f"{int(res.stats.get('labels', 0)):9d}", flush=True)
    print(f"proven optimal: {proven} of {known} instances with a known optimum")
    return proven


def main() -> None:
    """Parse the command line and run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("names", nargs="*", help="instance names (default: all with an optimum)")
    ap.add_argument("--limit", type=float, default=60.0, help="seconds per instance")
    ap.add_argument("--open", action="store_true", help="also run the instances still open")
    ap.add_argument("--root", type=Path, default=BENCH, help="benchmark directory")
    args = ap.parse_args()
    started = time.perf_counter()
    warm_up()
    print(f"warm-up (Numba compile or cache load) {time.perf_counter() - started:.2f} s")
    run(args.root, args.limit, set(args.names), args.open)


if __name__ == "__main__":
    main()
