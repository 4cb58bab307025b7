"""Running campaigns: one row per run, resume, retry of failures, stop, and on a Dask cluster
(also with a worker killed mid-campaign) every key exactly once."""

from __future__ import annotations

import os
import signal
from collections import Counter
from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.sim.campaigns import runner
from searchtrack.sim.campaigns.runner import Tally, run_campaign, run_one
from searchtrack.sim.campaigns.spec import CampaignSpec
from searchtrack.sim.campaigns.store import open_existing
from tests.sim.campaigns.toy import toy_spec


def _keys(db: Path) -> Counter[str]:
    with open_existing(db) as store:
        return Counter(r["key"] for r in store.rows())


def _assert_every_key_once(spec: CampaignSpec, db: Path) -> None:
    keys = _keys(db)
    assert set(keys) == {r.key for r in spec.runs()}
    assert max(keys.values()) == 1


def test_run_one_records_the_error_and_where_it_ran() -> None:
    """A run that raises gives a row with status error, its message, host and times."""
    run = toy_spec(fail=(True,)).runs()[0]
    row = run_one(run)
    assert row["status"] == "error" and "RuntimeError: toy run failed" in row["error"]
    assert row["host"] and row["started_utc"] <= row["ended_utc"] and row["runtime_s"] >= 0


def test_in_process_run_writes_one_row_per_run(tmp_path: Path) -> None:
    """``workers=0`` runs every run in this process and records each once."""
    spec, db = toy_spec(), tmp_path / "r.duckdb"
    seen: list[Tally] = []
    summary = run_campaign(spec, db, workers=0, progress=seen.append)
    assert (summary.total, summary.ok, summary.failed, summary.not_run) == (6, 6, 0, 0)
    assert seen[-1] == Tally(6, 0, 0, 6)
    _assert_every_key_once(spec, db)


def test_a_second_run_resumes(tmp_path: Path) -> None:
    """Running the same campaign again skips every finished key; new seeds run alone."""
    db = tmp_path / "r.duckdb"
    run_campaign(toy_spec(seeds=2), db, workers=0)
    again = run_campaign(toy_spec(seeds=2), db, workers=0)
    assert (again.skipped, again.ok) == (4, 0)
    more = run_campaign(toy_spec(seeds=3), db, workers=0)
    assert (more.skipped, more.ok) == (4, 2)
    _assert_every_key_once(toy_spec(seeds=3), db)


def test_failures_are_recorded_and_retried_alone(tmp_path: Path) -> None:
    """Failing runs are recorded and the others go on; ``retry_failed`` reruns only them."""
    spec, db = toy_spec(fail=(False, True)), tmp_path / "r.duckdb"
    first = run_campaign(spec, db, workers=0)
    assert (first.ok, first.failed) == (6, 6)
    plain = run_campaign(spec, db, workers=0)
    assert plain.skipped == 12
    assert (first.failed_recorded, plain.failed, plain.failed_recorded) == (6, 0, 6)
    retry = run_campaign(spec, db, workers=0, retry_failed=True)
    assert (retry.skipped, retry.ok, retry.failed) == (6, 0, 6)
    _assert_every_key_once(spec, db)


def test_a_stop_request_keeps_what_was_done(tmp_path: Path) -> None:
    """A stop after two runs leaves two rows; running again finishes the rest."""
    spec, db = toy_spec(), tmp_path / "r.duckdb"

    def stop_after_two(t: Tally) -> None:
        if t.done == 2:
            request_stop()

    try:
        summary = run_campaign(spec, db, workers=0, progress=stop_after_two)
    finally:
        clear_stop()
    assert (summary.ok, summary.not_run, summary.interrupted) == (2, 4, True)
    assert sum(_keys(db).values()) == 2
    assert run_campaign(spec, db, workers=0).ok == 4
    _assert_every_key_once(spec, db)


def test_a_stop_before_the_first_run_starts_no_cluster(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C before the campaign starts (e.g. while the kernels load): the runs are planned,
    none is run and no cluster is started (nothing to close)."""
    def no_cluster(*_: object) -> None:
        raise AssertionError("a cluster was started after the stop")

    monkeypatch.setattr(runner, "_client", no_cluster)
    spec, db = toy_spec(), tmp_path / "r.duckdb"
    request_stop()
    try:
        summary = run_campaign(spec, db, workers=2)
    finally:
        clear_stop()
    assert (summary.ok, summary.not_run, summary.interrupted) == (0, 6, True)
    assert sum(_keys(db).values()) == 0
    assert run_campaign(spec, db, workers=0).ok == 6


def test_negative_workers_are_refused(tmp_path: Path) -> None:
    """``workers < 0`` is refused before the database is created."""
    with pytest.raises(InvalidInputError, match="workers"):
        run_campaign(toy_spec(), tmp_path / "r.duckdb", workers=-1)
    assert not (tmp_path / "r.duckdb").exists()


@pytest.mark.slow
def test_local_cluster_records_every_key_once(tmp_path: Path) -> None:
    """Twenty toy runs (two failing) on a 2-process LocalCluster: every key exactly once."""
    spec, db = toy_spec((1.0, 2.0), seeds=5, fail=(False, True), sleep_s=0.01), tmp_path / "r.db"
    summary = run_campaign(spec, db, workers=2)
    assert (summary.ok, summary.failed, summary.slots) == (10, 10, 2)
    assert summary.dashboard is not None and summary.dashboard.startswith("http")
    _assert_every_key_once(spec, db)


@pytest.mark.slow
def test_a_killed_worker_loses_no_run(tmp_path: Path) -> None:
    """SIGKILL of a worker process mid-campaign: its runs are rescheduled, every key once."""
    from dask.distributed import Client, LocalCluster

    spec = toy_spec((1.0, 2.0), seeds=10, sleep_s=0.2)
    db = tmp_path / "r.duckdb"
    cluster = LocalCluster(n_workers=2, threads_per_worker=1,  # type: ignore[no-untyped-call]
                           processes=True, dashboard_address=":0")
    with cluster, Client(cluster) as client:  # type: ignore[no-untyped-call]
        pids = list(client.run(os.getpid).values())
        killed: list[int] = []

        def kill_one(t: Tally) -> None:
            if t.done >= 3 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        summary = run_campaign(spec, db, scheduler=cluster.scheduler_address,
                               progress=kill_one)
    assert killed
    assert (summary.ok, summary.failed, summary.not_run) == (20, 0, 0)
    _assert_every_key_once(spec, db)


@pytest.mark.slow
def test_a_stop_on_a_local_cluster_keeps_the_database_consistent(tmp_path: Path) -> None:
    """A stop request (what Ctrl-C sends) after four runs on a 2-process LocalCluster: the runs
    in flight are dropped, every recorded key once, and running again finishes the rest."""
    spec, db = toy_spec((1.0, 2.0), seeds=6, sleep_s=0.1), tmp_path / "r.duckdb"

    def stop_after_four(t: Tally) -> None:
        if t.done >= 4:
            request_stop()

    try:
        first = run_campaign(spec, db, workers=2, progress=stop_after_four)
    finally:
        clear_stop()
    assert first.interrupted and 4 <= first.ok < 12 and first.ok + first.not_run == 12
    keys = _keys(db)
    assert sum(keys.values()) == first.ok and max(keys.values()) == 1
    second = run_campaign(spec, db, workers=0)
    assert second.skipped == first.ok and second.ok == 12 - first.ok
    _assert_every_key_once(spec, db)
