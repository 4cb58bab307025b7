"""Benchmark the OPTW iterated local search on the instances with proven optima (m = 1).

Usage: ``python benchmarks/optw_ils.py [LIMIT_S ...] [--seed N] [--only NAME,NAME]``
(default limits 1 and 10 s). Every plan is re-checked with the independent validator.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

from searchtrack.core.result import Result
from searchtrack.plan.optw import read_optw, validate
from searchtrack.plan.optw.ils import solve_ils, warm_up
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.validate import Validation

BENCH = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"


def optima(root: Path) -> list[tuple[Path, float]]:
    """(instance file, proven optimum) for every instance of ``optima.csv`` with status proven."""
    rows = []
    with (root / "optima.csv").open(encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            if row["status"] == "proven":
                rows.append((root / row["set"] / f"{row['instance']}.txt", float(row["optimum"])))
    return rows


def solve_checked(inst: OPTWInstance, limit_s: float, seed: int,
                  label: str) -> tuple[Result[Routes], Validation, float]:
    """``solve_ils`` within ``limit_s``, its plan re-checked by the validator (exit on an invalid
    plan or a profit the validator does not confirm): the result, the check and the seconds."""
    started = time.perf_counter()
    res = solve_ils(inst, time_limit_s=limit_s, seed=seed)
    elapsed = time.perf_counter() - started
    assert res.plan is not None and res.objective is not None
    check = validate(inst, res.plan)
    if not check.feasible or abs(check.profit - res.objective) > 1e-6:
        raise SystemExit(f"{label}: invalid plan {check.violations} {check.profit}")
    return res, check, elapsed


def run(limit_s: float, seed: int, only: set[str]) -> float:
    """Solve every instance within ``limit_s`` seconds; print the table and return the mean gap."""
    gaps = []
    print(f"\n== time limit {limit_s:g} s, seed {seed}")
    print(f"{'instance':10} {'profit':>8} {'optimum':>8} {'gap %':>7} {'time s':>7} {'iters':>8}")
    for path, best in optima(BENCH):
        if only and path.stem not in only:
            continue
        res, _, elapsed = solve_checked(read_optw(path), limit_s, seed, path.stem)
        assert res.objective is not None
        gap = 100.0 * (best - res.objective) / best
        gaps.append(gap)
        flag = "" if gap <= 0 else "  *"
        print(f"{path.stem:10} {res.objective:8g} {best:8g} {gap:7.2f} {elapsed:7.2f} "
              f"{int(res.stats.get('iterations', 0)):8d}{flag}", flush=True)
    mean = sum(gaps) / max(1, len(gaps))
    print(f"mean gap {mean:.3f} % over {len(gaps)} instances "
          f"({sum(g > 0 for g in gaps)} not optimal)")
    return mean


def timed_warm_up() -> None:
    """Compile or load the ILS kernels and say how long it took (outside every timed run)."""
    started = time.perf_counter()
    warm_up()
    print(f"warm-up (Numba compile or cache load) {time.perf_counter() - started:.2f} s")


def main() -> None:
    """Parse the command line and run the benchmark for each time limit."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("limits", nargs="*", type=float, default=[1.0, 10.0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", default="", help="comma-separated instance names")
    args = ap.parse_args()
    timed_warm_up()
    only = {s for s in args.only.split(",") if s}
    for limit in args.limits:
        run(limit, args.seed, only)


if __name__ == "__main__":
    main()
