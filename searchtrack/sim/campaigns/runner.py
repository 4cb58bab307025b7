"""Run a campaign: every run not yet in the results database, on Dask distributed or in-process.

The client keeps a bounded window of runs submitted (``client.submit(run_one, ...)``), in the
order :class:`~searchtrack.sim.campaigns.schedule.LongestFirst` learns (slowest cells first), takes
them as they complete and inserts each row at once, so a crash or a stop loses at most the runs
in flight. A run that raises becomes a row with status ``error`` and its message (caught inside
:func:`run_one`, on the worker); a worker that dies is replaced by its nanny and the scheduler
reruns its tasks, and the primary key keeps one row per run. A stop request
(:func:`~searchtrack.core.interrupt.stop_requested`) stops submitting and cancels what is
pending; the rows written stay, so running the campaign again resumes.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import socket
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from threadpoolctl import threadpool_limits

import searchtrack
from searchtrack.core import checks
from searchtrack.core.interrupt import stop_requested
from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.campaigns.schedule import LongestFirst
from searchtrack.sim.campaigns.spec import CampaignSpec, RunSpec
from searchtrack.sim.campaigns.store import (
    ResultStore,
    clear_progress,
    utc_naive,
    write_progress,
)

log = logging.getLogger("searchtrack.sim.campaigns.runner")

#: Environment of LocalCluster workers: one BLAS / OpenMP thread each.
ONE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                  "NUMBA_NUM_THREADS": "1"}

_POLL_S = 0.05


def run_one(run: RunSpec) -> dict[str, Any]:
    """Run ``run`` (BLAS pinned to one thread) and return its row: metrics, or status
    ``error`` with the exception's message; with host, version, start, end and runtime."""
    started = datetime.now(UTC)
    t0 = time.perf_counter()
    row = _identity(run)
    try:
        experiment = get(run.experiment)
        with threadpool_limits(limits=1):
            metrics = experiment.run(run.params, run.seed)
        unknown = sorted(set(metrics) - set(experiment.metrics))
        if unknown:
            raise ValueError(f"returned metrics {unknown} it does not declare")
        row.update(metrics, status="ok", error=None)
    except Exception as exc:
        log.warning("run %s (seed %d) failed: %s", run.key[:12], run.seed, exc)
        row.update(status="error", error=f"{type(exc).__name__}: {exc}")
    row.update(runtime_s=time.perf_counter() - t0, host=socket.gethostname(),
               started_utc=utc_naive(started), ended_utc=utc_naive(datetime.now(UTC)))
    return row


def _identity(run: RunSpec) -> dict[str, Any]:
    """The columns that name a run: key, experiment, parameters, seed, package version."""
    return {"key": run.key, "experiment": run.experiment, **run.params, "seed": run.seed,
            "version": searchtrack.__version__}


@dataclass(frozen=True)
class Tally:
    """Progress of a campaign: runs recorded ok / failed this time, in flight, and to do."""

    done: int
    failed: int
    running: int
    total: int


@dataclass(frozen=True)
class CampaignSummary:
    """What :func:`run_campaign` did.

    Parameters
    ----------
    total
        Runs in the campaign.
    skipped
        Already in the database (not run again).
    ok, failed
        Runs recorded this time, by status.
    not_run
        Runs left for a later resume (after a stop).
    wall_s, run_s
        Wall time, and the sum of the runs' own runtimes.
    slots
        Runs executed at once (worker threads; 1 in-process).
    startup_s
        Time to start (or connect to) the cluster, within ``wall_s``.
    dashboard
        The Dask dashboard address of the embedded cluster, if any.
    failed_recorded
        Runs with status ``error`` in the database when the campaign stopped (this time's and
        earlier ones not retried).
    """

    total: int
    skipped: int
    ok: int
    failed: int
    not_run: int
    wall_s: float
    run_s: float
    slots: int
    startup_s: float = 0.0
    dashboard: str | None = None
    failed_recorded: int = 0

    @property
    def interrupted(self) -> bool:
        """Whether runs were left (a stop was requested)."""
        return self.not_run > 0


