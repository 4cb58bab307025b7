"""``searchtrack plan FAMILY PROBLEM.json --out PLAN.json``: one planning problem read from JSON,
solved by a backend of its family, summarised in a table and written as PLAN.json.

Families are the modules of :mod:`searchtrack.sim.jobs` (each a
:class:`~searchtrack.sim.jobs.PlanJob`); their formats are in each module's docstring. PLAN.json has
the top-level fields of ``searchtrack optw solve --json`` (``instance``, ``backend``, ``status``,
``objective``, ``bound``, ``gap``, ``runtime_s``, ``message``) plus ``family`` and the family's
``plan`` object (``null`` without a plan).
"""

from __future__ import annotations

import argparse
import functools
import json
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from searchtrack.cli import export
from searchtrack.cli.common import add_group, description, positive_float, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import output_file
from searchtrack.core.errors import SearchtrackError
from searchtrack.core.files import write_text_atomic
from searchtrack.core.registry import MAX_SEED, Registry
from searchtrack.core.result import Result, Status
from searchtrack.sim import jobs

#: The rows of the result table, as ``optw solve`` prints them.
SUMMARY_KEYS = ("backend", "status", "objective", "bound", "gap", "runtime_s")


def available_families() -> list[str]:
    """The families: the modules of :mod:`searchtrack.sim.jobs`."""
    return jobs.families()


@functools.cache
def family_module(name: str) -> jobs.PlanJob:
    """The module of family ``name``, imported on first use (the families load only when the
    ``plan`` command is built: other commands start without the solvers behind them)."""
    return jobs.load(name)


@functools.cache
def _help() -> dict[str, str]:
    return {name: family_module(name).DESCRIPTION for name in available_families()}


@functools.cache
def _backend_names() -> dict[str, tuple[str, ...]]:
    return {name: tuple(family_module(name).backends()) for name in available_families()}


def __getattr__(name: str) -> Any:
    """``HELP`` (each family's one-line ``DESCRIPTION``) and ``BACKEND_NAMES`` (each family's
    ``backends()``, ``"auto"`` first), built from the family modules on first use."""
    if name == "HELP":
        return _help()
    if name == "BACKEND_NAMES":
        return _backend_names()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def backend_help(name: str) -> str:
    """The ``--backend`` help of family ``name``: its backend names, then what each registered
    backend does (its registry's ``description``)."""
    registry: Registry[Any, Any] = family_module(name).BACKENDS
    names = _backend_names()[name]
    described = "; ".join(f"{b}: {registry.get(b).description}" for b in names
                          if b in registry.names())
    text = "backend: " + ", ".join(names) + " (default auto)"
    return (text + (f". {described}" if described else "")).replace("%", "%%")


def json_number(x: float | None) -> float | int | None:
    """``x`` for JSON: an integer when it is whole, ``None`` kept."""
    if x is None:
        return None
    return int(x) if float(x).is_integer() else float(x)


def result_record(instance: str, result: Result[Any]) -> dict[str, Any]:
    """The top-level fields PLAN.json shares with ``optw solve --json``."""
    return {
        "instance": instance,
        "backend": result.backend,
        "status": result.status.name,
        "objective": json_number(result.objective),
        "bound": json_number(result.bound),
        "gap": result.gap,
        "runtime_s": round(result.runtime_s, 4),
        "message": result.message,
        **({"stats": {k: json_number(v) for k, v in sorted(result.stats.items())}}
           if result.stats else {}),
    }


def result_table(title: str, record: dict[str, Any]) -> Table:
    """The two-column summary ``optw solve`` prints: backend, status, objective, bound, gap (in
    per cent), runtime, and the message when there is one."""
    table = Table(title=title, show_header=False)
    for key in SUMMARY_KEYS:
        value = record[key]
        if key == "gap" and value is not None:
            value = f"{100 * value:.2f} %"
        elif key in ("objective", "bound") and isinstance(value, float):
            value = f"{value:.6g}"  # the record keeps every digit
        table.add_row(key, "-" if value is None else str(value))
    if record.get("message"):
        table.add_row("message", str(record["message"]))
    error = record.get("stats", {}).get("objective_error")
    if error is not None:
        table.add_row("objective ±", f"{error:.2g}")
    return table


def exit_status(result: Result[Any]) -> int:
    """0 with a plan, 130 when interrupted, 1 otherwise (no plan, infeasible, error)."""
    if result.status is Status.INTERRUPTED:
        return 130
    return 0 if result.status.has_plan else 1


def plan_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack plan FAMILY``."""
    out = output_file("--out", args.out)
    fig_out = output_file("--figure", args.figure) if args.figure else None
    exports = export.export_dir(args)
    module = family_module(args.family)
    names = _backend_names()[args.family]
    if args.backend not in names:
        raise SearchtrackError(f"--backend {args.backend!r}: unknown {args.family} backend; "
                               f"choose one of {list(names)}")
    problem = module.read_problem(Path(args.problem))
    projection = jobs.geo_projection(module, problem)
    export.require_frame(args, projection)   # read, not solved
    ready_kernels(console, module.KERNELS)
    with console.status(f"solving {args.family} problem {Path(args.problem).name} with "
                        f"{args.backend} ({args.time_limit:g} s)"):
        result: Result[Any] = module.solve(problem, backend=args.backend,
                                           time_limit_s=args.time_limit, seed=args.seed)
    record = {"family": args.family, **result_record(Path(args.problem).stem, result)}
    record["plan"] = module.plan_json(problem, result) if result.plan is not None else None
    console.print(result_table(f"{args.family}: {Path(args.problem).name}", record))
    write_text_atomic(out, json.dumps(record, indent=2) + "\n")
    console.print(f"wrote {out}")
    if fig_out is not None:
        drawn = module.figure(problem, result, fig_out) if result.plan is not None else None
        console.print(f"wrote {drawn}" if drawn is not None
                      else "no figure: nothing to draw for this result")
    if exports is not None and result.plan is not None:
        from searchtrack.sim.export.plans import path_files

        paths = module.vehicle_paths(problem, result)
        if not paths.paths:
            console.print(f"nothing to export: the {args.family} plan moves no vehicle")
        else:
            frame = export.geo_frame(args, projection, args.altitude)
            export.write_files(exports, path_files(paths, frame, args.speed), console)
    return exit_status(result)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``plan FAMILY`` on the top-level subparsers (one subcommand per family)."""
    plan = add_group(sub, "plan", description(__doc__))
    psub = plan.add_subparsers(dest="family", required=True)
    for name in available_families():
        p = psub.add_parser(name, help=_help()[name],
                            description=f"{name}: {_help()[name]} (format: module "
                            f"searchtrack.sim.jobs.{name})")
        p.add_argument("problem", metavar="PROBLEM.json",
                       help=f"the problem (example: examples/problems/{name}.json)")
        p.add_argument("--out", required=True, metavar="PLAN.json", help="where to write the plan")
        p.add_argument("--backend", default="auto", help=backend_help(name))
        p.add_argument("--time-limit", type=positive_float, default=10.0, metavar="S",
                       help="seconds (default 10)")
        p.add_argument("--seed", type=seed_arg, default=0,
                       help=f"random seed, 0 to {MAX_SEED} (default 0)")
        p.add_argument("--figure", metavar="PLAN.png", help="also draw the plan as a PNG")
        export.add_arguments(p, speed=True)
        p.set_defaults(run=plan_command)
