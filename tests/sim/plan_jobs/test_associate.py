"""The ``associate`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.result import Status
from searchtrack.sim.plan_jobs import associate

EXAMPLE = Path(__file__).parents[3] / "examples" / "problems" / "associate.json"


def _doc() -> dict[str, Any]:
    """A 3 × 3 grid (100 m blocks), two trackers, three detections: two on them, one far."""
    return {
        "map": {"grid": [3, 3], "spacing_m": 100},
        "trackers": [{"nodes": {"0": 1.0}}, {"peak": [200, 200], "sd_m": 10}],
        "detections": [[195, 200], [0, 5], [200, 0]],
        "noise_sd_m": 5,
        "gate_m": 150,
        "support_mass": 0.999,
    }


def _write(tmp_path: Path, doc: Any) -> Path:
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def test_reads_the_example() -> None:
    """The shipped example: a 5 × 5 grid, 3 trackers (one as node masses), 4 detections."""
    job = associate.read_problem(EXAMPLE)
    assert job.name == "associate" and job.network.n_nodes == 25
    assert len(job.bank) == 3 and job.detections.shape == (4, 2)
    assert job.densities.shape == (4, 25) and np.allclose(job.densities.sum(axis=1), 1.0)
    assert np.allclose(job.bank[0].probability[[6, 7, 11]], [0.6, 0.3, 0.1])
    assert job.gate_m == 200.0 and job.support_mass == 0.999


def test_optional_fields_default(tmp_path: Path) -> None:
    """Without noise, gate, truncation and sd_m the defaults apply; node masses are rescaled."""
    doc = _doc()
    del doc["noise_sd_m"], doc["gate_m"], doc["support_mass"], doc["trackers"][1]["sd_m"]
    doc["trackers"][0] = {"nodes": {"0": 2.0, "1": 2.0}}
    job = associate.read_problem(_write(tmp_path, doc))
    assert job.gate_m == 300.0 and job.support_mass == 0.999
    assert np.allclose(job.bank[0].probability[:2], [0.5, 0.5])
    assert job.bank[1].peak_node() == 8


def _drop(key: str) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        *parents, last = key.split(".")
        target = doc
        for p in parents:
            target = target[int(p)] if p.isdigit() else target[p]
        del target[last]
    return edit


def _set(key: str, value: Any) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        *parents, last = key.split(".")
        target = doc
        for p in parents:
            target = target[int(p)] if p.isdigit() else target[p]
        target[last] = value
    return edit


BAD = [
    (_drop("map"), "'map'"),
    (_drop("trackers"), "'trackers'"),
    (_drop("detections"), "'detections'"),
    (_drop("map.spacing_m"), "'map.spacing_m'"),
    (_set("extra", 1), "'extra'"),
    (_set("map.roads", 1), "'map.roads'"),
    (_set("map.grid", [3]), "'map.grid'"),
    (_set("map.grid", [1, 3]), r"'map.grid\[0\]'"),
    (_set("map.osm", "Atlantis"), "'map'"),
    (_set("map", {"osm": "Atlantis.osm"}), "'map.osm'"),
    (_set("trackers", []), "'trackers'"),
    (_set("trackers.0.peak", [1, 2]), r"'trackers\[0\]'"),
    (_set("trackers.0.mass", 1), r"'trackers\[0\].mass'"),
    (_set("trackers.0.sd_m", 5), r"'trackers\[0\].sd_m'"),
    (_set("trackers.0.nodes", {"9": 1.0}), r"'trackers\[0\].nodes.9'"),
    (_set("trackers.0.nodes", {"x": 1.0}), r"'trackers\[0\].nodes.x'"),
    (_set("trackers.0.nodes", {"0": -1.0}), r"'trackers\[0\].nodes.0'"),
    (_set("trackers.0.nodes", {"0": 0.0}), r"'trackers\[0\].nodes'"),
    (_set("trackers.1.peak", [200, "north"]), r"'trackers\[1\].peak\[1\]'"),
    (_set("trackers.1.peak", [200]), r"'trackers\[1\].peak'"),
    (_set("trackers.1.sd_m", 0), r"'trackers\[1\].sd_m'"),
    (_set("detections", []), "'detections'"),
    (_set("detections", [[0, 0], [1, 2, 3]]), r"'detections\[1\]'"),
    (_set("detections", [[0, 0], [5000, 0]]), r"'detections\[1\]'"),
    (_set("noise_sd_m", 0), "'noise_sd_m'"),
    (_set("gate_m", -1), "'gate_m'"),
    (_set("gate_m", True), "'gate_m'"),
    (_set("support_mass", 1.5), "'support_mass'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    doc = copy.deepcopy(_doc())
    edit(doc)
    with pytest.raises(ParseError, match=key) as info:
        associate.read_problem(_write(tmp_path, doc))
    assert "problem.json" in str(info.value)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    path = tmp_path / "problem.json"
    path.write_text("{\n  \"map\": ,\n}", encoding="utf-8")
    with pytest.raises(ParseError, match="line 2"):
        associate.read_problem(path)
    with pytest.raises(ParseError, match="JSON object"):
        associate.read_problem(_write(tmp_path, [1, 2]))


@pytest.mark.parametrize("backend", ["auto", "greedy", "optimal"])
def test_solve_and_plan_json(tmp_path: Path, backend: str) -> None:
    """Each tracker takes the detection on it; the far one is new; the EMDs are road metres."""
    job = associate.read_problem(_write(tmp_path, _doc()))
    assert associate.backends() == ["auto", "greedy", "optimal"]
    result = associate.solve(job, backend=backend, time_limit_s=5.0, seed=0)
    assert result.status in (Status.OPTIMAL, Status.FEASIBLE) and result.objective is not None
    plan = associate.plan_json(job, result)
    json.dumps(plan)
    assert plan["assignment"] == [1, 0, None] and plan["new"] == [2]
    assert [(p["tracker"], p["detection"]) for p in plan["pairs"]] == [(1, 0), (0, 1)]
    assert plan["costs"][0][1] == pytest.approx(0.0, abs=1e-6)
    assert plan["costs"][1][0] == pytest.approx(0.0, abs=1e-3)
    assert plan["total_emd_m"] == pytest.approx(sum(p["emd_m"] for p in plan["pairs"]))
    assert math.isclose(result.objective, 2 * 150.0 - plan["total_emd_m"], abs_tol=1e-3)


def test_unknown_backend_is_refused() -> None:
    """A wrong backend name is an input error listing the choices."""
    job = associate.read_problem(EXAMPLE)
    with pytest.raises(InvalidInputError, match="optimal"):
        associate.solve(job, backend="hungarian", time_limit_s=1.0, seed=0)


def test_example_solves_and_draws(tmp_path: Path) -> None:
    """The example pairs three detections, leaves one new, and the figure is a PNG."""
    job = associate.read_problem(EXAMPLE)
    result = associate.solve(job, backend="auto", time_limit_s=10.0, seed=0)
    assert result.status is Status.OPTIMAL
    plan = associate.plan_json(job, result)
    assert plan["assignment"] == [1, 0, None, 2] and plan["new"] == [2]
    assert len(plan["costs"]) == 3 and all(len(row) == 4 for row in plan["costs"])
    png = associate.figure(job, result, tmp_path / "plan.png")
    assert png is not None and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
