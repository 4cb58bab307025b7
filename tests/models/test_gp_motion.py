"""Gaussian-process velocity field (paper 003, §1.3): fit, tabulated predictions, motion model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.gp_motion import GPMotion, GPVelocityField
from searchtrack.models.gp_regression import GPHyper
from searchtrack.models.particle_models import MotionModel
from tests.models.gp_reference import exact_gp as _exact_gp

OMEGA = 0.01  # rad/s: v = ω × (x, y)


def _rotation(x: np.ndarray) -> np.ndarray:
    return np.column_stack([-OMEGA * x[:, 1], OMEGA * x[:, 0]])


@pytest.fixture(scope="module")
def rotation_field() -> GPVelocityField:
    """A GP fitted to 1500 noisy samples of a rotation field over a 1 km square."""
    rng = np.random.default_rng(0)
    x = rng.uniform(-500.0, 500.0, (1500, 2))
    v = _rotation(x) + 0.3 * rng.standard_normal(x.shape)
    return GPVelocityField.fit(x, v, np.random.default_rng(1), cell_m=25.0, n_hyper=300)


def test_recovers_a_rotation_field(rotation_field: GPVelocityField) -> None:
    """Inside the data the mean velocity is within 0.15 m/s RMS of the true rotation field."""
    xt = np.random.default_rng(3).uniform(-450.0, 450.0, (500, 2))
    mean, _ = rotation_field.predict(xt)
    rmse = math.sqrt(np.mean(np.sum((mean - _rotation(xt)) ** 2, axis=1)))
    assert rmse < 0.15  # speeds reach 6 m/s; noise 0.3 m/s
    assert rotation_field.hyper.sigma_n == pytest.approx(0.3, rel=0.2)


def test_variance_small_near_data_and_prior_far_away(rotation_field: GPVelocityField) -> None:
    """Latent variance is tiny inside the data and the prior σ_f² outside the grid."""
    _, near = rotation_field.predict(np.array([[0.0, 0.0], [200.0, -100.0]]))
    mean_far, far = rotation_field.predict(np.array([[5000.0, 0.0]]))
    sf2 = rotation_field.hyper.sigma_f**2
    assert np.all(near < 0.01 * sf2)
    assert far[0] == pytest.approx(sf2)
    np.testing.assert_array_equal(mean_far, [[0.0, 0.0]])


def test_variance_grows_away_from_data() -> None:
    """With data only in the left half, the variance rises with distance into the right half."""
    rng = np.random.default_rng(4)
    x = rng.uniform([0.0, 0.0], [500.0, 1000.0], (600, 2))
    v = np.column_stack([np.sin(x[:, 1] / 150.0), np.cos(x[:, 0] / 150.0)])
    field = GPVelocityField.fit(x + 0.0, v + 0.05 * rng.standard_normal(v.shape),
                                np.random.default_rng(5), bounds=[[0.0, 1500.0], [0.0, 1000.0]],
                                hyper=GPHyper(150.0, 1.0, 0.05))
    probe = np.column_stack([np.linspace(250.0, 1450.0, 7), np.full(7, 500.0)])
    _, var = field.predict(probe)
    assert var[0] < 0.05 * var[-1]
    assert np.all(np.diff(var[1:]) > -1e-9)


def test_grid_matches_the_exact_gp_at_nodes() -> None:
    """With every sample a neighbour, grid nodes carry the exact GP posterior."""
    rng = np.random.default_rng(6)
    x = rng.uniform(0.0, 300.0, (200, 2))
    v = np.column_stack([x[:, 0] / 300.0, -x[:, 1] / 300.0]) + 0.05 * rng.standard_normal((200, 2))
    hyper = GPHyper(120.0, 1.0, 0.05)
    field = GPVelocityField.fit(x, v, np.random.default_rng(0), cell_m=30.0,
                                bounds=[[0.0, 300.0], [0.0, 300.0]], hyper=hyper,
                                n_neighbours=500)
    nodes = np.array([[30.0, 60.0], [150.0, 270.0]])
    mean, var = _exact_gp(x, v, hyper, nodes)
    m_grid, v_grid = field.predict(nodes)
    np.testing.assert_allclose(m_grid, mean, atol=1e-8)
    np.testing.assert_allclose(v_grid, var, atol=1e-8)


def test_gp_motion_is_a_motion_model(rotation_field: GPVelocityField) -> None:
    """GPMotion satisfies MotionModel with 2-D position states."""
    motion = GPMotion(rotation_field)
    assert isinstance(motion, MotionModel)
    assert (motion.state_dim, motion.position_dim) == (2, 2)


def test_propagate_follows_the_mean_with_gp_noise(rotation_field: GPVelocityField) -> None:
    """Particles move by μ(x)·Δt on average with spread √(σ² + σ_n²)·Δt."""
    motion = GPMotion(rotation_field)
    start = np.tile([[200.0, 100.0]], (20_000, 1))
    end = motion.propagate(start, 2.0, np.random.default_rng(8))
    mean, std = motion.velocity(start[:1])
    np.testing.assert_allclose(end.mean(axis=0), start[0] + 2.0 * mean[0], atol=0.05)
    np.testing.assert_allclose(end.std(axis=0), 2.0 * std[0], rtol=0.03)
    latent = GPMotion(rotation_field, include_noise=False)
    assert latent.velocity(start[:1])[1][0] < std[0]


def test_propagate_is_seeded_and_substeps_follow_the_curve(
        rotation_field: GPVelocityField) -> None:
    """Same seed, same particles; sub-steps keep a rotating particle on its circle better."""
    start = np.array([[300.0, 0.0], [0.0, -200.0]])
    one = GPMotion(rotation_field, include_noise=False)
    a = one.propagate(start, 30.0, np.random.default_rng(1))
    np.testing.assert_array_equal(a, one.propagate(start, 30.0, np.random.default_rng(1)))
    fine = GPMotion(rotation_field, max_step_s=1.0, include_noise=False).propagate(
        start, 30.0, np.random.default_rng(1))
    r0 = np.linalg.norm(start, axis=1)
    assert np.all(np.abs(np.linalg.norm(fine, axis=1) - r0) < np.abs(np.linalg.norm(a, axis=1)
                                                                     - r0))
    np.testing.assert_array_equal(one.propagate(start, 0.0, np.random.default_rng(1)), start)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"positions": np.zeros((1, 2)), "velocities": np.zeros((1, 2))}, "positions"),
    ({"velocities": np.zeros((5, 3))}, "velocities"),
    ({"positions": np.full((5, 2), np.nan)}, "positions"),
    ({"rng": 0}, "rng"), ({"cell_m": 0.0}, "cell_m"), ({"n_hyper": 1}, "n_hyper"),
    ({"n_neighbours": 0}, "n_neighbours"), ({"min_length_m": 0.0}, "min_length_m"),
    ({"bounds": [[1.0, 0.0], [0.0, 1.0]]}, "bounds"),
    ({"hyper": (1.0, 1.0, 1.0)}, "hyper"),
])
def test_bad_fit_input(kwargs: dict[str, object], field: str) -> None:
    """Bad arguments of GPVelocityField.fit raise InvalidInputError naming the argument."""
    args: dict[str, object] = {"positions": np.arange(10.0).reshape(5, 2),
                               "velocities": np.ones((5, 2)), "rng": np.random.default_rng(0)}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        GPVelocityField.fit(**args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"cell_m": -1.0}, "cell_m"), ({"mean": np.zeros((1, 3, 2))}, "mean"),
    ({"variance": -np.ones((3, 3))}, "variance"), ({"origin": [0.0]}, "origin"),
    ({"hyper": None}, "hyper"), ({"fit_s": -1.0}, "fit_s"),
])
def test_bad_field(kwargs: dict[str, object], field: str) -> None:
    """A GPVelocityField with a bad part is refused, naming the part."""
    args: dict[str, object] = {"hyper": GPHyper(1.0, 1.0, 1.0), "origin": [0.0, 0.0],
                               "cell_m": 1.0, "mean": np.zeros((3, 3, 2)),
                               "variance": np.ones((3, 3))}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        GPVelocityField(**args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"field": "gp"}, "field"), ({"max_step_s": 0.0}, "max_step_s"),
    ({"include_noise": 1}, "include_noise"),
])
def test_bad_motion(rotation_field: GPVelocityField, kwargs: dict[str, object],
                    field: str) -> None:
    """A GPMotion with a bad argument is refused, naming it."""
    args: dict[str, object] = {"field": rotation_field}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        GPMotion(**args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_propagate_input(rotation_field: GPVelocityField) -> None:
    """States of the wrong width and negative steps are refused."""
    motion = GPMotion(rotation_field)
    with pytest.raises(InvalidInputError, match="states"):
        motion.propagate(np.zeros((3, 4)), 1.0, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="dt_s"):
        motion.propagate(np.zeros((3, 2)), -1.0, np.random.default_rng(0))
