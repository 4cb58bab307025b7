"""Exact OPTW backends on the standard benchmark: profit, proven bound and status per instance.

Usage::

    python benchmarks/optw_cpsat.py                       # 35 instances with a known optimum, 60 s
    python benchmarks/optw_cpsat.py --set solomon100 --time-limit 20
    python benchmarks/optw_cpsat.py --instances c101,r101 --vehicles 3
    python benchmarks/optw_cpsat.py --backend mip --instances c101

The optima in ``optima.csv`` (Righini and Salani 2009) are for one vehicle; with ``--vehicles``
> 1 the column shows the single-vehicle optimum only as a lower bound on the team optimum.
Every returned plan is re-checked with the independent validator.
"""

from __future__ import annotations

import argparse
import csv
import logging
import sys
import time
from dataclasses import replace
from pathlib import Path

from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import Routes, read_optw, validate
from searchtrack.plan.optw.cpsat import Formulation, solve_cpsat
from searchtrack.plan.optw.ils import solve_ils, warm_up
from searchtrack.plan.optw.mip import solve_mip

DEFAULT_DATA = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"


def _optima(data: Path) -> dict[str, tuple[str, float | None]]:
    """Instance name → (set, optimum or None when still open)."""
    out: dict[str, tuple[str, float | None]] = {}
    with (data / "optima.csv").open(encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            value = row["optimum"].strip()
            out[row["instance"]] = (row["set"], float(value) if value else None)
    return out


def _formulation(toggle: str) -> Formulation:
    """The default formulation with ``name`` (a boolean) flipped or ``name=value`` set."""
    base = Formulation()
    changes: dict[str, object] = {}
    for item in filter(None, (t.strip() for t in toggle.split(","))):
        name, _, value = item.partition("=")
        default = getattr(base, name)
        changes[name] = (not default) if not value else type(default)(value)
    return replace(base, **changes)  # type: ignore[arg-type]


def _fmt(x: float | None) -> str:
    return "-" if x is None else f"{x:g}"


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print one table row per instance, then a summary."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="benchmark folder")
    ap.add_argument("--time-limit", type=float, default=60.0, help="seconds per instance")
    ap.add_argument("--instances", default="", help="comma-separated names (default: all proven)")
    ap.add_argument("--set", choices=["solomon100", "cordeau", "all"], default="all")
    ap.add_argument("--vehicles", type=int, default=1, help="team size m")
    ap.add_argument("--backend", choices=["cpsat", "mip"], default="cpsat")
    ap.add_argument("--workers", type=int, default=2, help="CP-SAT worker threads")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--include-open", action="store_true", help="also run the open instances")
    ap.add_argument("--toggle", default="",
                    help="CP-SAT Formulation fields to change: a name flips a switch, name=value "
                         "sets it, e.g. 'intervals,probing_level=0' (to measure each change)")
    ap.add_argument("--warm-start", type=float, default=0.0, metavar="S",
                    help="first run the ILS for S seconds (inside the limit) and pass its plan "
                         "as the initial solution, as the auto backend does")
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)

    optima = _optima(args.data)
    form = _formulation(args.toggle)
    if args.warm_start > 0:
        warm_up()  # compile the ILS kernels outside the timed runs
    if args.instances:
        names = [n.strip() for n in args.instances.split(",") if n.strip()]
    else:
        names = [n for n, (s, opt) in optima.items()
                 if (args.set in ("all", s)) and (opt is not None or args.include_open)]
    header = (f"{'instance':9} {'m':>2} {'profit':>8} {'bound':>8} {'optimum':>8} "
              f"{'status':11} {'time_s':>7}  note")
    print(f"backend={args.backend} time_limit_s={args.time_limit:g} vehicles={args.vehicles} "
          f"workers={args.workers} seed={args.seed} warm_start_s={args.warm_start:g}")
    if args.backend == "cpsat":
        print(f"formulation: {form}")
    print(header)
    print("-" * len(header))
    n_optimal = n_hit = n_known = 0
    for name in names:
        set_name, optimum = optima.get(name, ("solomon100", None))
        path = args.data / set_name / f"{name}.txt"
        inst = read_optw(path, vehicles=args.vehicles)
        res: Result[Routes]
        started = time.perf_counter()
        initial: Routes | None = None
        if args.warm_start > 0:
            initial = solve_ils(inst, time_limit_s=args.warm_start, seed=args.seed).plan
        left = max(1e-3, args.time_limit - (time.perf_counter() - started))
        if args.backend == "cpsat":
            res = solve_cpsat(inst, time_limit_s=left, seed=args.seed, workers=args.workers,
                              initial=initial, formulation=form)
        else:
            res = solve_mip(inst, time_limit_s=left, seed=args.seed, initial=initial)
        elapsed = time.perf_counter() - started
        notes: list[str] = []
        if res.plan is not None:
            check = validate(inst, res.plan)
            if not check.feasible:
                notes.append(f"INVALID PLAN: {check.violations[0]}")
            elif abs(check.profit - (res.objective or 0.0)) > 1e-6:
                notes.append(f"PROFIT MISMATCH (validator {check.profit:g})")
        if optimum is not None and args.vehicles == 1:
            n_known += 1
            if res.bound is not None and res.bound < optimum - 1e-6:
                notes.append("BOUND BELOW OPTIMUM")
            if res.objective is not None and res.objective > optimum + 1e-6:
                notes.append("PROFIT ABOVE OPTIMUM")
            if res.objective is not None and abs(res.objective - optimum) < 1e-6:
                n_hit += 1
        n_optimal += res.status is Status.OPTIMAL
        shown_opt = optimum if args.vehicles == 1 else None
        print(f"{name:9} {args.vehicles:>2} {_fmt(res.objective):>8} {_fmt(res.bound):>8} "
              f"{_fmt(shown_opt):>8} {res.status.name:11} {elapsed:7.1f}  "
              f"{'; '.join(notes)}", flush=True)
    print("-" * len(header))
    summary = f"OPTIMAL {n_optimal}/{len(names)}"
    if n_known:
        summary += f"; known optimum reached {n_hit}/{n_known}"
    print(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
