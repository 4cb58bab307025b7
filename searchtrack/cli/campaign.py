"""``searchtrack campaign``: run a Monte Carlo campaign into a DuckDB results database, show
its status, export its rows, report it (tables beside the papers' claims, figures)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeRemainingColumn
from rich.table import Table

from searchtrack.cli.common import add_group, int_at_least
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import OutputError, output_dir, output_file
from searchtrack.sim.kernels import warm_up_sets

if TYPE_CHECKING:
    from searchtrack.sim.campaigns.runner import Tally
    from searchtrack.sim.campaigns.store import StoreError

# The campaign modules (Dask, DuckDB, SciPy's statistics) are imported by the handlers that use
# them, so that every other command starts without them.


def _db_error(exc: StoreError) -> OutputError:
    return OutputError("--db", exc.path, exc.reason)


def run(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack campaign run``."""
    if not args.verbose:  # Dask logs every worker start and stop at INFO
        import distributed  # noqa: F401  (it sets its loggers' levels on import)

        logging.getLogger("distributed").setLevel(logging.WARNING)
    from searchtrack.sim.campaigns.runner import run_campaign
    from searchtrack.sim.campaigns.spec import read_spec
    from searchtrack.sim.campaigns.store import StoreError

    spec = read_spec(args.file)
    db = output_file("--db", args.db if args.db is not None
                     else Path(args.file).with_suffix(".duckdb"))
    ready_kernels(console, warm_up_sets())  # once, before the workers start
    with Progress(TextColumn("{task.description}"), BarColumn(),
                  TextColumn("{task.completed}/{task.total} done · {task.fields[failed]} failed"
                             " · {task.fields[running]} running"), TimeRemainingColumn(),
                  console=console, transient=True) as bar:
        task: TaskID | None = None

        def show(t: Tally) -> None:
            nonlocal task
            if task is None:
                task = bar.add_task(spec.name, total=t.total, failed=0, running=0)
            bar.update(task, completed=t.done + t.failed, failed=t.failed, running=t.running)

        def cluster(dashboard: str | None) -> None:
            if dashboard is not None:
                console.print(f"Dask dashboard: {dashboard}")

        try:
            summary = run_campaign(spec, db, workers=args.workers, scheduler=args.scheduler,
                                   retry_failed=args.retry_failed, progress=show,
                                   on_cluster=cluster)
        except StoreError as exc:
            raise _db_error(exc) from None
    console.print(f"{spec.name}: {summary.total} runs, {summary.skipped} already recorded, "
                  f"{summary.ok} ok, {summary.failed} failed, {summary.not_run} not run, in "
                  f"{summary.wall_s:.1f} s; results in {db}")
    return 1 if summary.failed_recorded else 0


