"""The UAV: turn-rate-limited flight, action primitives in the area, the straight sweep."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio.uav import (
    UavModel,
    fly_heading,
    primitive_headings,
    primitives,
    straight_sweep_heading,
)

UAV = UavModel()
AREA = (1500.0, 1500.0)


def _steps(pose: np.ndarray, path: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    full = np.vstack([pose, path])
    lengths = np.hypot(*np.diff(full[:, :2], axis=0).T)
    turns = np.abs(wrap_angle(np.diff(full[:, 2])))
    return lengths, turns


@pytest.mark.parametrize("target", [-3 * math.pi / 4, 0.0, math.pi / 4, math.pi, 2.0])
def test_fly_heading_keeps_speed_and_turn_rate(target: float) -> None:
    """Every step is speed·step_s long, turns at most max_turn_rate·step_s, then holds."""
    pose = UAV.start_pose
    path = fly_heading(UAV, pose, target, 12.0)
    assert path.shape == (12, 3)
    lengths, turns = _steps(pose, path)
    np.testing.assert_allclose(lengths, 20.0, rtol=1e-12)
    assert turns.max() <= math.pi / 3 + 1e-12
    assert abs(wrap_angle(path[-1, 2] - target)) < 1e-12
    assert np.all((path[:, 2] >= -math.pi) & (path[:, 2] < math.pi))


def test_turns_the_shortest_way_and_reaches_the_heading_at_the_max_rate() -> None:
    """From heading 0 to −π/2 in steps of π/6 (half-second steps): clockwise, then straight."""
    model = UavModel(step_s=0.5, plan_interval_s=2.0)
    path = fly_heading(model, [0.0, 0.0, 0.0], -math.pi / 2, 2.0)
    assert path.shape == (4, 3)
    np.testing.assert_allclose(path[:, 2], [-math.pi / 6, -math.pi / 3, -math.pi / 2,
                                            -math.pi / 2])
    assert np.all(path[:, 1] < 0)  # it went clockwise (south)
    np.testing.assert_allclose(path[-1, :2] - path[-2, :2], [0.0, -10.0], atol=1e-12)
    assert fly_heading(UAV, UAV.start_pose, 0.0, 0.2).shape == (0, 3)


def test_primitive_headings_are_evenly_spaced_around_the_heading() -> None:
    """θ + Δ_i with Δ_i = −π + 2πi/N_θ: includes straight on and straight back."""
    heads = primitive_headings(UAV, 0.3)
    assert heads.shape == (8,)
    np.testing.assert_allclose(wrap_angle(heads - 0.3), -np.pi + 2 * np.pi * np.arange(8) / 8,
                               atol=1e-12)
    assert primitive_headings(UavModel(n_headings=3), 0.0).shape == (3,)


def test_primitives_drop_paths_that_leave_the_area() -> None:
    """From the start corner only the primitives that stay in [0, W] × [0, H] are kept."""
    headings, paths = primitives(UAV, UAV.start_pose, AREA)
    assert paths.shape == (headings.size, 5, 3)
    assert 0 < headings.size < 8
    assert np.all((paths[..., :2] >= 0.0) & (paths[..., :2] <= 1500.0))
    dropped = np.setdiff1d(np.round(primitive_headings(UAV, math.pi / 4), 12),
                           np.round(headings, 12))
    for h in dropped:
        out = fly_heading(UAV, UAV.start_pose, float(h), 5.0)
        assert np.any((out[:, :2] < 0.0) | (out[:, :2] > 1500.0))
    centre = primitives(UAV, [750.0, 750.0, 0.0], AREA)[0]
    assert centre.size == 8


def test_when_all_leave_those_ending_nearest_are_kept() -> None:
    """Outside the area every primitive leaves it: those ending nearest to it are kept, and
    flying them brings the UAV back in."""
    headings, paths = primitives(UAV, [-500.0, -500.0, 1.0], AREA)
    assert 1 <= headings.size < 8 and paths.shape == (headings.size, 5, 3)
    every = [fly_heading(UAV, [-500.0, -500.0, 1.0], float(h), 5.0)[-1, :2]
             for h in primitive_headings(UAV, 1.0)]
    nearest = min(float(np.hypot(*np.maximum(0.0, -p))) for p in every)
    assert float(np.hypot(*np.maximum(0.0, -paths[0, -1, :2]))) <= nearest + 1.0
    pose = np.array([750.0, 1495.0, math.pi / 2])           # at the top edge, heading out
    for _ in range(6):
        pose = primitives(UAV, pose, AREA)[1][0, -1]
    assert 0.0 <= pose[1] <= 1500.0


def test_straight_sweep_alternates_corners() -> None:
    """Flying the sweep heading second by second visits (W, H), (0, 0), (W, H) in turn."""
    area = (600.0, 400.0)
    pose = UAV.start_pose
    assert straight_sweep_heading(UAV, pose, area) == pytest.approx(math.atan2(400, 600))
    visits = [1]  # it starts at (0, 0)
    for _ in range(220):
        heading = straight_sweep_heading(UAV, pose, area)
        pose = fly_heading(UAV, pose, heading, 1.0)[-1]
        for corner, xy in enumerate(((600.0, 400.0), (0.0, 0.0))):
            if math.hypot(pose[0] - xy[0], pose[1] - xy[1]) < 30.0 and (
                    not visits or visits[-1] != corner):
                visits.append(corner)
    assert visits[:6] == [1, 0, 1, 0, 1, 0]


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"speed_mps": 0.0}, "speed_mps"),
    ({"max_turn_rate": -1.0}, "max_turn_rate"),
    ({"start_xy": (0.0, math.nan)}, "start_xy"),
    ({"start_heading": math.inf}, "start_heading"),
    ({"n_headings": 0}, "n_headings"),
    ({"plan_interval_s": 0.2}, "plan_interval_s"),
    ({"step_s": math.nan}, "step_s"),
])
def test_bad_model_names_the_field(kwargs: dict[str, object], field: str) -> None:
    """Bad parameters raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        UavModel(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_calls_name_the_argument() -> None:
    """Bad poses, areas and durations raise InvalidInputError."""
    with pytest.raises(InvalidInputError, match="pose"):
        fly_heading(UAV, [0.0, 0.0], 0.0, 5.0)
    with pytest.raises(InvalidInputError, match="duration_s"):
        fly_heading(UAV, UAV.start_pose, 0.0, -1.0)
    with pytest.raises(InvalidInputError, match="target_heading"):
        fly_heading(UAV, UAV.start_pose, math.nan, 1.0)
    with pytest.raises(InvalidInputError, match="area_m"):
        primitives(UAV, UAV.start_pose, (1500.0, 0.0))
    with pytest.raises(InvalidInputError, match="area_m"):
        straight_sweep_heading(UAV, UAV.start_pose, (1500.0,))
