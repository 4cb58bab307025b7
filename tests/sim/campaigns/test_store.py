"""The DuckDB results store: one row per run, one campaign per file, exports that round-trip."""

from __future__ import annotations

from pathlib import Path

import duckdb
import pytest

from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.campaigns.runner import run_one
from searchtrack.sim.campaigns.store import ResultStore, StoreError, describe, open_existing
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
