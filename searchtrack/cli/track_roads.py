"""``searchtrack track-roads DETECTIONS.json``: the Rao-Blackwellized road filter (Moore et al.
2021) on recorded UAV detections of targets on roads.

The file formats are described in :mod:`searchtrack.sim.road_particles.track_job`.
"""

from __future__ import annotations

import argparse

from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from searchtrack.cli.common import add_group, description, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import output_file
from searchtrack.sim.kernels import ROAD_FILTER_KERNELS
from searchtrack.sim.road_particles.track_job import (
    read_road_job,
    run_road_track_job,
    write_road_estimates,
)


def track_roads_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack track-roads``."""
    out = output_file("--out", args.out)
    job = read_road_job(args.detections)
    seed = job.seed if args.seed is None else args.seed
    ready_kernels(console, (ROAD_FILTER_KERNELS,))
    with Progress(TextColumn("{task.description}"), BarColumn(),
                  TextColumn("{task.completed}/{task.total} steps"), TimeElapsedColumn(),
                  console=console, transient=True) as bar:
        task = bar.add_task("filtering", total=job.n_steps)
        result = run_road_track_job(job, seed,
                                    lambda done, _total: bar.update(task, completed=done))
    written = write_road_estimates(result, out)
    final = (f", combined entropy {result.combined_entropy[-1]:.2f} nats at the end"
             if result.steps else "")
    console.print(escape(
        f"{result.steps} of {job.n_steps} steps ({job.n_scans} scans, {job.n_detections} "
        f"detections) on {job.map_label}, {job.config.n_targets} targets, "
        f"{job.config.n_histories}×{job.config.n_particles} particles per target, "
        f"{result.ms_per_step:.2f} ms/step{final}; wrote {written}"))
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``track-roads`` on the top-level subparsers."""
    p = add_group(sub, "track-roads", description(__doc__))
    p.add_argument("detections", metavar="DETECTIONS.json",
                   help="recorded road detections (examples/make_road_detections.py writes one)")
    p.add_argument("--out", required=True, metavar="EST.json",
                   help="where to write the estimates")
    p.add_argument("--seed", type=seed_arg, default=None,
                   help="random seed (default: the file's seed, else 0)")
    p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                   help="log the filter's progress")
    p.set_defaults(run=track_roads_command)