Progress = Callable[[Tally], None]
"""Called after every recorded run (and once before the first)."""


@dataclass
class _Count:
    ok: int = 0
    failed: int = 0
    run_s: float = 0.0

    def add(self, store: ResultStore, row: dict[str, Any]) -> None:
        store.insert(row)
        if row["status"] == "ok":
            self.ok += 1
        else:
            self.failed += 1
        self.run_s += float(row["runtime_s"])


def _serial(todo: list[RunSpec], store: ResultStore, count: _Count, total: int,
            progress: Progress | None) -> int:
    """Run in this process, one after the other; returns the runs left on a stop."""
    for i, run in enumerate(todo):
        if stop_requested():
            return len(todo) - i
        count.add(store, run_one(run))
        if progress is not None:
            progress(Tally(count.ok, count.failed, 0, total))
    return 0


@contextmanager
def _client(workers: int | None, scheduler: str | None) -> Iterator[Any]:
    """A Dask client of ``scheduler``, or of an embedded LocalCluster with ``workers``
    single-threaded processes (one per core when ``None``)."""
    import dask
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        with Client(scheduler) as client:  # type: ignore[no-untyped-call]
            yield client
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    # The workers' statistical profiler samples every task's stack every 10 ms: on a busy
    # machine it costs runs a tenth of their speed, and a campaign does not read it.
    with dask.config.set({"distributed.worker.profile.enabled": False}), \
            LocalCluster(n_workers=0, threads_per_worker=1, processes=True,  # type: ignore[no-untyped-call]
                      dashboard_address=":0", env=ONE_THREAD_ENV,
                      # the workers' warnings on a stop (tasks cancelled, comms closed) are
                      # noise on the terminal; their errors are still shown
                      silence_logs=logging.ERROR,
                      preload=["searchtrack.sim.campaigns.worker_setup"]) as cluster, \
            Client(cluster) as client:  # type: ignore[no-untyped-call]
        # the workers start in the background, so that Ctrl-C while they start stops at once
        cluster.scale(n)  # type: ignore[no-untyped-call]
        while len(client.scheduler_info()["workers"]) < n and not stop_requested():
            time.sleep(_POLL_S)
        yield client


