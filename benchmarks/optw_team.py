"""Team OPTW benchmark: branch-and-price beside CP-SAT and ILS, with bounds and root gaps.

    python benchmarks/optw_team.py --vehicles 2 3 4 --limit 300 --instances c101 r101 pr01
    python benchmarks/optw_team.py --vehicles 2 --limit 60 --backends bp cpsat ils \\
        --instances c101 c105 r101 r105 rc101 pr01 --csv out/optw_team_dev.csv

Each (instance, m, backend, limit, seed) row is appended to the CSV as soon as it is solved, and
rows already in the CSV are skipped, so a long run can be stopped and resumed. The table printed
at the end is built from every row of the CSV that matches the request. ``gap %`` is
``(bound − profit) / profit``; each plan's routes go to ``<csv>.plans.jsonl`` beside the CSV
(one JSON object per solved row), so new best known values can be checked and listed;
``root gap %`` compares bp's root bound with the best profit any
backend found for that instance and ``m`` (the optimum when some backend proved it); ``vs bk %``
compares the profit with the literature's best known value (``toptw_best_known.csv``, where it
has one), and an OPTIMAL claim below a best known value is printed as a suspected bug. A plan
above a best known value is re-timed with plain floating-point Euclidean travel times (no
truncation, the file's coordinates) and printed as feasible with exact distances, with its least
slack, or as holding only under the library's reading, with the visit that starts late. Every
plan is re-checked by the independent validator (``solve`` does it). Run serially on an idle
machine.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import json
import math
import sys
import time
from pathlib import Path

from threadpoolctl import threadpool_limits

from searchtrack.plan.optw import read_optw, solve
from searchtrack.plan.optw.cpsat import solve_cpsat
from searchtrack.plan.optw.solve import checked, warm_up

ROOT = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"
FIELDS = ["instance", "m", "backend", "limit", "seed", "status", "profit", "bound", "time_s",
          "nodes", "columns", "root_bound", "root_s", "pricing_per_s", "lp_s", "pricing_s",
          "heuristic_s", "message"]


TEAMS = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "toptw"
BEST_KNOWN = Path(__file__).resolve().parent / "toptw_best_known.csv"


def _path(name: str) -> Path:
    for folder in (ROOT / "solomon100", ROOT / "cordeau", TEAMS / "solomon200", TEAMS / "cordeau"):
        p = folder / f"{name}.txt"
        if p.exists():
            return p
    raise SystemExit(f"unknown instance {name!r} (looked in {ROOT} and {TEAMS})")


def best_known() -> dict[tuple[str, str], float]:
    """The literature's best known values by (instance, m) (``toptw_best_known.csv``)."""
    with BEST_KNOWN.open() as fh:
        return {(r["instance"], r["vehicles"]): float(r["best_known"]) for r in csv.DictReader(fh)}


def _key(row: dict[str, str]) -> tuple[str, str, str, str, str]:
    return (row["instance"], row["m"], row["backend"], row["limit"], row["seed"])


def exact_timing(name: str, routes: list[list[int]]) -> str:
    """Whether ``routes`` (file vertex ids) keep every window with exact Euclidean travel
    times: "feasible with exact distances, least slack s" or "… late at vertex v"."""
    inst = read_optw(_path(name))
    if inst.coords is None:
        return "no coordinates"
    xy, ts = inst.coords, float(inst.time_scale)
    service, opening, closing = inst.service / ts, inst.open / ts, inst.close / ts
    least, late = math.inf, None
    for r in routes:
        t = float(opening[r[0]])
        for a, b in itertools.pairwise(r):
            t = max(float(opening[b]), t + float(service[a])
                    + math.hypot(*(xy[a] - xy[b])))
            slack = float(closing[b]) - t
            if slack < least:
                least, late = slack, b
    if least >= 0:
        return f"feasible with exact distances, least slack {least:.3f}"
    return f"holds only under the library's reading: {-least:.3f} late at vertex {late}"


