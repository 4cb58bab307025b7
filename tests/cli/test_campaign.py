"""``searchtrack campaign run|status|export``: exit statuses, resume, one-line bad input that
writes nothing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import duckdb
import pytest

from searchtrack.cli import main
from searchtrack.sim.campaigns.store import progress_path, write_progress
from tests.sim.campaigns.toy import write_toy_file


def test_run_status_and_export(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A toy campaign runs in-process (exit 0), resumes, reports its status and exports."""
    path, db = write_toy_file(tmp_path), tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 0
    assert "4 ok" in capsys.readouterr().out
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 0
    assert "4 already recorded" in capsys.readouterr().out
    assert main(["campaign", "status", str(db)]) == 0
    assert "toy-file" in capsys.readouterr().out
    out = tmp_path / "runs.csv"
    assert main(["campaign", "export", str(db), str(out)]) == 0
    assert len(out.read_text(encoding="utf-8").splitlines()) == 5


def test_default_database_sits_beside_the_file(tmp_path: Path) -> None:
    """Without --db the results go to FILE with suffix .duckdb."""
    path = write_toy_file(tmp_path)
    assert main(["campaign", "run", str(path), "--workers", "0"]) == 0
    assert path.with_suffix(".duckdb").is_file()


def test_failed_runs_exit_1_and_can_be_retried(tmp_path: Path) -> None:
    """Some failed runs give exit status 1, also after a retry that fails again."""
    path = write_toy_file(tmp_path, "[grid]\nfail = [false, true]\n")
    db = tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 1
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0",
                 "--retry-failed"]) == 1
    assert main(["campaign", "status", str(db)]) == 1


@pytest.mark.parametrize(("body", "key"), [
    ("[grid]\ncolour = [1]\n", "grid.colour"),
    ('[grid]\nvalue = ["x"]\n', "grid.value"),
    ("[grid]\nvalue = []\n", "grid.value"),
])
def test_bad_files_exit_2_and_write_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                            body: str, key: str) -> None:
    """A bad campaign file is one line naming the key, status 2, and no database."""
    path, db = write_toy_file(tmp_path, body), tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert key in err and len(err.strip().splitlines()) == 1
    assert not db.exists()


