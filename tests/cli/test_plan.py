"""``searchtrack plan FAMILY``: every registered family's example solves and writes PLAN.json;
bad input exits 2 naming the key and writes nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from searchtrack.cli import main
from searchtrack.cli.plan import available_families

EXAMPLES = Path(__file__).parents[2] / "examples" / "problems"
FIELDS = ("family", "instance", "backend", "status", "objective", "bound", "gap", "runtime_s",
          "message", "plan")

#: A malformed field per family: (dotted key, how to break the document).
BREAK: dict[str, tuple[str, Any]] = {
    "assign": ("sensor.peak_pd", lambda d: d["sensor"].__setitem__("peak_pd", 2.0)),
    "trajectory": ("waypoints", lambda d: d.pop("waypoints")),
}

PRESENT = available_families()


def test_every_family_is_present() -> None:
    """The families are the modules of searchtrack.sim.jobs, each with an example problem."""
    assert PRESENT == ["assign", "associate", "route", "search", "trajectory"]
    assert all((EXAMPLES / f"{family}.json").is_file() for family in PRESENT)


@pytest.mark.parametrize("family", PRESENT)
def test_example_solves(family: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The family's example exits 0, prints the result table and writes the shared fields."""
    out = tmp_path / "sub" / "plan.json"
    code = main(["plan", family, str(EXAMPLES / f"{family}.json"), "--out", str(out),
                 "--time-limit", "10"])
    assert code == 0
    text = capsys.readouterr().out
    assert "status" in text and "objective" in text and "runtime_s" in text
    rec = json.loads(out.read_text())
    assert all(key in rec for key in FIELDS)
    assert rec["family"] == family and rec["status"] in ("OPTIMAL", "FEASIBLE")
    assert isinstance(rec["plan"], dict)


@pytest.mark.parametrize("family", PRESENT)
def test_malformed_file_exits_2_naming_the_key(family: str, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """A broken field exits 2, names the key, and no PLAN.json is written."""
    key, edit = BREAK.get(family, ("bogus_key", lambda d: d.__setitem__("bogus_key", 1)))
    doc = json.loads((EXAMPLES / f"{family}.json").read_text())
    edit(doc)
    problem = tmp_path / "bad.json"
    problem.write_text(json.dumps(doc))
    out = tmp_path / "plan.json"
    assert main(["plan", family, str(problem), "--out", str(out)]) == 2
    assert key in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("family", PRESENT)
def test_unknown_backend_exits_2(family: str, tmp_path: Path,
                                 capsys: pytest.CaptureFixture[str]) -> None:
    """An unknown backend exits 2 listing the choices, before any work."""
    out = tmp_path / "plan.json"
    assert main(["plan", family, str(EXAMPLES / f"{family}.json"), "--out", str(out),
                 "--backend", "nope"]) == 2
    err = capsys.readouterr().err
    assert "nope" in err and "auto" in err
    assert not out.exists()


def test_assign_figure_and_backend(tmp_path: Path) -> None:
    """``--backend greedy --figure`` writes the plan and a PNG."""
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    assert main(["plan", "assign", str(EXAMPLES / "assign.json"), "--out", str(out),
                 "--backend", "greedy", "--figure", str(png)]) == 0
    rec = json.loads(out.read_text())
    assert rec["backend"] == "greedy" and rec["status"] == "FEASIBLE"
    assert len(rec["plan"]["actions"]) == 3 and len(rec["plan"]["poses"]) == 3
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_bad_out_path_exits_2_before_reading(tmp_path: Path) -> None:
    """``--out`` naming a folder fails at once with 2."""
    assert main(["plan", "assign", str(tmp_path / "missing.json"), "--out",
                 str(tmp_path)]) == 2


def test_missing_problem_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A missing PROBLEM.json exits 2 naming it."""
    assert main(["plan", "assign", str(tmp_path / "missing.json"), "--out",
                 str(tmp_path / "p.json")]) == 2
    assert "missing.json" in capsys.readouterr().err
