"""`searchtrack optw`: solve and bench, JSON output, and clear errors."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from searchtrack.cli import main

DATA = Path(__file__).parents[1] / "data" / "optw"


def test_solve_prints_summary_and_writes_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                              ) -> None:
    """`optw solve` prints the summary and writes the documented JSON record."""
    out = tmp_path / "r.json"
    code = main(["optw", "solve", str(DATA / "tiny5.txt"), "--backend", "ils", "--time-limit",
                 "0.5", "--json", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "tiny5" in text and "objective" in text
    rec = json.loads(out.read_text())
    for key in ("instance", "backend", "status", "objective", "bound", "runtime_s", "routes"):
        assert key in rec
    assert rec["instance"] == "tiny5" and rec["backend"] == "ils"
    assert all(r[0] == 0 and r[-1] == 0 for r in rec["routes"])


def test_solve_exact_with_vehicles(tmp_path: Path) -> None:
    """With two vehicles the exact auto backend proves the tiny optimum and returns two routes."""
    out = tmp_path / "r.json"
    assert main(["optw", "solve", str(DATA / "tiny5.txt"), "--vehicles", "2", "--time-limit",
                 "5", "--json", str(out)]) == 0
    rec = json.loads(out.read_text())
    assert rec["status"] == "OPTIMAL" and len(rec["routes"]) == 2


def test_bench_table_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`optw bench` solves every file, compares with optima.csv and writes a JSON list."""
    shutil.copy(DATA / "tiny5.txt", tmp_path / "tiny5.txt")
    shutil.copy(DATA / "tiny5.txt", tmp_path / "other.txt")
    (tmp_path / "optima.csv").write_text(
        "instance,set,nodes,optimum,status\ntiny5,x,5,42,proven\n"
    )
    out = tmp_path / "b.json"
    code = main(["optw", "bench", str(tmp_path), "--backend", "auto", "--time-limit", "2",
                 "--json", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "mean gap" in text and "proven optimal" in text
    recs = json.loads(out.read_text())
    assert [r["instance"] for r in recs] == ["other", "tiny5"]
    assert recs[1]["optimum"] == 42 and recs[1]["objective"] == 42


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["optw", "solve", "missing.txt"], "no such file"),
        (["optw", "bench", "not-a-dir"], "not a directory"),
    ],
)
def test_errors_are_clear(argv: list[str], needle: str, capsys: pytest.CaptureFixture[str]
                          ) -> None:
    """Bad paths give exit code 2 and a one-line error, not a traceback."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err


@pytest.mark.parametrize("flag", [["--time-limit", "0"], ["--time-limit", "x"],
                                  ["--vehicles", "0"], ["--backend", "nope"]])
def test_bad_options_rejected(flag: list[str]) -> None:
    """Non-positive limits, zero vehicles and unknown backends are refused by the parser."""
    with pytest.raises(SystemExit) as info:
        main(["optw", "solve", str(DATA / "tiny5.txt"), *flag])
    assert info.value.code == 2
