"""``searchtrack optw solve`` and ``searchtrack optw bench``: OPTW instance files solved by any
backend, summarised in a table, optionally written as JSON."""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from searchtrack.cli import export
from searchtrack.cli.common import add_group, int_at_least, int_in, positive_float, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import output_file
from searchtrack.cli.plan import json_number, result_record
from searchtrack.core.errors import ParseError, SearchtrackError
from searchtrack.core.files import read_text, write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import MAX_SEED
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw import BACKENDS, OPTWInstance, Routes, read_optw, solve
from searchtrack.plan.optw.io import MAX_DECIMALS
from searchtrack.sim.kernels import OPTW_KERNELS


def result_json(inst: OPTWInstance, result: Result[Routes]) -> dict[str, Any]:
    """The JSON record of one OPTW solve (vertex ids as in the file)."""
    return {**result_record(inst.name, result), "vehicles": inst.vehicles,
            "routes": inst.route_ids(result.plan) if result.plan is not None else []}


def read_optima(path: Path) -> dict[str, float]:
    """Known optima by instance name from a CSV with columns ``instance`` and ``optimum``.

    Raises
    ------
    ParseError
        Naming the file (and line): unreadable, not UTF-8, missing columns, a bad number.
    """
    reader = csv.DictReader(io.StringIO(read_text(path, max_bytes=2**20), newline=""))
    try:
        rows = list(reader)
    except csv.Error as exc:
        raise ParseError(path, reader.line_num or None, None, f"not a CSV table ({exc})") from None
    if rows and not {"instance", "optimum"} <= set(rows[0]):
        raise ParseError(path, 1, None, "needs columns 'instance' and 'optimum'")
    optima: dict[str, float] = {}
    for line, row in enumerate(rows, start=2):
        text = row.get("optimum")
        if not text:
            continue
        try:
            value = float(text)
        except ValueError:
            raise ParseError(path, line, "optimum", f"not a number: {text!r}") from None
        if not math.isfinite(value):
            raise ParseError(path, line, "optimum", f"not a finite number: {text!r}")
        optima[row["instance"]] = value
    return optima


def _find_optima(directory: Path) -> Path | None:
    for d in (directory, *directory.parents[:2]):
        if (d / "optima.csv").is_file():
            return d / "optima.csv"
    return None


def _load(path: Path, args: argparse.Namespace) -> OPTWInstance:
    return read_optw(path, decimals=args.decimals, vehicles=args.vehicles)


def exit_status(result: Result[Routes]) -> int:
    """0 with a plan, 130 when interrupted, 1 otherwise (no plan, infeasible, error)."""
    if result.status is Status.INTERRUPTED:
        return 130
    return 0 if result.status.has_plan else 1


