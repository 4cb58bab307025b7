"""``searchtrack mission run``: a scenario file flown, its log and figures written; a malformed
scenario exits with status 2."""

from __future__ import annotations

import json
from pathlib import Path

from searchtrack.cli import main


def test_cli_writes_json_and_figures(tmp_path: Path) -> None:
    """`searchtrack mission run` writes mission.json, map.png and moc.png."""
    scenario = tmp_path / "grid.toml"
    scenario.write_text('name = "cli"\nduration_s = 6.0\nseed = 1\n[map]\n'
                        'grid = { rows = 4, cols = 4, block_m = 100.0 }\n[uavs]\ncount = 2\n'
                        '[targets]\ncount = 2\n', encoding="utf-8")
    out = tmp_path / "out"
    assert main(["mission", "run", str(scenario), "--out", str(out)]) == 0
    record = json.loads((out / "mission.json").read_text(encoding="utf-8"))
    assert record["scenario"]["name"] == "cli"
    assert len(record["moc"]) == 20
    assert len(record["tracks"]) == len(record["associations"]) == 20
    assert record["summary"]["steps"] == 20
    for png in ("map.png", "moc.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_reports_bad_scenarios(tmp_path: Path) -> None:
    """A malformed scenario exits with status 2 and names the key."""
    scenario = tmp_path / "bad.toml"
    scenario.write_text('[map]\ngrid = { rows = 4, cols = 4 }\n[uavs]\ncount = -1\n',
                        encoding="utf-8")
    assert main(["mission", "run", str(scenario), "--out", str(tmp_path)]) == 2
