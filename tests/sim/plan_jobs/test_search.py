"""The ``search`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import ParseError
from searchtrack.core.result import Status
from searchtrack.plan.search import CentreProbability, EmptyHorizonMI, NoRefinement
from searchtrack.sim.plan_jobs import search

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


def _write(tmp_path: Path, doc: Any) -> Path:
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


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
    job = search.read_problem(_write(tmp_path, doc))
    prob = job.problem
    assert prob.centres is not None and prob.centres.shape == (0, 3)
    assert job.visited.shape == (0, 3) and np.all(prob.bonus.values == 1.0)
    assert prob.settings.horizon == 1 and prob.settings.alpha == 1.0
    assert prob.settings.dims == 3 and isinstance(prob.settings.refinement, CentreProbability)
    for name, kind in (("mi", EmptyHorizonMI), ("none", NoRefinement)):
        doc["settings"] = {"refinement": name}
        assert isinstance(search.read_problem(_write(tmp_path, doc)).problem.settings.refinement,
                          kind)


def _drop(key: str) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        *parents, last = key.split(".")
        target = doc
        for p in parents:
            target = target[p]
        del target[last]
    return edit


def _set(key: str, value: Any) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        *parents, last = key.split(".")
        target = doc
        for p in parents:
            target = target[p]
        target[last] = value
    return edit


BAD = [
    (_drop("uav"), "'uav'"),
    (_drop("bounds"), "'bounds'"),
    (_drop("belief"), "'belief'"),
    (_drop("sensor"), "'sensor'"),
    (_drop("belief.positions"), "'belief.positions'"),
    (_drop("sensor.peak_pd"), "'sensor.peak_pd'"),
    (_set("extra", 1), "'extra'"),
    (_set("settings.tau", 1), "'settings.tau'"),
    (_set("exploration.grid", 1), "'exploration.grid'"),
    (_set("uav", [60, 60]), "'uav'"),
    (_set("uav", [60, 60, "high"]), "'uav[2]'"),
    (_set("uav", [60, 60, 200]), "'uav'"),
    (_set("bounds", [[0, 120], [0, 120]]), "'bounds'"),
    (_set("bounds", [[0, 120], [0, 120], [50, 10]]), "'bounds[2]'"),
    (_set("bounds", [[0, 120], [0, 120], [0, None]]), "'bounds[2][1]'"),
    (_set("belief.weights", [1.0, -1.0]), "'belief.weights[1]'"),
    (_set("belief.weights", [1.0]), "'belief.weights'"),
    (_set("centres", [[1, 2]]), "'centres[0]'"),
    (_set("centres", 3), "'centres'"),
    (_set("sensor.scale_xy_m", 0), "'sensor.scale_xy_m'"),
    (_set("exploration.resolution_m", 0), "'exploration.resolution_m'"),
    (_set("exploration.resolution_m", 0.01), "'exploration.resolution_m'"),
    (_set("exploration.visited", [[1, 2, "x"]]), "'exploration.visited[0][2]'"),
    (_set("settings.horizon", 0), "'settings.horizon'"),
    (_set("settings.horizon", 2.5), "'settings.horizon'"),
    (_set("settings.alpha", -1), "'settings.alpha'"),
    (_set("settings.refinement", "max"), "'settings.refinement'"),
    (_set("settings.dims", 4), "'settings.dims'"),
    (_set("settings.step_m", 0), "'settings.step_m'"),
    (_set("settings.lawnmower_spacing_m", True), "'settings.lawnmower_spacing_m'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    doc = copy.deepcopy(_doc())
    edit(doc)
    with pytest.raises(ParseError, match=key.replace("[", r"\[").replace("]", r"\]")) as info:
        search.read_problem(_write(tmp_path, doc))
    assert "problem.json" in str(info.value)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    path = tmp_path / "problem.json"
    path.write_text("{\n  \"uav\": ,\n}", encoding="utf-8")
    with pytest.raises(ParseError, match="line 2"):
        search.read_problem(path)
    with pytest.raises(ParseError, match="JSON object"):
        search.read_problem(_write(tmp_path, [1, 2]))


def test_solve_and_plan_json(tmp_path: Path) -> None:
    """The receding planner flies to the centre (+x first); plan_json splits the score."""
    job = search.read_problem(_write(tmp_path, _doc()))
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
    job = search.read_problem(_write(tmp_path, doc))
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