def solve_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack optw solve``."""
    json_out = output_file("--json", args.json) if args.json else None
    exports = export.export_dir(args)
    export.require_frame(args, None)   # OPTW instances are in a local frame
    inst = _load(Path(args.file), args)
    ready_kernels(console, OPTW_KERNELS)
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
    if json_out is not None:
        written = write_text_atomic(json_out, json.dumps(record, indent=2) + "\n")
        console.print(f"wrote {written}")
    if exports is not None and result.plan:
        from searchtrack.sim.export.plans import optw_files

        frame = export.geo_frame(args, None, args.altitude)
        export.write_files(exports, optw_files(inst, result.plan, frame, args.speed), console)
    return exit_status(result)


def _error_record(path: Path, reason: str) -> dict[str, Any]:
    return {"instance": path.stem, "file": str(path), "backend": None, "status": "ERROR",
            "objective": None, "bound": None, "gap": None, "runtime_s": 0.0, "routes": [],
            "message": reason}


def bench_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack optw bench``: one row per file, an error row for a file that
    cannot be read or solved (the others go on), the finished rows kept on Ctrl-C."""
    json_out = output_file("--json", args.json) if args.json else None
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
    failed = 0
    ready_kernels(console, OPTW_KERNELS)
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/"
                  "{task.total}"), TimeElapsedColumn(), console=console, transient=True) as bar:
        task = bar.add_task("solving", total=len(files))
        for path in files:
            if stop_requested():
                break
            bar.update(task, description=f"solving {path.stem}")
            try:
                inst = _load(path, args)
                result = solve(inst, backend=args.backend, time_limit_s=args.time_limit,
                               seed=args.seed)
            except SearchtrackError as exc:
                failed += 1
                records.append(_error_record(path, str(exc)))
                table.add_row(path.stem, "-", "-", "-", "-", f"ERROR: {exc}", "-")
                bar.advance(task)
                continue
            rec = result_json(inst, result)
            known = optima.get(inst.name) if args.vehicles == 1 else None
            rec["optimum"] = json_number(known)
            gap = None
            if known is not None and result.objective is not None:
                gap = 100.0 * (known - result.objective) / max(known, 1e-9)
                gaps.append(gap)
            failed += result.status is Status.ERROR
            records.append(rec)
            table.add_row(inst.name, _cell(rec["objective"]), _cell(known),
                          "-" if gap is None else f"{gap:.2f}", _cell(rec["bound"]),
                          result.status.name, f"{result.runtime_s:.2f}")
            bar.advance(task)
    console.print(table)
    proven = sum(r["status"] == "OPTIMAL" for r in records)
    if gaps:
        console.print(f"mean gap to known optima: {sum(gaps) / len(gaps):.3f} % "
                      f"over {len(gaps)} instances")
    console.print(f"proven optimal: {proven} of {len(records)}"
                  + (f"; {failed} failed" if failed else "")
                  + (f"; {len(files) - len(records)} not run (interrupted)"
                     if len(records) < len(files) else ""))
    if json_out is not None:
        written = write_text_atomic(json_out, json.dumps(records, indent=2) + "\n")
        console.print(f"wrote {written}")
    return 1 if failed else 0


def _cell(value: float | int | None) -> str:
    if value is None:
        return "-"
    return f"{value:g}" if isinstance(value, float) else str(value)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``optw solve`` and ``optw bench`` on the top-level subparsers."""
    optw = add_group(sub, "optw")
    osub = optw.add_subparsers(dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--backend", default="auto", choices=BACKENDS.names(),
                        help="backend: %(choices)s (default auto: the heuristic, then the "
                        "exact solver within the time limit)")
    common.add_argument("--time-limit", type=positive_float, default=10.0, metavar="S",
                        help="seconds per instance (default 10)")
    common.add_argument("--vehicles", type=int_at_least(1), default=1, metavar="M",
                        help="number of routes (default 1)")
    common.add_argument("--seed", type=seed_arg, default=0,
                        help=f"random seed, 0 to {MAX_SEED} (default 0)")
    common.add_argument("--decimals", type=int_in(0, MAX_DECIMALS), default=None,
                        help="travel-time decimals, 0 to 6 (default: inferred; 1 Solomon, "
                        "2 Cordeau)")
    common.add_argument("--json", metavar="OUT", help="write the result(s) as JSON")
    p_solve = osub.add_parser("solve", parents=[common], help="solve one instance file")
    p_solve.add_argument("file", metavar="INSTANCE.txt",
                         help="OPTW instance (Solomon / Cordeau format)")
    export.add_arguments(p_solve, unit=True)
    p_solve.set_defaults(run=solve_command)
    p_bench = osub.add_parser("bench", parents=[common], help="solve every *.txt under DIR")
    p_bench.add_argument("dir", metavar="DIR",
                         help="directory searched recursively for instance files")
    p_bench.add_argument("--optima", metavar="CSV", help="known optima (default: optima.csv "
                         "in DIR or its parents)")
    p_bench.set_defaults(run=bench_command)
