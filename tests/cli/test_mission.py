"""``searchtrack mission run``: a scenario file flown, its log, figures and replay page written;
a malformed scenario exits with status 2. ``searchtrack mission view``: the replay page of a
mission.json, status 2 with one line for a missing, malformed or older file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from searchtrack.cli import main

GRID_SCENARIO = ('name = "cli"\nduration_s = 6.0\nseed = 1\n[map]\n'
                 'grid = { rows = 4, cols = 4, block_m = 100.0 }\n[uavs]\ncount = 2\n'
                 '[targets]\ncount = 2\n')


@pytest.fixture(scope="module")
def flown(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The output folder of a 20-step `mission run`."""
    folder = tmp_path_factory.mktemp("flown")
    (folder / "grid.toml").write_text(GRID_SCENARIO, encoding="utf-8")
    assert main(["mission", "run", str(folder / "grid.toml"), "--out", str(folder / "out")]) == 0
    return folder / "out"


def test_cli_writes_json_and_figures(flown: Path) -> None:
    """`searchtrack mission run` writes mission.json (with the map and heat frames), map.png,
    moc.png and replay.html."""
    out = flown
    record = json.loads((out / "mission.json").read_text(encoding="utf-8"))
    assert record["scenario"]["name"] == "cli"
    assert len(record["moc"]) == 20
    assert len(record["tracks"]) == len(record["associations"]) == 20
    assert record["summary"]["steps"] == 20
    for png in ("map.png", "moc.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(record["map"]["nodes_xy_m"]) == record["network"]["nodes"]
    assert len(record["heat"]["frames"]) == 20
    page = (out / "replay.html").read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and '<script src="http' not in page


def test_cli_reports_bad_scenarios(tmp_path: Path) -> None:
    """A malformed scenario exits with status 2 and names the key."""
    scenario = tmp_path / "bad.toml"
    scenario.write_text('[map]\ngrid = { rows = 4, cols = 4 }\n[uavs]\ncount = -1\n',
                        encoding="utf-8")
    assert main(["mission", "run", str(scenario), "--out", str(tmp_path)]) == 2


def test_view_writes_the_page(flown: Path, tmp_path: Path,
                              capsys: pytest.CaptureFixture[str]) -> None:
    """`mission view` exits 0 and writes the page at --out, by default replay.html beside the
    record; the same record gives the same page."""
    record = tmp_path / "mission.json"
    record.write_bytes((flown / "mission.json").read_bytes())
    assert main(["mission", "view", str(record), "--out", str(tmp_path / "p" / "r.html")]) == 0
    assert main(["mission", "view", str(record)]) == 0
    assert str(tmp_path / "replay.html") in capsys.readouterr().out.replace("\n", "")
    assert (tmp_path / "replay.html").read_bytes() == (tmp_path / "p" / "r.html").read_bytes()
    assert (tmp_path / "replay.html").read_bytes() == (flown / "replay.html").read_bytes()


def _old_record(tmp: Path, flown: Path) -> Path:
    record = json.loads((flown / "mission.json").read_text(encoding="utf-8"))
    del record["map"], record["heat"]
    return _write(tmp / "mission.json", json.dumps(record))


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("make", "words"), [
    (lambda t, f: t / "missing.json", "no such file"),
    (lambda t, f: _write(t / "mission.json", '{"time_s": [0.3,'), "line 1: not valid JSON"),
    (lambda t, f: _write(t / "mission.json", '{"time_s": [0.3]}'),
     "field 'scenario': missing: not a mission record"),
    (_old_record, "field 'map': missing: the record predates the replay page; re-run"),
], ids=["missing", "malformed", "not a record", "before the map"])
def test_view_rejects_bad_files(flown: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                make: object, words: str) -> None:
    """A missing file, malformed JSON or a record without the map: status 2, one line naming
    the file, and no page."""
    path = make(tmp_path, flown)  # type: ignore[operator]
    assert main(["mission", "view", str(path), "--out", str(tmp_path / "r.html")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert err.startswith(f"error: {path}") and words in " ".join(err.split())
    assert not (tmp_path / "r.html").exists()


def test_view_checks_out_before_reading(flown: Path, tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    """--out a folder, or the record itself: status 2 naming --out."""
    record = flown / "mission.json"
    assert main(["mission", "view", str(record), "--out", str(tmp_path)]) == 2
    assert main(["mission", "view", str(record), "--out", str(record)]) == 2
    err = capsys.readouterr().err
    assert err.count("error: --out") == 2 and "is a folder" in err and "record itself" in err
