"""The DuckDB results store: one row per run, one campaign per file, exports that round-trip."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import duckdb
import pytest

from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.campaigns.runner import run_one
from searchtrack.sim.campaigns.store import (
    ResultStore,
    StoreBusy,
    StoreError,
    clear_progress,
    describe,
    missing_runs,
    open_existing,
    progress_path,
    read_progress,
    write_progress,
)
from tests.sim.campaigns.toy import toy_spec


def _filled(path: Path, n_seeds: int = 2) -> int:
    spec = toy_spec(seeds=n_seeds, fail=(False, True))
    runs = spec.runs()
    with ResultStore(path, spec.name, get("toy")) as store:
        for run in runs:
            store.insert(run_one(run))
    return len(runs)


def test_rows_are_recorded_once_per_key(tmp_path: Path) -> None:
    """Inserting a key twice keeps one row (the later); finished keys can leave out failures."""
    db = tmp_path / "r.duckdb"
    n = _filled(db)
    spec = toy_spec(seeds=2, fail=(False, True))
    with ResultStore(db, spec.name, get("toy")) as store:
        store.insert(run_one(spec.runs()[0]))
        assert len(store.finished_keys()) == n
        assert len(store.finished_keys(include_failed=False)) == n // 2
        assert store.counts() == {"ok": n // 2, "error": n // 2}
        failed = [r for r in store.rows() if r["status"] == "error"]
        assert all("on purpose" in r["error"] and r["result"] is None for r in failed)
    assert describe(db) == ("toy-test", "toy", {"ok": n // 2, "error": n // 2})


def test_another_campaigns_database_is_refused(tmp_path: Path) -> None:
    """Opening a database of another campaign fails naming --db and changes nothing."""
    db = tmp_path / "r.duckdb"
    n = _filled(db)
    with pytest.raises(StoreError, match=r"holds campaign 'toy-test'.*--db"):
        ResultStore(db, "other", get("toy"))
    with pytest.raises(StoreError, match="toy-test"):
        ResultStore(db, "toy-test", get("mission"))
    assert sum(describe(db)[2].values()) == n


def test_a_foreign_database_is_refused(tmp_path: Path) -> None:
    """A DuckDB file with other tables, or a missing file, is not a campaign database."""
    db = tmp_path / "other.duckdb"
    with duckdb.connect(str(db)) as con:
        con.execute("CREATE TABLE t (x INT)")
    with pytest.raises(StoreError, match="holds tables"):
        ResultStore(db, "toy-test", get("toy"))
    with pytest.raises(StoreError, match="no such database"):
        describe(tmp_path / "missing.duckdb")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_export_round_trips_the_row_count(tmp_path: Path, suffix: str) -> None:
    """Export to CSV and Parquet keeps every row and column."""
    db = tmp_path / "r.duckdb"
    n = _filled(db)
    out = tmp_path / f"runs{suffix}"
    with open_existing(db) as store:
        store.export(out)
        columns = len(store.rows()[0])
    reader = "read_csv_auto" if suffix == ".csv" else "read_parquet"
    with duckdb.connect() as con:
        rel = con.execute(f"SELECT * FROM {reader}('{out}')")
        rows = rel.fetchall()
    assert len(rows) == n and len(rows[0]) == columns
    with open_existing(db) as store, pytest.raises(StoreError, match="by suffix"):
        store.export(tmp_path / "runs.json")


def _holder(db: Path) -> subprocess.Popen[str]:
    """Another process holding ``db`` open for writing (as a running campaign does)."""
    code = ("import duckdb, sys, time; c = duckdb.connect(sys.argv[1]); print('held', flush=True);"
            " time.sleep(60)")
    proc = subprocess.Popen([sys.executable, "-c", code, str(db)], stdout=subprocess.PIPE,
                            text=True)
    assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
    return proc


def test_a_database_held_by_a_running_campaign_is_busy_with_its_progress(
        tmp_path: Path) -> None:
    """Reading or opening a database another process writes raises StoreBusy, carrying the
    progress that campaign reported; without a report the error still says why."""
    db = tmp_path / "r.duckdb"
    _filled(db)
    holder = _holder(db)
    try:
        with pytest.raises(StoreBusy, match="being written by a running campaign") as busy:
            describe(db)
        assert busy.value.progress is None
        write_progress(db, {"campaign": "toy-test", "done": 3, "total": 10})
        with pytest.raises(StoreBusy, match=f"PID {os.getpid()}") as busy:
            describe(db)
        assert busy.value.progress is not None and busy.value.progress["done"] == 3
        with pytest.raises(StoreBusy):
            ResultStore(db, "toy-test", get("toy"))
    finally:
        holder.kill()
        holder.wait()
    clear_progress(db)
    assert read_progress(db) is None
    assert describe(db)[0] == "toy-test"


def test_progress_reports_round_trip_and_ignore_junk(tmp_path: Path) -> None:
    db = tmp_path / "r.duckdb"
    assert read_progress(db) is None
    write_progress(db, {"done": 1})
    report = read_progress(db)
    assert report is not None and report["done"] == 1 and report["pid"] == os.getpid()
    progress_path(db).write_text("{not json", encoding="utf-8")
    assert read_progress(db) is None
    clear_progress(db)
    clear_progress(db)  # removing twice is fine
    assert not progress_path(db).exists()


def test_missing_runs_counts_planned_runs_without_a_row(tmp_path: Path) -> None:
    """Planned keys without a row are missing; a database written before runs were planned
    says nothing (None) until a campaign run plans them."""
    db = tmp_path / "r.duckdb"
    spec = toy_spec(seeds=3)
    runs = spec.runs()
    with ResultStore(db, spec.name, get("toy")) as store:
        store.insert(run_one(runs[0]))
        with duckdb.connect(str(tmp_path / "old.duckdb")) as old:
            old.execute("CREATE TABLE campaign (name VARCHAR, experiment VARCHAR)")
            old.execute("INSERT INTO campaign VALUES ('toy-test', 'toy')")
            old.execute("CREATE TABLE runs (key VARCHAR, status VARCHAR)")
        assert store.missing() == []
        store.plan((r.key, r.params) for r in runs)
        assert len(store.missing()) == len(runs) - 1
        assert sorted(m["value"] for m in store.missing()) == [1.0, 1.0, 2.0, 2.0, 2.0]
    assert missing_runs(db) == len(runs) - 1
    assert missing_runs(tmp_path / "old.duckdb") is None
