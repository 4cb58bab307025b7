"""``searchtrack track``: SCANS.json in, EST.json out, and a named error for malformed files."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.cli import main
from searchtrack.core.errors import ParseError
from searchtrack.estimate.metrics import ospa
from searchtrack.models.motion import ConstantVelocity, Static
from searchtrack.sim.phd_scenario import standard_scenario
from searchtrack.sim.track_job import read_scans, run_track_file


def _doc(n_scans: int = 25) -> tuple[dict[str, Any], np.ndarray]:
    sc = standard_scenario(2, n_targets=3, n_scans=n_scans)
    doc = {"area": [[0.0, 1000.0], [0.0, 1000.0]], "dt": 1.0,
           "sensor": {"pd": 0.9, "sigma": 10.0, "clutter_rate": 10.0},
           "motion": {"model": "cv", "q": 0.5}, "birth_weight": 0.25,
           "scans": [z.tolist() for z in sc.scans]}
    return doc, sc.truth


def _write(tmp_path: Path, doc: object, name: str = "scans.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def test_cli_track_writes_estimates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`searchtrack track` writes one estimate list per scan that follows the targets."""
    doc, truth = _doc()
    scans, out = _write(tmp_path, doc), tmp_path / "est.json"
    assert main(["track", str(scans), "--particles", "3000", "--seed", "1", "--out",
                 str(out)]) == 0
    assert "25 scans" in capsys.readouterr().out
    est = json.loads(out.read_text())
    assert len(est["estimates"]) == 25 and est["ms_per_scan"] > 0.0
    late = [ospa(np.array(e).reshape(-1, 2), truth[k][:, :2], c=100.0)
            for k, e in enumerate(est["estimates"]) if k >= 10]
    assert np.mean(late) < 35.0


def test_run_track_file_is_deterministic(tmp_path: Path) -> None:
    """The same seed gives the same EST.json estimates."""
    doc, _ = _doc(12)
    scans = _write(tmp_path, doc)
    run_track_file(scans, tmp_path / "a.json", seed=4)
    run_track_file(scans, tmp_path / "b.json", seed=4)
    a = json.loads((tmp_path / "a.json").read_text())
    b = json.loads((tmp_path / "b.json").read_text())
    assert a["estimates"] == b["estimates"]


def test_motion_models_and_optional_birth_weight(tmp_path: Path) -> None:
    """`static` and `rw` motion parse; birth_weight defaults to 0.25."""
    doc, _ = _doc(3)
    del doc["birth_weight"]
    doc["motion"] = {"model": "static"}
    job = read_scans(_write(tmp_path, doc))
    assert isinstance(job.motion, Static) and job.birth_weight == 0.25
    doc["motion"] = {"model": "cv", "q": 2.0}
    job = read_scans(_write(tmp_path, doc))
    assert isinstance(job.motion, ConstantVelocity) and job.motion.q == 2.0


def _mutate(path: str, value: object) -> dict[str, Any]:
    doc, _ = _doc(3)
    doc = copy.deepcopy(doc)
    keys = path.split(".")
    target: Any = doc
    for key in keys[:-1]:
        target = target[int(key)] if key.isdigit() else target[key]
    last = keys[-1]
    if value is KeyError:
        del target[last]
    elif last.isdigit():
        target[int(last)] = value
    else:
        target[last] = value
    return doc


@pytest.mark.parametrize(("path", "value", "field"), [
    ("dt", KeyError, "dt"),
    ("scans", KeyError, "scans"),
    ("sensor.pd", KeyError, "sensor.pd"),
    ("dt", -1.0, "dt"),
    ("dt", "1", "dt"),
    ("dt", float("nan"), "dt"),
    ("sensor.pd", 1.5, "sensor.pd"),
    ("sensor.sigma", True, "sensor.sigma"),
    ("sensor", [0.9], "sensor"),
    ("area", [[0.0, 0.0], [0.0, 10.0]], "area"),
    ("area", [[0.0, 1.0]], "area"),
    ("motion.model", "ca", "motion.model"),
    ("motion.q", KeyError, "motion.q"),
    ("birth_weight", -0.1, "birth_weight"),
    ("scans", {"0": []}, "scans"),
    ("scans.1", 5, "scans[1]"),
    ("scans.1", [[1.0, 2.0, 3.0]], "scans[1][0]"),
    ("scans.1", [[1.0, "x"]], "scans[1][0][1]"),
    ("scans.1", [[1.0, float("nan")]], "scans[1][0][1]"),
    ("birth_wieght", 0.5, "birth_wieght"),
    ("sensor.clutter", 3.0, "sensor.clutter"),
])
def test_malformed_files_name_the_field(tmp_path: Path, path: str, value: object,
                                        field: str) -> None:
    """Every malformed SCANS.json raises ParseError naming the file and the JSON field."""
    scans = _write(tmp_path, _mutate(path, value))
    with pytest.raises(ParseError) as err:
        read_scans(scans)
    assert err.value.field == field
    assert str(scans) in str(err.value)


def test_cli_reports_bad_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The command exits with 2 and names the field for a bad file or invalid JSON."""
    bad = _write(tmp_path, _mutate("motion.model", "ukf"))
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
