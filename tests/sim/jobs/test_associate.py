"""The ``associate`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.sim.jobs import associate
from tests.sim.jobs.helpers import (
    assert_bad_key_named,
    assert_refuses_broken_json,
    drop,
    set_key,
    write_problem,
)

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
    job = associate.read_problem(write_problem(tmp_path, doc))
    assert job.gate_m == 300.0 and job.support_mass == 0.999
    assert np.allclose(job.bank[0].probability[:2], [0.5, 0.5])
    assert job.bank[1].peak_node() == 8




BAD = [
    (drop("map"), "'map'"),
    (drop("trackers"), "'trackers'"),
    (drop("detections"), "'detections'"),
    (drop("map.spacing_m"), "'map.spacing_m'"),
    (set_key("extra", 1), "'extra'"),
    (set_key("map.roads", 1), "'map.roads'"),
    (set_key("map.grid", [3]), "'map.grid'"),
    (set_key("map.grid", [1, 3]), "'map.grid[0]'"),
    (set_key("map.osm", "Atlantis"), "'map'"),
    (set_key("map", {"osm": "Atlantis.osm"}), "'map.osm'"),
    (set_key("trackers", []), "'trackers'"),
    (set_key("trackers.0.peak", [1, 2]), "'trackers[0]'"),
    (set_key("trackers.0.mass", 1), "'trackers[0].mass'"),
    (set_key("trackers.0.sd_m", 5), "'trackers[0].sd_m'"),
    (set_key("trackers.0.nodes", {"9": 1.0}), "'trackers[0].nodes.9'"),
    (set_key("trackers.0.nodes", {"x": 1.0}), "'trackers[0].nodes.x'"),
    (set_key("trackers.0.nodes", {"0": -1.0}), "'trackers[0].nodes.0'"),
    (set_key("trackers.0.nodes", {"0": 0.0}), "'trackers[0].nodes'"),
    (set_key("trackers.1.peak", [200, "north"]), "'trackers[1].peak[1]'"),
    (set_key("trackers.1.peak", [200]), "'trackers[1].peak'"),
    (set_key("trackers.1.sd_m", 0), "'trackers[1].sd_m'"),
    (set_key("detections", []), "'detections'"),
    (set_key("detections", [[0, 0], [1, 2, 3]]), "'detections[1]'"),
    (set_key("detections", [[0, 0], [5000, 0]]), "'detections[1]'"),
    (set_key("noise_sd_m", 0), "'noise_sd_m'"),
    (set_key("gate_m", -1), "'gate_m'"),
    (set_key("gate_m", True), "'gate_m'"),
    (set_key("support_mass", 1.5), "'support_mass'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    assert_bad_key_named(associate.read_problem, tmp_path, _doc(), edit, key)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    assert_refuses_broken_json(associate.read_problem, tmp_path, "map")


@pytest.mark.parametrize("backend", ["auto", "greedy", "optimal"])
def test_solve_and_plan_json(tmp_path: Path, backend: str) -> None:
    """Each tracker takes the detection on it; the far one is new; the EMDs are road metres."""
    job = associate.read_problem(write_problem(tmp_path, _doc()))
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
