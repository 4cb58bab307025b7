"""The results database of a campaign: a DuckDB file with a ``runs`` table (one row per finished
run) and a one-row ``campaign`` table naming the campaign it belongs to.

``runs`` columns: ``key`` (primary key), ``experiment``, every parameter, ``seed``, ``status``
(``ok`` or ``error``), every metric, ``runtime_s``, ``error`` (the message), ``host``,
``version``, ``started_utc``, ``ended_utc``. Only the campaign's client writes (one writer);
each row is committed as its run completes.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Iterable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import duckdb

from searchtrack.core.errors import SearchtrackError
from searchtrack.core.files import atomic_path, write_text_atomic
from searchtrack.sim.campaigns import experiments
from searchtrack.sim.campaigns.experiments import Experiment

log = logging.getLogger("searchtrack.sim.campaigns.store")

_SQL_TYPES: dict[type, str] = {bool: "BOOLEAN", int: "BIGINT", float: "DOUBLE", str: "VARCHAR"}

#: Export formats by file suffix.
EXPORTS = {".parquet": "(FORMAT parquet)", ".csv": "(FORMAT csv, HEADER true)"}


class StoreError(SearchtrackError):
    """A results database that cannot serve this campaign (another campaign's, or not one)."""

    def __init__(self, path: Path, reason: str) -> None:
        super().__init__(f"{path}: {reason}")
        self.path, self.reason = path, reason


#: The runs each campaign file asked for (key, parameters as JSON).
PLANNED_TABLE = "CREATE TABLE IF NOT EXISTS planned (key VARCHAR PRIMARY KEY, params VARCHAR)"


def columns(experiment: Experiment) -> dict[str, str]:
    """The ``runs`` table's columns and their SQL types, in order."""
    cols = {"key": "VARCHAR PRIMARY KEY", "experiment": "VARCHAR"}
    cols.update({p.name: _SQL_TYPES[p.kind] for p in experiment.params})
    cols.update({"seed": "BIGINT", "status": "VARCHAR"})
    cols.update({name: _SQL_TYPES[m.kind] for name, m in experiment.metrics.items()})
    cols.update({"runtime_s": "DOUBLE", "error": "VARCHAR", "host": "VARCHAR",
                 "version": "VARCHAR", "started_utc": "TIMESTAMP", "ended_utc": "TIMESTAMP"})
    return cols


def _quote(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


class ResultStore:
    """The ``runs`` of one campaign in a DuckDB file, created if missing.

    Parameters
    ----------
    path
        The database file.
    campaign
        The campaign's name; a database holding another campaign is refused.
    experiment
        Its experiment (defines the columns).
    metrics
        The metrics the campaign reports (kept with it; all of the experiment's when empty).

    Raises
    ------
    StoreError
        The file holds another campaign, another experiment, or is not a results database.
    """

    def __init__(self, path: str | Path, campaign: str, experiment: Experiment,
                 metrics: Sequence[str] = ()) -> None:
        self.path = Path(path)
        self.campaign, self.experiment = campaign, experiment
        self.metrics: tuple[str, ...] = tuple(metrics) or tuple(experiment.metrics)
        self._columns = columns(experiment)
        try:
            self._db = duckdb.connect(str(self.path))
        except duckdb.Error as exc:
            if _is_lock_conflict(exc):
                raise StoreBusy(self.path, read_progress(self.path)) from None
            raise StoreError(self.path, f"not a DuckDB database ({exc})") from None
        try:
            self._open()
        except duckdb.Error as exc:
            self._db.close()
            raise StoreError(self.path, f"cannot read it as a campaign database "
                             f"({str(exc).splitlines()[0]})") from None
        except BaseException:
            self._db.close()
            raise

    def _open(self) -> None:
        tables = {r[0] for r in self._db.execute("SELECT table_name FROM information_schema."
                                                 "tables").fetchall()}
        if "campaign" in tables:
            kept = {r[0] for r in self._db.execute(
                "SELECT column_name FROM information_schema.columns WHERE table_name = "
                "'campaign'").fetchall()}
            listed = "metrics" if "metrics" in kept else "NULL"  # databases before the column
            row = self._db.execute(f"SELECT name, experiment, {listed} FROM campaign").fetchone()
            if row is not None and row[2]:
                self.metrics = tuple(json.loads(row[2]))
            if row is None or tuple(row[:2]) != (self.campaign, self.experiment.name):
                held = "nothing" if row is None else f"campaign {row[0]!r} ({row[1]})"
                raise StoreError(self.path, f"holds {held}, not campaign {self.campaign!r} "
                                 f"({self.experiment.name}); give another --db")
            have = [r[0] for r in self._db.execute(
                "SELECT column_name FROM information_schema.columns WHERE table_name = 'runs' "
                "ORDER BY ordinal_position").fetchall()]
            if have != list(self._columns):
                raise StoreError(self.path, "its runs table has other columns than experiment "
                                 f"{self.experiment.name!r} now has; give another --db")
            self._db.execute(PLANNED_TABLE)  # databases before the table
            return
        if tables:
            raise StoreError(self.path, f"holds tables {sorted(tables)}, not a campaign")
        cols = ", ".join(f"{_quote(c)} {t}" for c, t in self._columns.items())
        self._db.execute("BEGIN TRANSACTION")
        self._db.execute("CREATE TABLE campaign (name VARCHAR, experiment VARCHAR, "
                         "metrics VARCHAR)")
        self._db.execute("INSERT INTO campaign VALUES (?, ?, ?)",
                         [self.campaign, self.experiment.name, json.dumps(list(self.metrics))])
        self._db.execute(f"CREATE TABLE runs ({cols})")
        self._db.execute(PLANNED_TABLE)
        self._db.execute("COMMIT")
        log.info("created results database %s for campaign %s", self.path, self.campaign)

    def close(self) -> None:
        """Close the database."""
        self._db.close()

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def finished_keys(self, *, include_failed: bool = True) -> set[str]:
        """Keys of the runs recorded (only those that ended ``ok`` unless ``include_failed``)."""
        where = "" if include_failed else " WHERE status = 'ok'"
        return {r[0] for r in self._db.execute(f"SELECT key FROM runs{where}").fetchall()}

    def insert(self, row: Mapping[str, Any]) -> None:
        """Record one run (replacing an earlier row of the same key: a retried failure).

        ``row`` has every column; missing metrics are NULL.
        """
        values = [row.get(c) for c in self._columns]
        names = ", ".join(_quote(c) for c in self._columns)
        marks = ", ".join("?" for _ in self._columns)
        self._db.execute(f"INSERT OR REPLACE INTO runs ({names}) VALUES ({marks})", values)

    def plan(self, runs: Iterable[tuple[str, Mapping[str, Any]]]) -> None:
        """Record the runs a campaign file asks for, as ``(key, parameters)`` (kept across
        resumes: a file that asks for more seeds adds its new runs), so that a stopped
        campaign's status and report can say which runs are missing."""
        self._db.executemany("INSERT OR IGNORE INTO planned VALUES (?, ?)",
                             [[key, json.dumps(dict(params), sort_keys=True)]
                              for key, params in runs])

    def missing(self) -> list[dict[str, Any]]:
        """The parameters of each planned run with no row yet (none recorded: an empty list)."""
        return [json.loads(r[0]) for r in self._db.execute(
            "SELECT params FROM planned WHERE key NOT IN (SELECT key FROM runs) ORDER BY key"
        ).fetchall()]

    def counts(self) -> dict[str, int]:
        """Number of rows per status."""
        rows = self._db.execute("SELECT status, count(*) FROM runs GROUP BY status").fetchall()
        return {str(s): int(n) for s, n in rows}

    def rows(self) -> list[dict[str, Any]]:
        """Every row, as column -> value, in key order."""
        cur = self._db.execute("SELECT * FROM runs ORDER BY key")
        names = [d[0] for d in cur.description]
        return [dict(zip(names, r, strict=True)) for r in cur.fetchall()]

    def export(self, path: str | Path) -> Path:
        """Write the ``runs`` table to ``path`` (``.parquet`` or ``.csv``, atomically).

        Raises
        ------
        StoreError
            Another suffix.
        """
        target = Path(path)
        fmt = EXPORTS.get(target.suffix.lower())
        if fmt is None:
            raise StoreError(target, f"export to {sorted(EXPORTS)}, by suffix")
        with atomic_path(target) as temp:
            quoted = str(temp).replace("'", "''")
            self._db.execute(f"COPY (SELECT * FROM runs ORDER BY key) TO '{quoted}' {fmt}")
        return target


class StoreBusy(StoreError):
    """The database is held by a running campaign (DuckDB allows one writing process);
    ``progress`` is what that campaign last reported (:func:`read_progress`), if anything."""

    def __init__(self, path: Path, progress: dict[str, Any] | None) -> None:
        who = f" (PID {progress['pid']})" if progress else ""
        super().__init__(path, f"is being written by a running campaign{who}; try again "
                               "when it stops")
        self.progress = progress


def progress_path(db_path: str | Path) -> Path:
    """The file beside ``db_path`` where a running campaign reports its progress."""
    p = Path(db_path)
    return p.with_name(p.name + ".progress.json")


def write_progress(db_path: str | Path, progress: Mapping[str, Any]) -> None:
    """Report a running campaign's progress beside its database (atomically), with this
    process's PID and the time."""
    data = {**progress, "pid": os.getpid(),
            "updated_utc": datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S")}
    write_text_atomic(progress_path(db_path), json.dumps(data))


def read_progress(db_path: str | Path) -> dict[str, Any] | None:
    """What the campaign writing ``db_path`` last reported, or ``None`` (none running, or no
    readable report)."""
    try:
        data = json.loads(progress_path(db_path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and "pid" in data else None


def clear_progress(db_path: str | Path) -> None:
    """Remove the progress report of ``db_path`` (the campaign stopped)."""
    progress_path(db_path).unlink(missing_ok=True)


def _is_lock_conflict(exc: duckdb.Error) -> bool:
    return isinstance(exc, duckdb.IOException) and "lock" in str(exc).lower()


def describe(path: str | Path) -> tuple[str, str, dict[str, int]]:
    """Campaign name, experiment and row counts per status of the database at ``path``, opened
    read-only.

    Raises
    ------
    StoreBusy
        A running campaign holds the database.
    StoreError
        Missing file or not a campaign database.
    """
    p = Path(path)
    if not p.is_file():
        raise StoreError(p, "no such database")
    try:
        with duckdb.connect(str(p), read_only=True) as db:
            row = db.execute("SELECT name, experiment FROM campaign").fetchone()
            counts = db.execute("SELECT status, count(*) FROM runs GROUP BY status").fetchall()
    except duckdb.Error as exc:
        if _is_lock_conflict(exc):
            raise StoreBusy(p, read_progress(p)) from None
        raise StoreError(p, f"cannot read it as a campaign database ({str(exc).splitlines()[0]})"
                         ) from None
    if row is None:
        raise StoreError(p, "not a campaign database (no campaign row)")
    return str(row[0]), str(row[1]), {str(s): int(n) for s, n in counts}


def missing_runs(path: str | Path) -> int | None:
    """How many planned runs the database at ``path`` has no row for (opened read-only);
    ``None`` for a database written before runs were planned in it.

    Raises
    ------
    StoreBusy, StoreError
        As :func:`describe`.
    """
    p = Path(path)
    describe(p)
    with duckdb.connect(str(p), read_only=True) as db:
        tables = {r[0] for r in db.execute("SELECT table_name FROM information_schema.tables"
                                           ).fetchall()}
        if "planned" not in tables:
            return None
        row = db.execute("SELECT count(*) FROM planned WHERE key NOT IN (SELECT key FROM runs)"
                         ).fetchone()
    return int(row[0]) if row is not None else 0


def open_existing(path: str | Path) -> ResultStore:
    """The store of the campaign already in ``path`` (for export and status).

    Raises
    ------
    StoreError
        Missing file, not a campaign database, or an experiment no longer registered.
    """
    name, experiment, _ = describe(path)
    if experiment not in experiments.EXPERIMENTS:
        raise StoreError(Path(path), f"experiment {experiment!r} is not registered")
    return ResultStore(path, name, experiments.EXPERIMENTS[experiment])


def utc_naive(moment: datetime) -> datetime:
    """``moment`` (zone-aware) in UTC without its zone: the ``TIMESTAMP`` columns hold UTC."""
    return moment.astimezone(UTC).replace(tzinfo=None)
