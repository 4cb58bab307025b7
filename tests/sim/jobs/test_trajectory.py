"""The trajectory plan family: PROBLEM.json read with named errors, flown clear of obstacles."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.result import Result, Sense, Status
from searchtrack.sim.flight.loop import FlightLog
from searchtrack.sim.jobs import trajectory
from searchtrack.sim.jobs.trajectory import TrajectoryProblem

EXAMPLE = Path(__file__).parents[3] / "examples" / "problems" / "trajectory.json"


@pytest.fixture(scope="module")
def problem() -> TrajectoryProblem:
    """The example problem."""
    return trajectory.read_problem(EXAMPLE)


@pytest.fixture(scope="module")
def flown(problem: TrajectoryProblem) -> Result[FlightLog]:
    """The example flown with the default controller."""
    return trajectory.solve(problem, backend="auto", time_limit_s=10.0, seed=0)


def _write(tmp_path: Path, doc: dict[str, Any]) -> Path:
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def _example() -> dict[str, Any]:
    doc: dict[str, Any] = json.loads(EXAMPLE.read_text(encoding="utf-8"))
    return doc


def test_module_interface() -> None:
    """The family exposes a description and the controllers, ``auto`` first."""
    assert trajectory.DESCRIPTION
    assert trajectory.backends()[0] == "auto"
    assert {"nmpc", "ltv_mpc", "closed_form"} <= set(trajectory.backends())


def test_example_reads(problem: TrajectoryProblem) -> None:
    """The example is a unicycle course around two obstacles, started from the named state."""
    assert problem.model.name == "unicycle"
    assert problem.waypoints_m.shape == (4, 2) and problem.obstacles.k == 2
    np.testing.assert_allclose(problem.start, [0.0, 0.0, 0.0])
    assert problem.duration_s == pytest.approx(problem.reference.duration_s)


def test_example_flies_clear_to_the_last_waypoint(problem: TrajectoryProblem,
                                                  flown: Result[FlightLog]) -> None:
    """The flight stays outside both obstacles and ends near the last waypoint."""
    assert flown.status is Status.FEASIBLE and flown.sense is Sense.MINIMIZE
    flight = flown.plan
    assert flight is not None and flight.collisions == 0
    pos = flight.states[:, :2]
    centre_dist = np.linalg.norm(pos[:, None, :] - problem.obstacles.centers_m[None, :, :2],
                                 axis=2)
    assert np.all(centre_dist >= problem.obstacles.radii_m[None, :])
    end = np.linalg.norm(pos[-1] - problem.waypoints_m[-1])
    assert end <= problem.goal_tolerance_m
    assert flown.objective == pytest.approx(flight.rms_error_m)
    assert flown.stats["steps"] == problem.steps


def test_plan_json_fields(problem: TrajectoryProblem, flown: Result[FlightLog]) -> None:
    """The plan lists times, states, inputs, the closest approach and controller counts."""
    plan = trajectory.plan_json(problem, flown)
    json.dumps(plan, allow_nan=False)
    steps = problem.steps
    assert len(plan["times_s"]) == len(plan["states"]) == steps + 1
    assert len(plan["inputs"]) == len(plan["controllers"]) == steps
    assert plan["state_names"] == ["x_m", "y_m", "heading_rad"]
    assert plan["input_names"] == ["speed_mps", "turn_rate_rps"]
    assert plan["closest_obstacle"] in (0, 1) and plan["min_clearance_m"] >= 0.0
    assert sum(plan["controller_steps"].values()) == steps
    assert plan["reached_goal"] is True and plan["collisions"] == 0
    assert plan["fallbacks"] == flown.stats["fallbacks"]


def test_figure_writes_png(problem: TrajectoryProblem, flown: Result[FlightLog],
                           tmp_path: Path) -> None:
    """The figure is a PNG file."""
    out = trajectory.figure(problem, flown, tmp_path / "plan.png")
    assert out is not None and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_closed_form_and_a_missed_goal(tmp_path: Path) -> None:
    """A course cut short by ``duration_s`` misses the last waypoint: NO_SOLUTION with the
    flight as a fallback."""
    doc = _example()
    doc["duration_s"] = 4.0
    problem = trajectory.read_problem(_write(tmp_path, doc))
    result = trajectory.solve(problem, backend="closed_form", time_limit_s=1.0, seed=0)
    assert result.status is Status.NO_SOLUTION and result.fallback is not None
    assert "missed the last waypoint" in result.message
    assert trajectory.plan_json(problem, result)["reached_goal"] is False


def test_default_start_and_3d_vehicle(tmp_path: Path) -> None:
    """Without ``start`` a fixed wing starts on the first waypoint heading along the first leg."""
    doc = {"vehicle": "fixed_wing", "waypoints": [[0, 0, 20], [0, 50, 20]], "speed_mps": 12}
    problem = trajectory.read_problem(_write(tmp_path, doc))
    np.testing.assert_allclose(problem.start, [0.0, 0.0, 20.0, math.pi / 2, 0.0])


def test_a_crash_is_no_solution(tmp_path: Path) -> None:
    """The uav7's closed-form law ignores obstacles: flying into a sphere on its course stops
    the flight there, reported as NO_SOLUTION with the flight as a fallback."""
    doc = {"vehicle": "uav7", "waypoints": [[0, 0, -50], [200, 0, -60]], "speed_mps": 15,
           "obstacles": [{"center": [100, 2, -55], "radius_m": 10, "cylinder": False}]}
    problem = trajectory.read_problem(_write(tmp_path, doc))
    assert not problem.obstacles.is_cylinder[0]
    result = trajectory.solve(problem, backend="closed_form", time_limit_s=1.0, seed=0)
    assert result.status is Status.NO_SOLUTION and "crashed" in result.message
    plan = trajectory.plan_json(problem, result)
    assert plan["collisions"] == 1 and plan["min_clearance_m"] < 0.0
    assert plan["reached_goal"] is False


def test_solve_rejects_an_unknown_backend(problem: TrajectoryProblem) -> None:
    """An unknown controller is an input error naming the backend."""
    with pytest.raises(InvalidInputError, match="backend"):
        trajectory.solve(problem, backend="magic", time_limit_s=1.0, seed=0)


def _set(doc: dict[str, Any], dotted: str, value: Any) -> None:
    """Set ``doc[a][i][b]`` for ``"a.i.b"`` (list indices as numbers)."""
    keys: list[Any] = [int(k) if k.isdigit() else k for k in dotted.split(".")]
    target: Any = doc
    for k in keys[:-1]:
        target = target[k]
    target[keys[-1]] = value


@pytest.mark.parametrize(("where", "value", "field"), [
    ("colour", "red", "colour"),
    ("vehicle", "submarine", "vehicle"),
    ("waypoints.2.1", math.nan, "waypoints[2]"),
    ("waypoints.1", [1, 2, 3], "waypoints[1]"),
    ("waypoints", [[0, 0]], "waypoints"),
    ("obstacles.1.radius_m", -2.0, "obstacles[1].radius_m"),
    ("obstacles.0.height", 3.0, "obstacles[0].height"),
    ("obstacles.0.center", [60], "obstacles[0].center"),
    ("start.x_m", 60.0, "start"),
    ("start.speed", 1.0, "start.speed"),
    ("start", [0, 0], "start"),
    ("speed_mps", 0.0, "speed_mps"),
    ("dt_s", "fast", "dt_s"),
    ("horizon", 0, "horizon"),
    ("waypoints.3", [60, 3], "waypoints[3]"),
])
def test_bad_inputs_name_the_key(tmp_path: Path, where: str, value: Any, field: str) -> None:
    """Each malformed field raises a ParseError naming the file and the dotted key."""
    doc = copy.deepcopy(_example())
    _set(doc, where, value)
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc, allow_nan=True), encoding="utf-8")
    with pytest.raises(ParseError) as info:
        trajectory.read_problem(path)
    assert info.value.field == field
    assert str(path) in str(info.value)


def test_not_json(tmp_path: Path) -> None:
    """A file that is not JSON names the line."""
    path = tmp_path / "problem.json"
    path.write_text("{\n  nope", encoding="utf-8")
    with pytest.raises(ParseError) as info:
        trajectory.read_problem(path)
    assert info.value.line == 2
