"""``searchtrack optw solve`` and ``searchtrack optw bench``: OPTW instance files solved by any
backend, summarised in a table, optionally written as JSON."""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from searchtrack.cli.common import int_at_least, positive_float
from searchtrack.core.errors import SearchtrackError
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import BACKENDS, OPTWInstance, Routes, read_optw, solve


def result_json(inst: OPTWInstance, result: Result[Routes]) -> dict[str, Any]:
    """The JSON record of one OPTW solve (vertex ids as in the file)."""
    return {
        "instance": inst.name,
        "backend": result.backend,
        "status": result.status.name,
        "objective": _num(result.objective),
        "bound": _num(result.bound),
        "gap": result.gap,
        "runtime_s": round(result.runtime_s, 4),
        "vehicles": inst.vehicles,
        "routes": inst.route_ids(result.plan) if result.plan is not None else [],
        "message": result.message,
    }


def _num(x: float | None) -> float | int | None:
    if x is None:
        return None
    return int(x) if float(x).is_integer() else float(x)


def read_optima(path: Path) -> dict[str, float]:
    """Known optima by instance name from a CSV with columns ``instance`` and ``optimum``."""
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    if rows and not {"instance", "optimum"} <= set(rows[0]):
        raise SearchtrackError(f"{path}: needs columns 'instance' and 'optimum'")
    return {r["instance"]: float(r["optimum"]) for r in rows if r.get("optimum")}


def _find_optima(directory: Path) -> Path | None:
    for d in (directory, *directory.parents[:2]):
        if (d / "optima.csv").is_file():
            return d / "optima.csv"
    return None


def _load(path: Path, args: argparse.Namespace) -> OPTWInstance:
    return read_optw(path, decimals=args.decimals, vehicles=args.vehicles)


def solve_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack optw solve``."""
    inst = _load(Path(args.file), args)
    with console.status(f"solving {inst.name} with {args.backend} ({args.time_limit:g} s)"):
        result = solve(inst, backend=args.backend, time_limit_s=args.time_limit, seed=args.seed)
    record = result_json(inst, result)
    table = Table(title=f"{inst.name}: {inst.n - 1} customers, {inst.vehicles} vehicle(s)",
                  show_header=False)
    for key in ("backend", "status", "objective", "bound", "gap", "runtime_s"):
        value = record[key]
        if key == "gap" and value is not None:
            value = f"{100 * value:.2f} %"
        table.add_row(key, "-" if value is None else str(value))
    for k, route in enumerate(record["routes"]):
        table.add_row(f"route {k}", " → ".join(map(str, route)))
    if result.message:
        table.add_row("message", result.message)
    console.print(table)
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    return 0 if result.status is not Status.ERROR else 1


def bench_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack optw bench``."""
    directory = Path(args.dir)
    if not directory.is_dir():
        raise SearchtrackError(f"{directory}: not a directory")
    files = sorted(p for p in directory.rglob("*.txt") if p.is_file())
    if not files:
        raise SearchtrackError(f"{directory}: no instance files (*.txt)")
    optima_path = Path(args.optima) if args.optima else _find_optima(directory)
    optima = read_optima(optima_path) if optima_path else {}
    records: list[dict[str, Any]] = []
    table = Table(title=f"OPTW bench: {args.backend}, {args.time_limit:g} s, m = {args.vehicles}")
    for col in ("instance", "profit", "optimum", "gap %", "bound", "status", "time s"):
        table.add_column(col, justify="left" if col in ("instance", "status") else "right")
    gaps: list[float] = []
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/"
                  "{task.total}"), TimeElapsedColumn(), console=console, transient=True) as bar:
        task = bar.add_task("solving", total=len(files))
        for path in files:
            bar.update(task, description=f"solving {path.stem}")
            inst = _load(path, args)
            result = solve(inst, backend=args.backend, time_limit_s=args.time_limit,
                           seed=args.seed)
            rec = result_json(inst, result)
            known = optima.get(inst.name) if args.vehicles == 1 else None
            rec["optimum"] = _num(known)
            gap = None
            if known is not None and result.objective is not None:
                gap = 100.0 * (known - result.objective) / max(known, 1e-9)
                gaps.append(gap)
            records.append(rec)
            table.add_row(inst.name, str(rec["objective"]), "-" if known is None else
                          f"{known:g}", "-" if gap is None else f"{gap:.2f}",
                          "-" if rec["bound"] is None else str(rec["bound"]),
                          result.status.name, f"{result.runtime_s:.2f}")
            bar.advance(task)
    console.print(table)
    proven = sum(r["status"] == "OPTIMAL" for r in records)
    if gaps:
        console.print(f"mean gap to known optima: {sum(gaps) / len(gaps):.3f} % "
                      f"over {len(gaps)} instances")
    console.print(f"proven optimal: {proven} of {len(records)}")
    if args.json:
        Path(args.json).write_text(json.dumps(records, indent=2) + "\n", encoding="utf-8")
    return 0 if all(r["status"] != "ERROR" for r in records) else 1


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``optw solve`` and ``optw bench`` on the top-level subparsers."""
    optw = sub.add_parser("optw", help="orienteering with time windows (team OPTW)")
    osub = optw.add_subparsers(dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--backend", default="auto", choices=BACKENDS.names())
    common.add_argument("--time-limit", type=positive_float, default=10.0, metavar="S",
                        help="seconds per instance (default 10)")
    common.add_argument("--vehicles", type=int_at_least(1), default=1, metavar="M",
                        help="number of routes (default 1)")
    common.add_argument("--seed", type=int, default=0)
    common.add_argument("--decimals", type=int, default=None,
                        help="travel-time decimals (default: inferred; 1 Solomon, 2 Cordeau)")
    common.add_argument("--json", metavar="OUT", help="write the result(s) as JSON")
    p_solve = osub.add_parser("solve", parents=[common], help="solve one instance file")
    p_solve.add_argument("file")
    p_solve.set_defaults(run=solve_command)
    p_bench = osub.add_parser("bench", parents=[common], help="solve every *.txt under DIR")
    p_bench.add_argument("dir")
    p_bench.add_argument("--optima", metavar="CSV", help="known optima (default: optima.csv "
                         "in DIR or its parents)")
    p_bench.set_defaults(run=bench_command)
