"""Obstacles: signed distances of spheres and cylinders, clearance, start checks, solver rows."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.trajectory import Obstacles


def test_sphere_and_cylinder_distances() -> None:
    """A sphere measures 3-D distance, a vertical cylinder only the horizontal one."""
    obs = Obstacles(centers_m=[[0, 0, 0], [0, 0, 0]], radii_m=[1, 1],
                    cylinder=np.array([False, True]))
    d = obs.distance_m([[0, 0, 5]])
    np.testing.assert_allclose(d, [[4.0, -1.0]])
    np.testing.assert_allclose(obs.distance_m([[3, 4]]), [[4.0, 4.0]])
    assert Obstacles().clearance_m([[1, 2]])[0] == math.inf
    assert obs.parameters(2, 0.5)[:, 4].tolist() == [0.0, 0.0]  # planar: all cylinders


def test_obstacle_bad_input() -> None:
    """Non-positive radii, ragged centres and wrong flag counts are rejected."""
    with pytest.raises(InvalidInputError, match="radii_m"):
        Obstacles(centers_m=[[0, 0, 0]], radii_m=[0.0])
    with pytest.raises(InvalidInputError, match="centers_m"):
        Obstacles(centers_m=[[0, 0, 0, 0]], radii_m=[1.0])
    with pytest.raises(InvalidInputError, match="cylinder"):
        Obstacles(centers_m=[[0, 0, 0]], radii_m=[1.0], cylinder=np.array([True, False]))


def test_planar_centres_are_padded_and_arrays_read_only() -> None:
    """(k, 2) centres get z = 0, flags default to cylinders, and the arrays cannot be written."""
    obs = Obstacles(centers_m=[[1, 2], [3, 4]], radii_m=[1.0, 2.0])
    np.testing.assert_array_equal(obs.centers_m, [[1, 2, 0], [3, 4, 0]])
    assert obs.k == 2 and obs.is_cylinder.tolist() == [True, True]
    for arr in (obs.centers_m, obs.radii_m, obs.is_cylinder):
        with pytest.raises(ValueError):
            arr[0] = 0


def test_distances_of_several_points_to_several_obstacles() -> None:
    """Rows are points, columns obstacles: |p − c| − r by hand (3-4-5 and 5-12-13 triangles)."""
    obs = Obstacles(centers_m=[[0, 0, 0], [10, 0, 0]], radii_m=[2.0, 1.0],
                    cylinder=np.array([True, False]))
    pts = [[3, 4, 0], [10, 5, 12], [0, 0, 7]]
    expected = [[5 - 2, math.hypot(7, 4) - 1],
                [math.hypot(10, 5) - 2, 13 - 1],
                [0 - 2, math.sqrt(100 + 49) - 1]]
    np.testing.assert_allclose(obs.distance_m(pts), expected)
    np.testing.assert_allclose(obs.clearance_m(pts), [3.0, math.hypot(10, 5) - 2, -2.0])


def test_planar_points_ignore_height_even_for_spheres() -> None:
    """A 2-D point sees a sphere as a vertical cylinder of its radius."""
    obs = Obstacles(centers_m=[[0, 0, 50]], radii_m=[1.0], cylinder=np.array([False]))
    np.testing.assert_allclose(obs.distance_m([[0, 3]]), [[2.0]])


def test_bad_points_name_the_field() -> None:
    """Points must be (n, 2) or (n, 3)."""
    with pytest.raises(InvalidInputError, match="points_m"):
        Obstacles().distance_m([[1, 2, 3, 4]])


def test_check_outside_names_field_and_obstacle() -> None:
    """A point inside or on an obstacle is an error naming the caller's field and obstacle j;
    a point just outside, or any point with no obstacles, passes."""
    obs = Obstacles(centers_m=[[50, 0], [0, 0]], radii_m=[1.0, 2.0])
    with pytest.raises(InvalidInputError, match="inside obstacle 1") as info:
        obs.check_outside("start", [1.0, 0.0])
    assert info.value.field == "start"
    with pytest.raises(InvalidInputError, match="inside obstacle 1"):
        obs.check_outside("start", [2.0, 0.0])  # on the surface counts as inside
    obs.check_outside("start", [2.001, 0.0])
    Obstacles().check_outside("start", [0.0, 0.0])


def test_solver_rows_add_the_margin_and_flag_spheres_in_3d() -> None:
    """parameters(3, m) gives (c_x, c_y, c_z, r + m, 1 for a sphere / 0 for a cylinder)."""
    obs = Obstacles(centers_m=[[1, 2, 3], [4, 5, 6]], radii_m=[1.0, 2.0],
                    cylinder=np.array([False, True]))
    np.testing.assert_allclose(obs.parameters(3, 0.5), [[1, 2, 3, 1.5, 1], [4, 5, 6, 2.5, 0]])
    assert obs.parameters(3, 0.5).shape == (2, 5) and Obstacles().parameters(2, 1.0).shape == (0, 5)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"centers_m": [[0, 0, math.nan]], "radii_m": [1.0]}, "centers_m"),
    ({"centers_m": [[0, 0, 0]], "radii_m": [math.inf]}, "radii_m"),
    ({"centers_m": [[0, 0, 0]], "radii_m": [1.0, 2.0]}, "radii_m"),
    ({"centers_m": [[0, 0, 0]], "radii_m": [-1.0]}, "radii_m"),
    ({"centers_m": [[0, 0, 0]], "radii_m": [1.0], "cylinder": np.array([1])}, "cylinder")])
def test_each_bad_field_is_named(kwargs: dict[str, object], field: str) -> None:
    """Non-finite centres or radii, a radius count that differs, negative radii and non-boolean
    flags each name their field."""
    with pytest.raises(InvalidInputError) as info:
        Obstacles(**kwargs)  # type: ignore[arg-type]
    assert info.value.field == field
