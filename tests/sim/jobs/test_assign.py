"""The ``assign`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.assign import ExpectedDetections, MutualInformation
from searchtrack.sim.jobs import assign
from tests.sim.jobs.helpers import (
    assert_bad_key_named,
    assert_refuses_broken_json,
    drop,
    set_key,
    write_problem,
)

EXAMPLE = Path(__file__).parents[3] / "examples" / "problems" / "assign.json"


def _doc() -> dict[str, Any]:
    """Two UAVs, two one-step actions each, three particles under the second actions."""
    return {
        "uavs": [[0, 0, 20], [50, 0, 20]],
        "actions": [[[[0, 10, 20]], [[0, 40, 20]]], [[[50, 10, 20]], [[50, 40, 20]]]],
        "belief": {"positions": [[0, 40], [50, 40], [25, 40]], "weights": [1.0, 1.0, 0.5]},
        "sensor": {"peak_pd": 0.9, "scale_xy_m": 5.0, "scale_z_m": 30.0},
        "objective": "end",
        "min_separation_m": 0,
    }


def test_reads_the_example() -> None:
    """The shipped example has 3 UAVs, 4-5 actions each and 200 particles."""
    job = assign.read_problem(EXAMPLE)
    prob = job.problem
    assert job.name == "assign" and prob.robots == 3
    assert [prob.n_actions(r) for r in range(3)] == [5, 4, 5]
    assert prob.positions.shape == (200, 2)
    assert isinstance(prob.objective, ExpectedDetections) and prob.min_separation_m == 5.0


def test_optional_fields_default(tmp_path: Path) -> None:
    """Without objective and min_separation_m the problem is END without separation; mi reads."""
    doc = _doc()
    del doc["objective"], doc["min_separation_m"]
    prob = assign.read_problem(write_problem(tmp_path, doc)).problem
    assert isinstance(prob.objective, ExpectedDetections) and prob.min_separation_m == 0.0
    doc["objective"] = "mi"
    assert isinstance(assign.read_problem(write_problem(tmp_path, doc)).problem.objective,
                      MutualInformation)


def _set_pose(r: int, a: int, value: Any) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        doc["actions"][r][a] = value
    return edit


BAD = [
    (drop("uavs"), "'uavs'"),
    (drop("actions"), "'actions'"),
    (drop("belief"), "'belief'"),
    (drop("sensor"), "'sensor'"),
    (drop("belief.weights"), "'belief.weights'"),
    (drop("sensor.scale_z_m"), "'sensor.scale_z_m'"),
    (set_key("extra", 1), "'extra'"),
    (set_key("sensor.fov", 1), "'sensor.fov'"),
    (set_key("uavs", [[0, 0]]), "'uavs[0]'"),
    (set_key("uavs", []), "'uavs'"),
    (set_key("actions", [[]]), "'actions'"),
    (_set_pose(1, 0, [[50, 10, "high"]]), "'actions[1][0][0][2]'"),
    (_set_pose(1, 1, [[50, 10, 20], [50, 20, 20]]), "'actions[1][1]'"),
    (set_key("belief.positions", [[0, 40], [1, 2, 3], [4, 5]]), "'belief.positions[1]'"),
    (set_key("belief.weights", [1.0, -1.0, 0.5]), "'belief.weights[1]'"),
    (set_key("belief.weights", [1.0]), "'belief.weights'"),
    (set_key("sensor.peak_pd", 1.5), "'sensor.peak_pd'"),
    (set_key("sensor.scale_xy_m", 0), "'sensor.scale_xy_m'"),
    (set_key("objective", "max"), "'objective'"),
    (set_key("min_separation_m", -1), "'min_separation_m'"),
    (set_key("min_separation_m", True), "'min_separation_m'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    assert_bad_key_named(assign.read_problem, tmp_path, _doc(), edit, key)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    assert_refuses_broken_json(assign.read_problem, tmp_path, "uavs")


def test_solve_and_plan_json(tmp_path: Path) -> None:
    """The exact backend picks the actions over the particles; plan_json reports them."""
    job = assign.read_problem(write_problem(tmp_path, _doc()))
    assert assign.backends()[0] == "auto" and "greedy" in assign.backends()
    result = assign.solve(job, backend="exact_bnb", time_limit_s=5.0, seed=0)
    assert result.status is Status.OPTIMAL
    plan = assign.plan_json(job, result)
    assert plan["objective"] == "end" and plan["actions"] == [1, 1]
    assert np.allclose(plan["poses"], [[[0, 40, 20]], [[50, 40, 20]]])
    json.dumps(plan)


def test_example_solves_and_draws(tmp_path: Path) -> None:
    """The example solves to optimality under auto, and the figure is a PNG."""
    job = assign.read_problem(EXAMPLE)
    result = assign.solve(job, backend="auto", time_limit_s=10.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective is not None
    assert len(assign.plan_json(job, result)["actions"]) == 3
    png = assign.figure(job, result, tmp_path / "plan.png")
    assert png is not None and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
