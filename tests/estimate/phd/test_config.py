"""SMC-PHD settings and the grid birth intensity: validated, each error naming its field."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import BirthGrid, PHDConfig, SurvivalMap


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"survival_probability": 0.0}, "survival_probability"),
    ({"birth_mass": -1.0}, "birth_mass"),
    ({"birth_particles_per_measurement": 0}, "birth_particles_per_measurement"),
    ({"birth_position_sigma_m": float("nan")}, "birth_position_sigma_m"),
    ({"particles_per_target": 2.5}, "particles_per_target"),
    ({"min_particles": 20, "max_particles": 10}, "min_particles"),
    ({"extraction": "dbscan"}, "extraction"),
    ({"region": [[0.0, -1.0], [0.0, 1.0]]}, "region"),
    ({"birth_grid": "uniform"}, "birth_grid"),
])
def test_bad_config(kwargs: dict[str, object], field: str) -> None:
    """Invalid settings raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        PHDConfig(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_config_coerces_numbers_and_freezes_the_region() -> None:
    """Integers given for real settings become floats; the region is a read-only array."""
    cfg = PHDConfig(birth_mass=1, survival_probability=1, region=[[0, 10], [0, 20]])  # type: ignore[arg-type]
    assert isinstance(cfg.birth_mass, float) and cfg.survival_probability == 1.0
    assert isinstance(cfg.region, np.ndarray) and not cfg.region.flags.writeable
    np.testing.assert_array_equal(cfg.region, [[0.0, 10.0], [0.0, 20.0]])


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"report_missed": 1}, "report_missed"),
    ({"merge_radius_m": -1.0}, "merge_radius_m"),
    ({"attribution_threshold": 0.0}, "attribution_threshold"),
    ({"kmeans_iterations": 0}, "kmeans_iterations"),
    ({"survival_probability": 1.5}, "survival_probability"),
    ({"adaptive_birth": 1}, "adaptive_birth"),
    ({"adaptive_birth": True, "birth_mass": 1.5}, "birth_mass"),
])
def test_more_bad_settings(kwargs: dict[str, object], field: str) -> None:
    """Non-bool flags, negative radii and out-of-range thresholds name the field."""
    with pytest.raises(InvalidInputError) as err:
        PHDConfig(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_any_object_with_a_survival_method_is_a_survival_map() -> None:
    """survival_map takes anything with ``survival(positions, dt_s)``."""

    class Half:
        def survival(self, positions: np.ndarray, dt_s: float | None = None) -> np.ndarray:
            return np.full(positions.shape[0], 0.5)

    assert isinstance(PHDConfig(survival_map=Half()).survival_map, SurvivalMap)


@pytest.mark.parametrize(("args", "field"), [
    (([[0.0, 1.0], [1.0, 1.0]], np.ones((2, 2)), 1.0, 10), "bounds"),
    (([0.0, 1.0], np.ones(2), 1.0, 10), "bounds"),
    (([[0.0, 1.0]], np.ones((2, 2)), 1.0, 10), "cell_weights"),
    (([[0.0, 1.0]], np.array([1.0, -1.0]), 1.0, 10), "cell_weights"),
    (([[0.0, 1.0]], np.ones(2), -0.1, 10), "mass"),
    (([[0.0, 1.0]], np.ones(2), 1.0, 0), "particles"),
])
def test_bad_birth_grids_name_the_field(args: tuple[object, ...], field: str) -> None:
    """Bounds with low ≥ high or not (p, 2), weights of another dimension or negative, negative
    mass and no particles are refused naming the field."""
    with pytest.raises(InvalidInputError) as err:
        BirthGrid(*args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize("seed", range(3))
def test_birth_grid_samples_only_weighted_cells(seed: int) -> None:
    """A 1-D grid of five 2 m cells weighted only in the middle one draws every particle in
    [4, 6); a 2-D uniform grid draws inside its bounds."""
    grid = BirthGrid(np.array([[0.0, 10.0]]), np.array([0.0, 0.0, 5.0, 0.0, 0.0]), 1.0, 200)
    x = grid.sample(np.random.default_rng(seed))
    assert x.shape == (200, 1) and np.all((x >= 4.0) & (x < 6.0))
    uniform = BirthGrid.uniform([[0.0, 1.0], [10.0, 30.0]], mass=0.5, particles=300)
    assert uniform.cell_weights.shape == (1, 1)
    y = uniform.sample(np.random.default_rng(seed))
    assert np.all((y[:, 0] >= 0.0) & (y[:, 0] < 1.0) & (y[:, 1] >= 10.0) & (y[:, 1] < 30.0))
    assert y[:, 1].max() - y[:, 1].min() > 15.0  # spread over the whole interval


def test_birth_grid_sample_follows_the_cell_weights() -> None:
    """Cells weighted 1 : 3 receive about a quarter and three quarters of the particles."""
    grid = BirthGrid(np.array([[0.0, 2.0]]), np.array([1.0, 3.0]), 1.0, 4000)
    share = float(np.mean(grid.sample(np.random.default_rng(0))[:, 0] < 1.0))
    assert share == pytest.approx(0.25, abs=0.03)


def test_backend_is_numba_or_numpy() -> None:
    """The compiled passes are the default; the NumPy reference is selectable; others refused."""
    assert PHDConfig().backend == "numba" and PHDConfig(backend="numpy").backend == "numpy"
    with pytest.raises(InvalidInputError) as err:
        PHDConfig(backend="cuda")
    assert err.value.field == "backend"