def status(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack campaign status`` (of a campaign running now, too)."""
    from searchtrack.sim.campaigns.store import StoreBusy, describe, missing_runs

    try:
        name, experiment, counts = describe(args.db)
        missing = missing_runs(args.db)
    except StoreBusy as busy:
        if busy.progress is None:
            raise
        return _running(args.db, busy.progress, console)
    table = Table(title=f"{name} ({experiment}): {args.db}")
    table.add_column("status")
    table.add_column("runs", justify="right")
    for key in sorted(counts):
        table.add_row(key, str(counts[key]))
    table.add_row("recorded", str(sum(counts.values())))
    if missing is not None:
        table.add_row("not run yet", str(missing))
        table.add_row("planned", str(sum(counts.values()) + missing))
    console.print(table)
    if missing:
        console.print(f"{missing} planned runs are missing: `searchtrack campaign run FILE "
                      f"--db {args.db}` runs them")
    return 1 if counts.get("error", 0) else 0


def _running(db: Path, progress: dict[str, Any], console: Console) -> int:
    """The status of a campaign still running, from its progress report."""
    table = Table(title=f"{progress.get('campaign')} ({progress.get('experiment')}): {db}, "
                        f"running (PID {progress['pid']}), as of {progress.get('updated_utc')} "
                        "UTC")
    table.add_column("this run")
    table.add_column("runs", justify="right")
    for label, key in (("ok", "done"), ("error", "failed"), ("running", "running"),
                       ("runs this time", "total")):
        table.add_row(label, str(progress.get(key, "?")))
    console.print(table)
    return 0


def export(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack campaign export``."""
    from searchtrack.sim.campaigns.store import EXPORTS, open_existing

    out = output_file("OUT", args.out)
    if out.suffix.lower() not in EXPORTS:
        raise OutputError("OUT", out, f"must end in one of {sorted(EXPORTS)}")
    with open_existing(args.db) as store:
        store.export(out)
        rows = sum(store.counts().values())
    console.print(f"wrote {rows} runs to {out}")
    return 0


def report(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack campaign report``: mean ± 95 % CI by group beside the paper's
    claim, and one figure per metric with ``--out``."""
    from searchtrack.sim.campaigns.report import build_report, table_rows, write_figures
    from searchtrack.sim.campaigns.series import write_series_figures
    from searchtrack.sim.campaigns.store import open_existing

    folder = output_dir("--out", args.out) if args.out is not None else None
    with open_existing(args.db) as store:
        rows = store.rows()
        missing = store.missing()
        definition = store.experiment
        name = store.campaign
        metrics = store.metrics
    result = build_report(name, definition, list(metrics), rows, missing)
    table = Table(title=f"{name} ({definition.name}): mean ± 95 % CI over seeds")
    cells = table_rows(list(result.groups), list(result.metrics))
    for col in cells[0]:
        table.add_column(col, justify="left" if col in result.group_keys else "right")
    for row in cells[1:]:
        table.add_row(*row)
    console.print(table)
    if result.claim:
        console.print(f"claim: {result.claim}")
    if missing:
        partial = sum(1 for g in result.groups if g.missing)
        console.print(f"partial: {len(missing)} planned runs are missing, in {partial} of "
                      f"{len(result.groups)} cells (marked 'of' in the runs column)")
    if folder is not None:
        written = write_figures(result, folder) + write_series_figures(
            name, definition, result.group_keys, rows, list(metrics), folder)
        console.print("wrote " + (", ".join(str(p) for p in written) or "no figure (nothing "
                                  "varies)"))
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``campaign run|status|export|report`` on the top-level subparsers."""
    campaign = add_group(sub, "campaign")
    csub = campaign.add_subparsers(dest="command", required=True)
    p_run = csub.add_parser("run", help="run (or resume) a TOML campaign")
    p_run.add_argument("file", help="campaign TOML file")
    p_run.add_argument("--db", default=None, metavar="PATH",
                       help="results database (default: FILE with suffix .duckdb)")
    p_run.add_argument("--scheduler", default=None, metavar="ADDR",
                       help="address of an existing Dask scheduler (default: a local cluster)")
    p_run.add_argument("--workers", type=int_at_least(0), default=None, metavar="N",
                       help="local worker processes (default: one per core; 0: in-process)")
    p_run.add_argument("--retry-failed", action="store_true",
                       help="run again the runs recorded as failed")
    p_run.set_defaults(run=run)
    p_status = csub.add_parser("status", help="count the runs of a results database")
    p_status.add_argument("db", help="results database")
    p_status.set_defaults(run=status)
    p_export = csub.add_parser("export", help="write the runs to .parquet or .csv")
    p_export.add_argument("db", help="results database")
    p_export.add_argument("out", metavar="OUT", help="output file (.parquet or .csv)")
    p_export.set_defaults(run=export)
    p_report = csub.add_parser("report", help="mean ± 95 %% CI by group, the paper's claim, "
                               "figures")
    p_report.add_argument("db", help="results database")
    p_report.add_argument("--out", default=None, metavar="DIR",
                          help="write one PNG per metric into DIR")
    p_report.set_defaults(run=report)
