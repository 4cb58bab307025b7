"""``searchtrack track SCANS.json``: run the SMC-PHD filter on recorded 2-D detections.

The file formats are described in :mod:`searchtrack.sim.particles.track_job`.
"""

from __future__ import annotations

import argparse

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from searchtrack.cli.common import add_group, description, int_at_least, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import output_file
from searchtrack.sim.kernels import PHD_KERNELS
from searchtrack.sim.particles.track_job import run_track_file


def track_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack track``."""
    out = output_file("--out", args.out)
    ready_kernels(console, [PHD_KERNELS])
    with Progress(TextColumn("SMC-PHD"), BarColumn(),
                  TextColumn("{task.completed}/{task.total} scans"), TimeElapsedColumn(),
                  console=console, transient=True) as bar:
        task = bar.add_task("filter", total=None)
        summary = run_track_file(args.scans, out, args.particles, args.seed,
                                 lambda done, total: bar.update(task, completed=done,
                                                                total=total))
    console.print(f"{summary.scans} scans, {summary.ms_per_scan:.2f} ms/scan, "
                  f"{summary.mean_estimates:.2f} estimates per scan on average, expected "
                  f"count {summary.final_expected_count:.2f} at the end; wrote {summary.out_path}")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``track`` on the top-level subparsers."""
    p = add_group(sub, "track", description(__doc__))
    p.add_argument("scans", metavar="SCANS.json",
                   help="recorded detections (example: examples/problems/scans.json)")
    p.add_argument("--particles", type=int_at_least(1), default=None, metavar="N",
                   help="cap on the number of particles (default 10000)")
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    p.add_argument("--out", required=True, metavar="EST.json",
                   help="where to write the estimates")
    p.set_defaults(run=track_command)
