"""Offline SMC-PHD jobs: SCANS.json in, EST.json out, and a named error for malformed files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from searchtrack.core.errors import ParseError
from searchtrack.models.motion import ConstantVelocity, Static
from searchtrack.sim.particles.track_job import read_scans, run_track_file
from tests.sim.particles.track_files import mutated, scans_document, write_json


def test_run_track_file_is_deterministic(tmp_path: Path) -> None:
    """The same seed gives the same EST.json estimates."""
    doc, _ = scans_document(12)
    scans = write_json(tmp_path, doc)
    run_track_file(scans, tmp_path / "a.json", seed=4)
    run_track_file(scans, tmp_path / "b.json", seed=4)
    a = json.loads((tmp_path / "a.json").read_text())
    b = json.loads((tmp_path / "b.json").read_text())
    assert a["estimates"] == b["estimates"]


def test_motion_models_and_optional_birth_weight(tmp_path: Path) -> None:
    """`static` and `rw` motion parse; birth_weight defaults to 0.25."""
    doc, _ = scans_document(3)
    del doc["birth_weight"]
    doc["motion"] = {"model": "static"}
    job = read_scans(write_json(tmp_path, doc))
    assert isinstance(job.motion, Static) and job.birth_weight == 0.25
    doc["motion"] = {"model": "cv", "q": 2.0}
    job = read_scans(write_json(tmp_path, doc))
    assert isinstance(job.motion, ConstantVelocity) and job.motion.q == 2.0


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
    scans = write_json(tmp_path, mutated(path, value))
    with pytest.raises(ParseError) as err:
        read_scans(scans)
    assert err.value.field == field
    assert str(scans) in str(err.value)


def test_progress_is_reported_after_every_scan(tmp_path: Path) -> None:
    """``progress(done, total)`` follows the scans, ending at ``(total, total)``."""
    from searchtrack.sim.particles.track_job import run_track_file

    example = Path(__file__).parents[3] / "examples" / "problems" / "scans.json"
    calls: list[tuple[int, int]] = []
    run_track_file(example, tmp_path / "est.json", 500, 0,
                   lambda done, total: calls.append((done, total)))
    assert calls == [(k, 60) for k in range(1, 61)]
