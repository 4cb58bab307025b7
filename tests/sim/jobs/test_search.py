"""The ``search`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.search import CentreProbability, EmptyHorizonMI, NoRefinement
from searchtrack.sim.jobs import search
from tests.sim.jobs.helpers import (
    assert_bad_key_named,
    assert_refuses_broken_json,
    drop,
    set_key,
    write_problem,
)

EXAMPLE = Path(__file__).parents[3] / "examples" / "problems" / "search.json"


def _doc() -> dict[str, Any]:
    """A UAV in the middle of a 120 m box, one centre 12 m east of it, one-step horizon."""
    return {
        "uav": [60, 60, 60],
        "bounds": [[0, 120], [0, 120], [0, 120]],
        "belief": {"positions": [[72, 60, 60], [60, 72, 60]], "weights": [1.0, 0.5]},
        "centres": [[72, 60, 60]],
        "sensor": {"peak_pd": 0.98, "scale_xy_m": 25.0, "scale_z_m": 25.0},
        "exploration": {"resolution_m": 20.0, "visited": [[60, 60, 60]]},
        "settings": {"horizon": 1, "alpha": 1.0, "refinement": "centre", "step_m": 12.0,
                     "dims": 3, "lawnmower_spacing_m": 48.0},
    }


def test_reads_the_example() -> None:
    """The shipped example: 100 particles, two centres, four poses visited, horizon 2."""
    job = search.read_problem(EXAMPLE)
    prob = job.problem
    assert job.name == "search" and prob.belief is not None
    assert prob.belief.positions.shape == (100, 3) and prob.centres is not None
    assert prob.centres.shape == (2, 3) and job.visited.shape == (4, 3)
    assert prob.settings.horizon == 2 and isinstance(prob.settings.refinement, CentreProbability)
    assert float(prob.bonus.values.min()) < 0.1  # the visited poses lowered the bonus


def test_optional_fields_default(tmp_path: Path) -> None:
    """Without centres, exploration and settings: no centres, a fresh bonus, the defaults; the
    refinement names read."""
    doc = _doc()
    del doc["centres"], doc["exploration"], doc["settings"]
    job = search.read_problem(write_problem(tmp_path, doc))
    prob = job.problem
    assert prob.centres is not None and prob.centres.shape == (0, 3)
    assert job.visited.shape == (0, 3) and np.all(prob.bonus.values == 1.0)
    assert prob.settings.horizon == 1 and prob.settings.alpha == 1.0
    assert prob.settings.dims == 3 and isinstance(prob.settings.refinement, CentreProbability)
    for name, kind in (("mi", EmptyHorizonMI), ("none", NoRefinement)):
        doc["settings"] = {"refinement": name}
        job = search.read_problem(write_problem(tmp_path, doc))
        assert isinstance(job.problem.settings.refinement, kind)


BAD = [
    (drop("uav"), "'uav'"),
    (drop("bounds"), "'bounds'"),
    (drop("belief"), "'belief'"),
    (drop("sensor"), "'sensor'"),
    (drop("belief.positions"), "'belief.positions'"),
    (drop("sensor.peak_pd"), "'sensor.peak_pd'"),
    (set_key("extra", 1), "'extra'"),
    (set_key("settings.tau", 1), "'settings.tau'"),
    (set_key("exploration.grid", 1), "'exploration.grid'"),
    (set_key("uav", [60, 60]), "'uav'"),
    (set_key("uav", [60, 60, "high"]), "'uav[2]'"),
    (set_key("uav", [60, 60, 200]), "'uav'"),
    (set_key("bounds", [[0, 120], [0, 120]]), "'bounds'"),
    (set_key("bounds", [[0, 120], [0, 120], [50, 10]]), "'bounds[2]'"),
    (set_key("bounds", [[0, 120], [0, 120], [0, None]]), "'bounds[2][1]'"),
    (set_key("belief.weights", [1.0, -1.0]), "'belief.weights[1]'"),
    (set_key("belief.weights", [1.0]), "'belief.weights'"),
    (set_key("centres", [[1, 2]]), "'centres[0]'"),
    (set_key("centres", 3), "'centres'"),
    (set_key("sensor.scale_xy_m", 0), "'sensor.scale_xy_m'"),
    (set_key("exploration.resolution_m", 0), "'exploration.resolution_m'"),
    (set_key("exploration.resolution_m", 0.01), "'exploration.resolution_m'"),
    (set_key("exploration.visited", [[1, 2, "x"]]), "'exploration.visited[0][2]'"),
    (set_key("settings.horizon", 0), "'settings.horizon'"),
    (set_key("settings.horizon", 2.5), "'settings.horizon'"),
    (set_key("settings.alpha", -1), "'settings.alpha'"),
    (set_key("settings.refinement", "max"), "'settings.refinement'"),
    (set_key("settings.dims", 4), "'settings.dims'"),
    (set_key("settings.step_m", 0), "'settings.step_m'"),
    (set_key("settings.lawnmower_spacing_m", True), "'settings.lawnmower_spacing_m'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    assert_bad_key_named(search.read_problem, tmp_path, _doc(), edit, key)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    assert_refuses_broken_json(search.read_problem, tmp_path, "uav")


def test_solve_and_plan_json(tmp_path: Path) -> None:
    """The receding planner flies to the centre (+x first); plan_json splits the score."""
    job = search.read_problem(write_problem(tmp_path, _doc()))
    assert search.backends() == ["auto", "receding", "lawnmower"]
    result = search.solve(job, backend="auto", time_limit_s=5.0, seed=0)
    assert result.status is Status.OPTIMAL and result.message.startswith("auto: ")
    plan = search.plan_json(job, result)
    assert plan["refinement"] == "centre" and plan["candidates"] == 6
    assert np.allclose(plan["waypoint"], [72, 60, 60]) and np.allclose(plan["sequence"],
                                                                        [[72, 60, 60]])
    score = plan["score"]
    assert score["refinement"] == pytest.approx(0.98)
    assert score["total"] == pytest.approx(score["alpha"] * score["exploration"]
                                           + score["refinement"])
    assert result.objective == pytest.approx(score["total"])
    json.dumps(plan)


def test_mi_refinement_and_lawnmower(tmp_path: Path) -> None:
    """The MI refinement solves on the belief; the lawnmower answers FEASIBLE."""
    doc = _doc()
    doc["settings"] = {"refinement": "mi", "horizon": 2}
    job = search.read_problem(write_problem(tmp_path, doc))
    result = search.solve(job, backend="receding", time_limit_s=5.0, seed=0)
    assert result.status is Status.OPTIMAL and result.plan is not None
    assert search.plan_json(job, result)["score"]["refinement"] > 0.0
    mower = search.solve(job, backend="lawnmower", time_limit_s=5.0, seed=0)
    assert mower.status is Status.FEASIBLE
    assert len(search.plan_json(job, mower)["sequence"]) == 2


def test_example_solves_and_draws(tmp_path: Path) -> None:
    """The example solves to optimality under auto, and the figure is a PNG."""
    job = search.read_problem(EXAMPLE)
    result = search.solve(job, backend="auto", time_limit_s=10.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective is not None
    assert len(search.plan_json(job, result)["sequence"]) == 2
    png = search.figure(job, result, tmp_path / "plan.png")
    assert png is not None and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
