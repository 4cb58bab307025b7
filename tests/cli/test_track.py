"""``searchtrack track``: SCANS.json in, EST.json out, and exit status 2 naming the field of a
malformed file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from searchtrack.cli import main
from searchtrack.estimate.metrics import ospa
from tests.sim.particles.track_files import mutated, scans_document, write_json


def test_cli_track_writes_estimates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`searchtrack track` writes one estimate list per scan that follows the targets."""
    doc, truth = scans_document()
    scans, out = write_json(tmp_path, doc), tmp_path / "est.json"
    assert main(["track", str(scans), "--particles", "3000", "--seed", "1", "--out",
                 str(out)]) == 0
    assert "25 scans" in capsys.readouterr().out
    est = json.loads(out.read_text())
    assert len(est["estimates"]) == 25 and est["ms_per_scan"] > 0.0
    late = [ospa(np.array(e).reshape(-1, 2), truth[k][:, :2], c=100.0)
            for k, e in enumerate(est["estimates"]) if k >= 10]
    assert np.mean(late) < 35.0


def test_cli_reports_bad_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The command exits with 2 and names the field for a bad file or invalid JSON."""
    bad = write_json(tmp_path, mutated("motion.model", "ukf"))
    assert main(["track", str(bad), "--out", str(tmp_path / "e.json")]) == 2
    assert "motion.model" in capsys.readouterr().err
    broken = tmp_path / "broken.json"
    broken.write_text("{\"area\": [", encoding="utf-8")
    assert main(["track", str(broken), "--out", str(tmp_path / "e.json")]) == 2
    assert "line 1" in capsys.readouterr().err
    assert main(["track", str(tmp_path / "missing.json"), "--out",
                 str(tmp_path / "e.json")]) == 2
    for flag, value in (("--seed", "-1"), ("--particles", "0")):
        with pytest.raises(SystemExit):
            main(["track", str(bad), "--out", str(tmp_path / "e.json"), flag, value])
        assert flag.lstrip("-") in capsys.readouterr().err


def test_the_shipped_example_tracks_its_three_targets(tmp_path: Path) -> None:
    """``examples/problems/scans.json`` (three targets crossing a 200 m square, clutter 2 per
    scan) runs end to end and the filter ends with about three targets."""
    from searchtrack.cli import main

    example = Path(__file__).parents[2] / "examples" / "problems" / "scans.json"
    out = tmp_path / "est.json"
    assert main(["track", str(example), "--out", str(out)]) == 0
    est = json.loads(out.read_text(encoding="utf-8"))
    assert len(est["estimates"]) == 60
    assert 2.0 <= sum(est["expected_count"][-10:]) / 10 <= 4.5
