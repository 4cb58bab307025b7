"""``searchtrack warm-up``: compile the numba kernels ahead of use, and the one-line notice the
other commands print when a solve must compile them first (:func:`ready_kernels`)."""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Iterable

from rich.console import Console
from rich.table import Table

from searchtrack.cli.common import add_group
from searchtrack.sim.kernels import KERNEL_SETS, cold_sets, warm, warm_up_sets

NOTICE = "compiling solver kernels, once per install"
"""What a command says before it compiles kernels that numba has not cached yet."""


def ready_kernels(console: Console, names: Iterable[str]) -> dict[str, float]:
    """Compile the kernel sets ``names`` that are not in numba's cache yet, saying so first
    (once per install: later processes load the machine code from disk). Seconds per set."""
    cold = cold_sets(names)
    if not cold:
        return {}
    what = ", ".join(ks.description for ks in cold)
    console.print(f"{NOTICE} ({what}; about 30 s at most, then cached on disk)")
    with console.status(NOTICE):
        return warm(cold)


def warm_up_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack warm-up``."""
    names = args.only or list(warm_up_sets())
    unknown = [n for n in names if n not in KERNEL_SETS]
    if unknown:
        raise ValueError(f"--only {unknown[0]!r}: unknown kernel set; choose from "
                         + ", ".join(KERNEL_SETS))
    if args.jobs is not None and args.jobs < 1:
        raise ValueError(f"--jobs {args.jobs}: must be at least 1")
    table = Table(title="numba kernels")
    for column in ("set", "computes", "was", "seconds"):
        table.add_column(column, justify="right" if column == "seconds" else "left")
    started = time.perf_counter()
    cold = [ks.name for ks in cold_sets(names)]
    jobs = args.jobs if args.jobs is not None else (os.cpu_count() or 1)
    with console.status(f"{NOTICE}: {len(cold)} sets on {min(jobs, len(cold))} processes"
                        if cold else "loading the cached kernels"):
        took = warm([KERNEL_SETS[n] for n in cold], jobs=jobs)
        took |= warm([KERNEL_SETS[n] for n in names if n not in took])
    for name in names:
        table.add_row(name, KERNEL_SETS[name].description,
                      "cold" if name in cold else "cached", f"{took[name]:.1f}")
    console.print(table)
    console.print(f"kernels ready in {time.perf_counter() - started:.1f} s")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``warm-up`` on the top-level subparsers."""
    p = add_group(sub, "warm-up", "Compile every numba kernel set into numba's on-disk cache, so "
                  "that the first solve starts at once (make runs it at install).")
    p.add_argument("--only", nargs="+", metavar="SET",
                   help="kernel sets to compile: " + ", ".join(KERNEL_SETS) + " (default all)")
    p.add_argument("--jobs", type=int, metavar="N",
                   help="processes compiling at once (default: one per core)")
    p.set_defaults(run=warm_up_command)
