"""Motion models: moments of one propagation step against the closed form, and bad input."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.motion import ConstantVelocity, RandomWalk, Static
from searchtrack.models.particle_models import MotionModel

N = 200_000


def _moments(samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return samples.mean(axis=0), np.cov(samples.T)


def test_cv_moments_match_closed_form() -> None:
    """CV propagation has mean F x and covariance q [[dt³/3, dt²/2], [dt²/2, dt]] per axis."""
    model = ConstantVelocity(0.5)
    x0 = np.array([10.0, -5.0, 2.0, 1.0])
    dt = 2.0
    out = model.propagate(np.tile(x0, (N, 1)), dt, np.random.default_rng(1))
    mean, cov = _moments(out)
    np.testing.assert_allclose(mean, model.transition_matrix(dt) @ x0, atol=0.03)
    expected = 0.5 * np.array([[8 / 3, 0, 2, 0], [0, 8 / 3, 0, 2], [2, 0, 2, 0], [0, 2, 0, 2]])
    np.testing.assert_allclose(model.noise_covariance(dt), expected)
    np.testing.assert_allclose(cov, expected, atol=0.03)


def test_cv_3d_layout_and_zero_dt() -> None:
    """A 3-D CV state is [x, y, z, vx, vy, vz]; dt = 0 leaves it unchanged."""
    model = ConstantVelocity(1.0, position_dim=3)
    x = np.array([[0.0, 0.0, 0.0, 1.0, 2.0, 3.0]])
    assert model.state_dim == 6
    np.testing.assert_array_equal(model.propagate(x, 0.0, np.random.default_rng(0)), x)
    np.testing.assert_allclose(model.transition_matrix(1.0) @ x[0], [1, 2, 3, 1, 2, 3])


def test_random_walk_moments() -> None:
    """A random-walk step has mean 0 and standard deviation sigma·dt per axis."""
    model = RandomWalk(3.0)
    out = model.propagate(np.zeros((N, 2)), 0.5, np.random.default_rng(2))
    mean, cov = _moments(out)
    np.testing.assert_allclose(mean, 0.0, atol=0.02)
    np.testing.assert_allclose(cov, 1.5**2 * np.eye(2), atol=0.03)


def test_static_is_identity_copy() -> None:
    """Static targets keep their states; the result is a new array."""
    x = np.arange(6.0).reshape(3, 2)
    out = Static().propagate(x, 5.0, np.random.default_rng(0))
    np.testing.assert_array_equal(out, x)
    assert out is not x


@pytest.mark.parametrize("model", [RandomWalk(1.0), ConstantVelocity(0.5), Static(3)])
def test_models_satisfy_protocol(model: MotionModel) -> None:
    """Every model is a MotionModel."""
    assert isinstance(model, MotionModel)


@pytest.mark.parametrize(("make", "field"), [
    (lambda: RandomWalk(0.0), "sigma_mps"),
    (lambda: RandomWalk(float("nan")), "sigma_mps"),
    (lambda: ConstantVelocity(-1.0), "q"),
    (lambda: ConstantVelocity(1.0, position_dim=4), "position_dim"),
    (lambda: Static(0), "position_dim"),
])
def test_bad_parameters(make: object, field: str) -> None:
    """Invalid parameters raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        make()  # type: ignore[operator]
    assert err.value.field == field


def test_bad_states_and_dt() -> None:
    """A state array of the wrong width or a negative dt is rejected."""
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidInputError, match="states"):
        ConstantVelocity(0.5).propagate(np.zeros((3, 2)), 1.0, rng)
    with pytest.raises(InvalidInputError, match="dt_s"):
        RandomWalk(1.0).propagate(np.zeros((3, 2)), -1.0, rng)