def _num(x: object) -> str:
    return "" if x is None else f"{float(x):g}"  # type: ignore[arg-type]


def _solve(inst, backend: str, limit: float, seed: int):  # type: ignore[no-untyped-def]
    """``solve`` by backend name; ``cpsat1`` is CP-SAT on one worker thread (bp's core count)."""
    if backend == "cpsat1":
        return checked(inst, solve_cpsat(inst, time_limit_s=limit, seed=seed, workers=1))
    return solve(inst, backend=backend, time_limit_s=limit, seed=seed)


def run(args: argparse.Namespace) -> list[dict[str, str]]:
    """Solve every missing row, appending it to the CSV; return the requested rows."""
    path = Path(args.csv)
    path.parent.mkdir(parents=True, exist_ok=True)
    done: dict[tuple[str, str, str, str, str], dict[str, str]] = {}
    if path.exists():
        with path.open() as fh:
            done = {_key(r): r for r in csv.DictReader(fh)}
    new = not path.exists()
    wanted = []
    plans = path.with_suffix(".plans.jsonl")
    with path.open("a", newline="") as fh, plans.open("a") as pfh:
        out = csv.DictWriter(fh, fieldnames=FIELDS)
        if new:
            out.writeheader()
        for name in args.instances:
            inst = read_optw(_path(name))
            for m in args.vehicles:
                for backend in args.backends:
                    key = (name, str(m), backend, f"{args.limit:g}", str(args.seed))
                    wanted.append(key)
                    if key in done:
                        continue
                    res = _solve(inst.with_vehicles(m), backend, args.limit, args.seed)
                    st = res.stats
                    row = dict(zip(FIELDS, [*key, res.status.name, _num(res.objective),
                                            _num(res.bound), f"{res.runtime_s:.2f}",
                                            *(_num(st.get(k)) for k in FIELDS[9:17]),
                                            res.message[:200]], strict=True))
                    out.writerow(row)
                    fh.flush()
                    routes = [list(map(int, r)) for r in res.plan] if res.plan else None
                    pfh.write(json.dumps({"instance": name, "m": m, "backend": backend,
                                          "limit": args.limit, "seed": args.seed,
                                          "status": res.status.name, "profit": res.objective,
                                          "routes": routes}) + "\n")
                    pfh.flush()
                    done[key] = row
                    print(f"{name} m={m} {backend}: {row['status']} {row['profit']} "
                          f"≤ {row['bound']} in {row['time_s']} s", flush=True)
    return [done[k] for k in wanted]


