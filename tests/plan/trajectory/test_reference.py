"""References: sampled paths interpolated and held, waypoint polylines flown at constant speed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.trajectory import SampledPath, waypoint_path


def test_waypoint_path_is_flown_at_constant_speed_and_held() -> None:
    """waypoint_path reaches each corner at arc length / speed and holds the last point."""
    ref = waypoint_path([[0, 0], [10, 0], [10, 10]], 5.0)
    assert ref.duration_s == pytest.approx(4.0)
    np.testing.assert_allclose(ref.positions([1.0, 2.0, 3.0, 9.0]),
                               [[5, 0], [10, 0], [10, 5], [10, 10]])
    with pytest.raises(InvalidInputError, match="speed_mps"):
        waypoint_path([[0, 0], [1, 1]], 0.0)
    with pytest.raises(InvalidInputError, match="times_s"):
        SampledPath(times_s=np.array([0.0, 0.0]), positions_m=np.zeros((2, 2)))


def test_sampled_path_interpolates_and_holds_both_ends() -> None:
    """Between samples positions are linear in time; before the first and after the last
    sample the end points are held."""
    path = SampledPath(times_s=np.array([1.0, 3.0]), positions_m=np.array([[0.0, 0.0, 10.0],
                                                                           [4.0, -2.0, 20.0]]))
    assert path.dim == 3 and path.duration_s == 3.0
    np.testing.assert_allclose(path.positions([0.0, 1.0, 1.5, 2.0, 3.0, 7.0]),
                               [[0, 0, 10], [0, 0, 10], [1, -0.5, 12.5], [2, -1, 15],
                                [4, -2, 20], [4, -2, 20]])
    np.testing.assert_allclose(path.positions(2.0), [[2, -1, 15]])  # a scalar time is one row


def test_a_single_sample_is_a_fixed_point() -> None:
    """One sample gives a reference that stays there at every time."""
    path = SampledPath(times_s=np.array([5.0]), positions_m=np.array([[1.0, 2.0]]))
    np.testing.assert_allclose(path.positions([0.0, 5.0, 100.0]), [[1, 2]] * 3)


@pytest.mark.parametrize(("times", "positions", "field"), [
    ([0.0, 2.0, 1.0], np.zeros((3, 2)), "times_s"),
    ([], np.zeros((0, 2)), "times_s"),
    ([0.0, math.nan], np.zeros((2, 2)), "times_s"),
    ([0.0, 1.0], np.zeros((3, 2)), "positions_m"),
    ([0.0, 1.0], np.zeros((2, 4)), "positions_m"),
    ([0.0, 1.0], np.array([[0.0, 0.0], [math.inf, 0.0]]), "positions_m")])
def test_bad_samples_name_the_field(times: list[float], positions: np.ndarray, field: str
                                    ) -> None:
    """Unordered, empty or non-finite times and positions of the wrong shape are refused."""
    with pytest.raises(InvalidInputError) as info:
        SampledPath(times_s=np.array(times), positions_m=positions)
    assert info.value.field == field


def test_waypoint_path_starts_late_and_drops_repeated_points() -> None:
    """A repeated waypoint adds no sample; the 3-4-5 leg of 5 m at 2 m/s from t = 10 s ends at
    12.5 s."""
    ref = waypoint_path([[0, 0, 1], [0, 0, 1], [3, 4, 1]], 2.0, start_time_s=10.0)
    np.testing.assert_allclose(ref.times_s, [10.0, 12.5])
    np.testing.assert_allclose(ref.positions([11.25]), [[1.5, 2.0, 1.0]])
    assert ref.dim == 3 and ref.duration_s == 12.5


@pytest.mark.parametrize(("args", "field"), [
    (([0.0, 1.0], 1.0), "waypoints_m"), (([], 1.0), "waypoints_m"),
    (([[0, 0], [math.nan, 1]], 1.0), "waypoints_m"), (([[0, 0], [1, 1]], -3.0), "speed_mps")])
def test_bad_waypoints_name_the_field(args: tuple[object, float], field: str) -> None:
    """A flat list, no waypoints, NaN or a negative speed each name their field."""
    with pytest.raises(InvalidInputError) as info:
        waypoint_path(*args)  # type: ignore[arg-type]
    assert info.value.field == field


def test_bad_start_time_names_the_field() -> None:
    """A non-finite start time is refused by name."""
    with pytest.raises(InvalidInputError, match="start_time_s"):
        waypoint_path([[0, 0], [1, 0]], 1.0, start_time_s=math.inf)
