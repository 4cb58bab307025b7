"""OPTW benchmark tables: heuristic quality, exact proofs, and the team OPTW beside PyVRP.

    python benchmarks/optw.py ils --limits 1 10 [--pyvrp]   # ILS gap to the 35 proven optima
    python benchmarks/optw.py exact --limit 60               # auto/labelling/cpsat proofs
    python benchmarks/optw.py team --vehicles 2 3 4 --limit 5  # team OPTW vs PyVRP, m vehicles

Every plan is re-checked by the independent validator (``solve`` does it; ERROR rows mean a
rejected plan). Run serially on an idle machine: timings depend on it.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
import time
from pathlib import Path

from threadpoolctl import threadpool_limits

from searchtrack.core.result import Status
from searchtrack.plan.optw import OPTWInstance, read_optw, solve

ROOT = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"


Case = tuple[OPTWInstance, float | None]


def instances(names: list[str] | None, proven_only: bool) -> list[Case]:
    """Benchmark instances (Solomon then Cordeau) with their proven optimum, if any."""
    with (ROOT / "optima.csv").open() as fh:
        optima = {r["instance"]: (float(r["optimum"]) if r["optimum"] else None)
                  for r in csv.DictReader(fh)}
    out = []
    for sub in ("solomon100", "cordeau"):
        for path in sorted((ROOT / sub).glob("*.txt")):
            name = path.stem
            if names and name not in names:
                continue
            if proven_only and optima.get(name) is None:
                continue
            out.append((read_optw(path), optima.get(name)))
    return out


def warm_up() -> None:
    """Compile the numba kernels before anything is timed."""
    inst = read_optw(Path(__file__).resolve().parents[1] / "searchtrack/data/optw/c101.txt")
    for backend in ("ils", "labelling"):
        solve(inst, backend=backend, time_limit_s=0.5)


def _row(cells: list[str], widths: list[int]) -> str:
    return "  ".join(c.rjust(w) if k else c.ljust(w) for k, (c, w) in enumerate(zip(cells, widths,
                                                                                    strict=True)))


def table(header: list[str], rows: list[list[str]]) -> None:
    """Print a plain aligned table."""
    widths = [max(len(h), *(len(r[k]) for r in rows)) if rows else len(h)
              for k, h in enumerate(header)]
    print(_row(header, widths))
    print("  ".join("-" * w for w in widths))
    for r in rows:
        print(_row(r, widths))
    sys.stdout.flush()


def bench_ils(args: argparse.Namespace) -> None:
    """ILS at each time limit: profit, optimum, gap; PyVRP beside it when asked."""
    if args.pyvrp:
        from pyvrp_anchor import solve_pyvrp
    for limit in args.limits:
        rows, gaps, pgaps = [], [], []
        for inst, opt in instances(args.only, proven_only=True):
            assert opt is not None
            res = solve(inst, backend="ils", time_limit_s=limit, seed=args.seed)
            obj = res.objective if res.objective is not None else float("nan")
            gap = 100 * (opt - obj) / opt
            gaps.append(gap)
            row = [inst.name, f"{obj:g}", f"{opt:g}", f"{gap:.2f}", f"{res.runtime_s:.2f}",
                   res.status.name]
            if args.pyvrp:
                pv, _ = solve_pyvrp(inst, limit, args.seed)
                pgaps.append(100 * (opt - pv) / opt)
                row += [f"{pv:g}", f"{pgaps[-1]:.2f}"]
            rows.append(row)
        print(f"\nILS, {limit:g} s per instance, m = 1")
        header = ["instance", "profit", "optimum", "gap %", "time s", "status"]
        table(header + (["pyvrp", "pyvrp gap %"] if args.pyvrp else []), rows)
        print(f"mean gap {statistics.mean(gaps):.3f} %, max {max(gaps):.2f} %, "
              f"optimum reached on {sum(g <= 1e-9 for g in gaps)}/{len(gaps)}"
              + (f"; PyVRP mean gap {statistics.mean(pgaps):.3f} %" if pgaps else ""))


def bench_exact(args: argparse.Namespace) -> None:
    """Exact backend at a time limit: proven optima, bounds, wrong-proof check."""
    rows, proven_solomon, proven_all, wrong = [], 0, 0, 0
    for inst, opt in instances(args.only, proven_only=False):
        res = solve(inst, backend=args.backend, time_limit_s=args.limit, seed=args.seed)
        obj = res.objective
        optimal = res.status is Status.OPTIMAL
        if optimal and opt is not None and obj != opt:
            wrong += 1
        if optimal and opt is not None and obj == opt:
            proven_all += 1
            proven_solomon += not inst.name.startswith("pr")
        rows.append([inst.name, "-" if obj is None else f"{obj:g}",
                     "-" if res.bound is None else f"{res.bound:g}",
                     "open" if opt is None else f"{opt:g}", res.status.name, res.backend,
                     f"{res.runtime_s:.2f}"])
    print(f"\nexact ({args.backend}), {args.limit:g} s per instance, m = 1")
    table(["instance", "profit", "bound", "optimum", "status", "answered by", "time s"], rows)
    print(f"proven optimal and equal to the known optimum: {proven_all} "
          f"({proven_solomon} of 27 Solomon); wrong OPTIMAL claims: {wrong}")


def bench_team(args: argparse.Namespace) -> None:
    """Team OPTW with m vehicles: our backend beside PyVRP at the same time limit."""
    from pyvrp_anchor import solve_pyvrp

    for m in args.vehicles:
        rows, diffs = [], []
        for inst, _ in instances(args.only, proven_only=False):
            team = inst.with_vehicles(m)
            res = solve(team, backend=args.backend, time_limit_s=args.limit, seed=args.seed)
            pv, pt = solve_pyvrp(team, args.limit, args.seed)
            obj = res.objective if res.objective is not None else float("nan")
            diffs.append(100 * (obj - pv) / max(pv, 1e-9))
            rows.append([inst.name, f"{obj:g}", "-" if res.bound is None else f"{res.bound:g}",
                         res.status.name, f"{res.runtime_s:.2f}", f"{pv:g}", f"{pt:.2f}",
                         f"{diffs[-1]:+.2f}"])
        print(f"\nteam OPTW, m = {m}, {args.backend} vs PyVRP, {args.limit:g} s each")
        table(["instance", "profit", "bound", "status", "time s", "pyvrp", "pyvrp s",
               "ours vs pyvrp %"], rows)
        ok = [d for d in diffs if d == d]
        print(f"mean difference {statistics.mean(ok):+.3f} % (positive: we collect more) over "
              f"{len(ok)} instances where PyVRP's plan validated ({len(diffs) - len(ok)} did not); "
              f"better on {sum(d > 0 for d in ok)}, equal {sum(d == 0 for d in ok)}, "
              f"worse {sum(d < 0 for d in ok)}")


def main() -> None:
    """Parse the section and its options, warm up, print the tables."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="section", required=True)
    for name in ("ils", "exact", "team"):
        s = sub.add_parser(name)
        s.add_argument("--only", nargs="*", help="instance names")
        s.add_argument("--seed", type=int, default=0)
        if name == "ils":
            s.add_argument("--limits", type=float, nargs="+", default=[1.0, 10.0])
            s.add_argument("--pyvrp", action="store_true")
        else:
            s.add_argument("--limit", type=float, default=60.0 if name == "exact" else 5.0)
            s.add_argument("--backend", default="auto")
        if name == "team":
            s.add_argument("--vehicles", type=int, nargs="+", default=[2, 3, 4])
    args = p.parse_args()
    sys.path.insert(0, str(Path(__file__).parent))
    started = time.perf_counter()
    with threadpool_limits(1):
        warm_up()
        {"ils": bench_ils, "exact": bench_exact, "team": bench_team}[args.section](args)
    print(f"\ntotal {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