def table(rows: list[dict[str, str]], plans: Path | None = None) -> None:
    """Print the aligned table, with gaps against the best profit found per (instance, m), and
    how each plan above a best known value times with exact distances (its routes from
    ``plans``)."""
    best: dict[tuple[str, str], float] = {}
    for r in rows:
        if r["profit"]:
            k = (r["instance"], r["m"])
            best[k] = max(best.get(k, 0.0), float(r["profit"]))
    bkv = best_known()
    header = ["instance", "m", "backend", "status", "profit", "bound", "gap %", "root bound",
              "root gap %", "time s", "nodes", "columns", "pricing/s", "best known", "vs bk %"]
    body = []
    for r in rows:
        known = bkv.get((r["instance"], r["m"]))
        versus = (f"{100 * (float(r['profit']) - known) / known:+.2f}"
                  if known and r["profit"] else "-")
        if known and r["status"] == "OPTIMAL" and float(r["profit"]) < known - 1e-6:
            print(f"BUG? {r['instance']} m={r['m']} {r['backend']}: OPTIMAL {r['profit']} "
                  f"below the best known {known:g}")
        p = float(r["profit"]) if r["profit"] else None
        gap = (f"{100 * (float(r['bound']) - p) / max(p, 1e-9):.2f}" if p is not None
               and r["bound"] else "-")
        ref = best.get((r["instance"], r["m"]))
        root = r["root_bound"]
        rgap = f"{100 * (float(root) - ref) / max(ref, 1e-9):.2f}" if root and ref else "-"
        body.append([r["instance"], r["m"], r["backend"], r["status"], r["profit"] or "-",
                     r["bound"] or "-", gap, root or "-", rgap, r["time_s"], r["nodes"] or "-",
                     r["columns"] or "-",
                     f"{float(r['pricing_per_s']):.1f}" if r["pricing_per_s"] else "-",
                     f"{known:g}" if known else "-", versus])
    widths = [max(len(h), *(len(b[k]) for b in body)) if body else len(h)
              for k, h in enumerate(header)]
    print("  ".join(h.ljust(w) if k < 3 else h.rjust(w)
                    for k, (h, w) in enumerate(zip(header, widths, strict=True))))
    for b in body:
        print("  ".join(c.ljust(w) if k < 3 else c.rjust(w)
                        for k, (c, w) in enumerate(zip(b, widths, strict=True))))
    for backend in sorted({r["backend"] for r in rows}):
        mine = [r for r in rows if r["backend"] == backend]
        proven = sum(r["status"] == "OPTIMAL" for r in mine)
        gaps = [100 * (bkv[k] - float(r["profit"])) / bkv[k] for r in mine
                if (k := (r["instance"], r["m"])) in bkv and r["profit"]]
        beats = [f"{r['instance']} m={r['m']}" for r in mine
                 if (k := (r["instance"], r["m"])) in bkv and r["profit"]
                 and float(r["profit"]) > bkv[k] + 1e-6]
        roots = [100 * (float(r["root_bound"]) - best[(r["instance"], r["m"])])
                 / best[(r["instance"], r["m"])] for r in mine if r["root_bound"]]
        line = f"{backend}: proven optimal {proven}/{len(mine)}"
        if roots:
            line += f"; mean root gap {sum(roots) / len(roots):.2f} % over {len(roots)}"
        if gaps:
            line += (f"; mean gap to best known {sum(gaps) / len(gaps):.2f} % over {len(gaps)}"
                     f", above it: {', '.join(beats) or 'none'}")
        print(line)
    _above(rows, bkv, plans)


def _above(rows: list[dict[str, str]], bkv: dict[tuple[str, str], float],
           plans: Path | None) -> None:
    """Print each plan above its best known value with its exact-distance timing."""
    if plans is None or not plans.exists():
        return
    routes: dict[tuple[str, str, str, str, str], list[list[int]]] = {}
    with plans.open() as fh:
        for line in fh:
            d = json.loads(line)
            if d["routes"]:
                key = (d["instance"], str(d["m"]), d["backend"], f"{d['limit']:g}",
                       str(d["seed"]))
                routes[key] = d["routes"]
    for r in rows:
        known = bkv.get((r["instance"], r["m"]))
        if known and r["profit"] and float(r["profit"]) > known + 1e-6 and _key(r) in routes:
            print(f"above the best known {known:g}: {r['instance']} m={r['m']} {r['backend']} "
                  f"{r['status']} {r['profit']}, "
                  f"{exact_timing(r['instance'], routes[_key(r)])}")


def main() -> None:
    """Parse the options, warm the kernels up, solve what is missing, print the table."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--instances", nargs="+", default=["c101", "c105", "r101", "r105", "rc101",
                                                      "pr01"])
    p.add_argument("--vehicles", type=int, nargs="+", default=[2])
    p.add_argument("--backends", nargs="+", default=["bp", "cpsat", "ils"],
                   help="bp, cpsat (2 workers), cpsat1 (1 worker, as bp), ils, auto, ...")
    p.add_argument("--limit", type=float, default=60.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--csv", default="out/optw_team.csv")
    args = p.parse_args()
    started = time.perf_counter()
    with threadpool_limits(1):
        for backend in args.backends:
            warm_up(backend)
        rows = run(args)
    print(f"\nteam OPTW, {args.limit:g} s per run, seed {args.seed}")
    table(rows, Path(args.csv).with_suffix(".plans.jsonl"))
    print(f"\ntotal {time.perf_counter() - started:.0f} s")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