def test_another_campaigns_database_exits_2(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """A --db holding another campaign is refused naming --db; its rows are untouched."""
    db = tmp_path / "r.duckdb"
    first = write_toy_file(tmp_path)
    assert main(["campaign", "run", str(first), "--db", str(db), "--workers", "0"]) == 0
    other = write_toy_file(tmp_path, head='name = "other"\nexperiment = "toy"\nseeds = [7]\n')
    capsys.readouterr()
    assert main(["campaign", "run", str(other), "--db", str(db), "--workers", "0"]) == 2
    assert "--db" in capsys.readouterr().err
    with duckdb.connect(str(db), read_only=True) as con:
        assert con.execute("SELECT count(*) FROM runs").fetchone() == (4,)


def test_bad_paths_exit_2(tmp_path: Path) -> None:
    """A folder as --db, a missing database, or an export suffix we cannot write: status 2."""
    path = write_toy_file(tmp_path)
    assert main(["campaign", "run", str(path), "--db", str(tmp_path), "--workers", "0"]) == 2
    assert main(["campaign", "status", str(tmp_path / "missing.duckdb")]) == 2
    with pytest.raises(SystemExit) as usage:
        main(["campaign", "run", str(path), "--workers", "-1"])
    assert usage.value.code == 2
    db = tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 0
    assert main(["campaign", "export", str(db), str(tmp_path / "runs.json")]) == 2


def test_report_prints_the_groups_and_draws_figures(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """``campaign report`` prints one row per grid point with mean ± CI and writes one PNG per
    metric against the varying parameter."""
    spec = write_toy_file(tmp_path, "[grid]\nvalue = [1.0, 2.0, 4.0]\n")
    db = tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(spec), "--db", str(db), "--workers", "0"]) == 0
    capsys.readouterr()
    assert main(["campaign", "report", str(db), "--out", str(tmp_path / "fig")]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "value" in out and "4 ± 0" in out and "result" in out
    assert sorted(p.name for p in (tmp_path / "fig").iterdir()) == [
        "toy-file-result.png", "toy-file-seed_echo.png"]


def test_report_keeps_to_the_campaigns_metrics(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """A campaign that lists its metrics is reported and drawn for those only."""
    spec = write_toy_file(tmp_path, '[grid]\nvalue = [1.0, 2.0]\n',
                          head='name = "toy-m"\nexperiment = "toy"\nseeds = {count = 2}\n'
                               'metrics = ["result"]\n')
    db = tmp_path / "m.duckdb"
    assert main(["campaign", "run", str(spec), "--db", str(db), "--workers", "0"]) == 0
    assert main(["campaign", "report", str(db), "--out", str(tmp_path / "fig")]) == 0
    assert "seed_echo" not in capsys.readouterr().out
    assert [p.name for p in (tmp_path / "fig").iterdir()] == ["toy-m-result.png"]


def test_status_of_a_running_campaign_reads_its_progress(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """While a campaign holds its database, `status` shows the progress it reports (exit 0);
    `export` says the database is busy (exit 2); the report is gone once the run ends."""
    path, db = write_toy_file(tmp_path), tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 0
    assert not progress_path(db).exists()
    capsys.readouterr()
    code = ("import duckdb, sys, time; c = duckdb.connect(sys.argv[1]); print('held', flush=True);"
            " time.sleep(60)")
    holder = subprocess.Popen([sys.executable, "-c", code, str(db)], stdout=subprocess.PIPE,
                              text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        write_progress(db, {"campaign": "toy-file", "experiment": "toy", "done": 2,
                            "failed": 1, "running": 1, "total": 4})
        assert main(["campaign", "status", str(db)]) == 0
        out = capsys.readouterr().out
        assert "running" in out and "toy-file" in out
        assert main(["campaign", "export", str(db), str(tmp_path / "x.csv")]) == 2
        assert "being written by a running campaign" in capsys.readouterr().err
        assert not (tmp_path / "x.csv").exists()
    finally:
        holder.kill()
        holder.wait()


def test_status_and_report_of_a_stopped_campaign_say_what_is_missing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A campaign stopped after 3 of its 8 planned runs: `status` counts the 5 not run yet,
    `report` marks each partial cell ("1 of 4") and says how many runs are missing."""
    from searchtrack.sim.campaigns.experiments import get
    from searchtrack.sim.campaigns.runner import run_one
    from searchtrack.sim.campaigns.store import ResultStore
    from tests.sim.campaigns.toy import toy_spec

    spec, db = toy_spec(seeds=4), tmp_path / "r.duckdb"
    runs = spec.runs()
    with ResultStore(db, spec.name, get("toy")) as store:
        store.plan((r.key, r.params) for r in runs)
        store.plan((r.key, r.params) for r in runs[:2])   # planning again adds nothing
        for run in [runs[0], runs[1], runs[4]]:
            store.insert(run_one(run))
    assert main(["campaign", "status", str(db)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "not run yet │ 5" in out and "planned │ 8" in out and "5 planned runs are missing" in out
    assert main(["campaign", "report", str(db)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "2 of 4" in out and "1 of 4" in out
    assert "5 planned runs are missing, in 2 of 2 cells" in out


def test_a_finished_campaign_reports_nothing_missing(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    path, db = write_toy_file(tmp_path), tmp_path / "r.duckdb"
    assert main(["campaign", "run", str(path), "--db", str(db), "--workers", "0"]) == 0
    capsys.readouterr()
    assert main(["campaign", "status", str(db)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "not run yet │ 0" in out and "missing" not in out
    assert main(["campaign", "report", str(db)]) == 0
    assert " of " not in capsys.readouterr().out.replace("mean ± 95 % CI", "")
