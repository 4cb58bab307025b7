"""The ``route`` plan family: PROBLEM.json read with every bad key named, solved, written."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.sim.jobs import route
from tests.sim.jobs.helpers import (
    assert_bad_key_named,
    assert_refuses_broken_json,
    drop,
    set_key,
    write_problem,
)

EXAMPLE = Path(__file__).parents[3] / "examples" / "problems" / "route.json"


def _doc() -> dict[str, Any]:
    """A 3 × 3 grid; the UAV at node 0 reaches node 2 (0, 200) or node 6 (200, 0), not both."""
    return {
        "map": {"grid": [3, 3], "spacing_m": 100},
        "uav": {"start_node": 0, "speed_mps": 10},
        "horizon_s": 25,
        "trackers": [{"nodes": [2], "masses": [3.0]},
                     {"nodes": [6], "masses": [1.0], "weight": 0.5}],
        "max_nodes": 10,
        "support_mass": 1.0,
    }


def test_reads_the_example() -> None:
    """The shipped example: a 6 × 6 grid, three trackers of mass 1, 1 and 0.5."""
    job = route.read_problem(EXAMPLE)
    assert job.name == "route" and job.network.n_nodes == 36 and job.start_node == 0
    assert np.allclose(job.trackers.sum(axis=1), [1.0, 1.0, 0.5])
    assert job.node_ids[0] == -1 and 1 < job.instance.n <= 26
    assert job.instance.to_time(job.instance.latest_finish) == 60.0


def test_peak_spread_and_defaults(tmp_path: Path) -> None:
    """A peak tracker is a normalised Gaussian around its node; optional keys default."""
    doc = _doc()
    doc["trackers"] = [{"peak_node": 4, "spread_m": 50}]
    del doc["max_nodes"], doc["support_mass"]
    job = route.read_problem(write_problem(tmp_path, doc))
    p = job.trackers[0]
    assert p.sum() == pytest.approx(1.0) and int(np.argmax(p)) == 4
    assert p[1] == pytest.approx(p[3]) and p[0] < p[1]
    assert set(job.node_ids[1:].tolist()) <= set(range(9))


def _tracker(i: int, **changes: Any) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        doc["trackers"][i].update(changes)
    return edit


BAD = [
    (drop("map"), "'map'"),
    (drop("uav"), "'uav'"),
    (drop("horizon_s"), "'horizon_s'"),
    (drop("trackers"), "'trackers'"),
    (drop("uav.speed_mps"), "'uav.speed_mps'"),
    (drop("uav.start_node"), "'uav.start_node'"),
    (set_key("extra", 1), "'extra'"),
    (set_key("uav.heading", 1), "'uav.heading'"),
    (set_key("map", {"grid": [3, 1], "spacing_m": 100}), "'map.grid[1]'"),
    (set_key("map", {"osm": "Atlantis"}), "'map.osm'"),
    (set_key("uav.start_node", 9), "'uav.start_node'"),
    (set_key("uav.speed_mps", 0), "'uav.speed_mps'"),
    (set_key("horizon_s", -5), "'horizon_s'"),
    (set_key("trackers", []), "'trackers'"),
    (_tracker(0, color="red"), "'trackers[0].color'"),
    (_tracker(1, nodes=[6, 42], masses=[1, 1]), "'trackers[1].nodes[1]'"),
    (_tracker(1, masses=[1.0, 2.0]), "'trackers[1].masses'"),
    (_tracker(0, masses=[-1.0]), "'trackers[0].masses[0]'"),
    (_tracker(0, masses=[0]), "'trackers[0].masses'"),
    (_tracker(1, weight=0), "'trackers[1].weight'"),
    (_tracker(0, peak_node=4), "'trackers[0]'"),
    (set_key("trackers", [{"peak_node": 4}]), "'trackers[0].spread_m'"),
    (set_key("trackers", [{"peak_node": 4, "spread_m": 0}]), "'trackers[0].spread_m'"),
    (set_key("trackers", [{"peak_node": 4, "spread_m": 9, "masses": [1]}]),
     "'trackers[0].masses'"),
    (set_key("max_nodes", 0), "'max_nodes'"),
    (set_key("support_mass", 1.5), "'support_mass'"),
]


@pytest.mark.parametrize(("edit", "key"), BAD)
def test_bad_key_is_named(tmp_path: Path, edit: Any, key: str) -> None:
    """Every malformed field raises a ParseError naming the file and the dotted key."""
    assert_bad_key_named(route.read_problem, tmp_path, _doc(), edit, key)


def test_not_json_or_not_an_object(tmp_path: Path) -> None:
    """Broken JSON names the line; a top-level list is refused."""
    assert_refuses_broken_json(route.read_problem, tmp_path, "uav")


def test_solve_and_plan_json(tmp_path: Path) -> None:
    """The exact labelling backend flies to the heavier tracker; plan_json reports the route,
    its times and the profit per tracker."""
    job = route.read_problem(write_problem(tmp_path, _doc()))
    assert route.backends()[0] == "auto" and "labelling" in route.backends()
    result = route.solve(job, backend="labelling", time_limit_s=5.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective == pytest.approx(1.0)
    plan = route.plan_json(job, result)
    assert plan["nodes"] == [0, 2] and plan["xy"] == [[0.0, 0.0], [0.0, 200.0]]
    assert plan["times_s"] == [0.0, 20.0] and plan["finish_s"] == 20.0
    assert plan["horizon_s"] == 25.0 and plan["candidates"] == 2
    assert plan["tracker_profit"] == [1.0, 0.0] and plan["profit"] == 1.0
    json.dumps(plan)


def test_example_solves_and_draws(tmp_path: Path) -> None:
    """The example solves to optimality under auto, every tracker collects, the figure is a PNG."""
    job = route.read_problem(EXAMPLE)
    result = route.solve(job, backend="auto", time_limit_s=10.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective is not None
    plan = route.plan_json(job, result)
    assert plan["profit"] == pytest.approx(result.objective)
    assert all(p > 0 for p in plan["tracker_profit"]) and plan["finish_s"] <= 60.0
    assert np.all(np.diff(plan["times_s"]) > 0)
    png = route.figure(job, result, tmp_path / "plan.png")
    assert png is not None and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