def _error_row(run: RunSpec, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose task failed outside :func:`run_one` (e.g. its workers kept
    dying)."""
    now = utc_naive(datetime.now(UTC))
    return {**_identity(run), "status": "error", "error": f"{type(exc).__name__}: {exc}",
            "runtime_s": 0.0, "host": None, "started_utc": now, "ended_utc": now}


def _distributed(client: Any, todo: list[RunSpec], store: ResultStore, count: _Count,
                 total: int, progress: Progress | None) -> tuple[int, int]:
    """Run on ``client``'s cluster; returns (runs left on a stop, slots)."""
    from dask.distributed import as_completed

    slots = max(1, sum(w.get("nthreads", 1) for w in
                       client.scheduler_info()["workers"].values()))
    window = max(4, 2 * slots)
    queue = LongestFirst(todo)
    pending: dict[Any, RunSpec] = {}
    ready = as_completed()  # type: ignore[no-untyped-call]

    def submit() -> None:
        while queue and len(pending) < window and not stop_requested():
            run = queue.pop()
            future = client.submit(run_one, run, pure=False, key=f"run-{run.key}")
            pending[future] = run
            ready.add(future)  # type: ignore[no-untyped-call]

    submit()
    while pending:
        if stop_requested():
            client.cancel(list(pending))
            log.info("stop requested: cancelled %d runs in flight", len(pending))
            return len(queue) + len(pending), slots
        batch = ready.next_batch(block=False)  # type: ignore[no-untyped-call]
        if not batch:
            time.sleep(_POLL_S)
            continue
        for future in batch:
            run = pending.pop(future)
            try:
                row = future.result()
            except Exception as exc:
                log.warning("run %s lost: %s", run.key[:12], exc)
                row = _error_row(run, exc)
            queue.record(run, float(row["runtime_s"]))
            count.add(store, row)
            future.release()
        submit()
        if progress is not None:
            progress(Tally(count.ok, count.failed, min(len(pending), slots), total))
    return len(queue), slots


_REPORT_EVERY_S = 1.0


@contextmanager
def _reporting(db_path: str | Path, spec: CampaignSpec,
               progress: Progress | None) -> Iterator[Progress]:
    """``progress``, also reported beside the database (at most once a second, and at the
    start) for ``campaign status`` to read while the database is held; the report is removed
    when the campaign stops."""
    last = -math.inf

    def report(tally: Tally) -> None:
        nonlocal last
        if progress is not None:
            progress(tally)
        now = time.monotonic()
        if now - last >= _REPORT_EVERY_S:
            last = now
            write_progress(db_path, {"campaign": spec.name, "experiment": spec.experiment,
                                     **dataclasses.asdict(tally)})

    try:
        yield report
    finally:
        clear_progress(db_path)


def run_campaign(spec: CampaignSpec, db_path: str | Path, *, workers: int | None = None,
                 scheduler: str | None = None, retry_failed: bool = False,
                 progress: Progress | None = None,
                 on_cluster: Callable[[str | None], None] | None = None) -> CampaignSummary:
    """Run every run of ``spec`` not yet recorded in ``db_path``.

    Parameters
    ----------
    spec
        The campaign.
    db_path
        Its DuckDB results database (created if missing).
    workers
        Processes of the embedded LocalCluster (``None``: one per core; ``0``: run in this
        process, one run after the other).
    scheduler
        Address of an existing Dask scheduler (``workers`` is then ignored).
    retry_failed
        Run again the runs recorded with status ``error``.
    progress
        Called with a :class:`Tally` after each recorded run.
    on_cluster
        Called once the cluster is up, with its dashboard address (``None`` when there is none).

    Raises
    ------
    InvalidInputError
        ``workers < 0``.
    StoreError
        ``db_path`` holds another campaign.
    """
    if workers is not None:
        checks.count("workers", workers)
    runs = spec.runs()
    started = time.perf_counter()
    count = _Count()
    with ResultStore(db_path, spec.name, spec.definition, spec.metrics) as store, \
            _reporting(db_path, spec, progress) as progress:
        store.plan((r.key, r.params) for r in runs)
        finished = store.finished_keys(include_failed=not retry_failed)
        todo = [r for r in runs if r.key not in finished]
        log.info("campaign %s: %d runs, %d recorded, %d to run", spec.name, len(runs),
                 len(runs) - len(todo), len(todo))
        total = len(todo)
        progress(Tally(0, 0, 0, total))
        dashboard: str | None = None
        startup = 0.0
        if not todo:
            left, slots = 0, 0
        elif stop_requested():   # Ctrl-C before the first run: no cluster to start and close
            left, slots = len(todo), 0
        elif scheduler is None and workers == 0:
            if on_cluster is not None:
                on_cluster(None)
            left, slots = _serial(todo, store, count, total, progress), 1
        else:
            t0 = time.perf_counter()
            with _client(workers, scheduler) as client:
                startup = time.perf_counter() - t0
                dashboard = client.dashboard_link if scheduler is None else None
                if on_cluster is not None:
                    on_cluster(dashboard)
                left, slots = _distributed(client, todo, store, count, total, progress)
        failed_recorded = store.counts().get("error", 0)
    return CampaignSummary(len(runs), len(runs) - len(todo), count.ok, count.failed, left,
                           time.perf_counter() - started, count.run_s, slots, startup, dashboard,
                           failed_recorded)
