"""Matérn 3/2 GP regression (paper 003): kernel, marginal likelihood and its gradient,
hyper-parameter fit, nearest-neighbour posterior, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import approx_fprime
from scipy.stats import multivariate_normal

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.gp_regression import (
    GPHyper,
    check_xy,
    fit_hyperparameters,
    local_predict,
    matern32,
    negative_log_marginal,
)
from tests.models.gp_reference import exact_gp as _exact_gp


def test_matern32_matches_the_formula() -> None:
    """k(0) = σ_f², k(ℓ) = σ_f²(1 + √3)e^{−√3}, and GPHyper.kernel uses Euclidean distance."""
    r = np.array([0.0, 2.0, 5.0])
    want = 4.0 * (1 + math.sqrt(3) * r / 2.0) * np.exp(-math.sqrt(3) * r / 2.0)
    np.testing.assert_allclose(matern32(r, 2.0, 2.0), want)
    assert matern32(np.array([2.0]), 2.0, 2.0)[0] == pytest.approx(
        4.0 * (1 + math.sqrt(3)) * math.exp(-math.sqrt(3)))
    k = GPHyper(2.0, 2.0, 0.1).kernel(np.zeros((1, 2)), np.array([[3.0, 4.0]]))
    assert k[0, 0] == pytest.approx(matern32(np.array([5.0]), 2.0, 2.0)[0])


def test_marginal_likelihood_gradient_matches_finite_differences() -> None:
    """The analytic gradient of −log p(Y | X, θ) agrees with central differences."""
    rng = np.random.default_rng(2)
    x = rng.uniform(0.0, 100.0, (40, 2))
    y = np.column_stack([np.sin(x[:, 0] / 20.0), np.cos(x[:, 1] / 30.0)])
    y += 0.1 * rng.standard_normal(y.shape)
    theta = np.log([15.0, 1.0, 0.2])
    _, grad = negative_log_marginal(theta, x, y)
    num = approx_fprime(theta, lambda t: negative_log_marginal(t, x, y)[0], 1e-6)
    np.testing.assert_allclose(grad, num, rtol=1e-4, atol=1e-4)


def test_nearest_neighbour_gp_is_close_to_the_exact_gp() -> None:
    """Predicting from the 40 nearest of 400 samples is within 2 % of the exact GP."""
    rng = np.random.default_rng(9)
    x = rng.uniform(0.0, 1000.0, (400, 2))
    v = np.column_stack([np.sin(x[:, 0] / 80.0), np.cos(x[:, 1] / 60.0)])
    hyper = GPHyper(60.0, 1.0, 0.1)
    xs = rng.uniform(100.0, 900.0, (50, 2))
    mean, var = _exact_gp(x, v, hyper, xs)
    m_nn, v_nn = local_predict(x, v, hyper, xs, 40)
    np.testing.assert_allclose(m_nn, mean, atol=0.02)
    np.testing.assert_allclose(v_nn, var, atol=0.02)


@pytest.mark.parametrize("name", ["length_m", "sigma_f", "sigma_n"])
def test_bad_hyper(name: str) -> None:
    """Non-positive hyper-parameters are refused."""
    args = {"length_m": 1.0, "sigma_f": 1.0, "sigma_n": 1.0, name: 0.0}
    with pytest.raises(InvalidInputError, match=name):
        GPHyper(**args)


def test_marginal_likelihood_is_the_gaussian_log_density() -> None:
    """−log p(Y | X, θ) is minus the summed N(0, K_f + σ_n² I) log-densities of the columns."""
    rng = np.random.default_rng(10)
    x = rng.uniform(0.0, 50.0, (25, 2))
    y = rng.standard_normal((25, 2))
    hyper = GPHyper(12.0, 1.5, 0.3)
    cov = hyper.kernel(x, x) + hyper.sigma_n**2 * np.eye(25)
    want = -sum(multivariate_normal(np.zeros(25), cov).logpdf(y[:, j]) for j in range(2))
    theta = np.log([12.0, 1.5, 0.3])
    nll, _ = negative_log_marginal(theta, x, y)
    assert nll == pytest.approx(want, rel=1e-7)
    r = np.linalg.norm(x[:, None] - x[None], axis=2)
    assert negative_log_marginal(theta, x, y, r)[0] == pytest.approx(nll, rel=1e-12)


def test_fit_recovers_the_hyperparameters_of_a_gp_sample() -> None:
    """Fitted to 120 samples drawn from a GP with ℓ = 40 m, σ_f = 1, σ_n = 0.1, the estimates
    land near the truth, and the same generator gives the same fit."""
    rng = np.random.default_rng(11)
    x = rng.uniform(0.0, 150.0, (120, 2))
    truth = GPHyper(40.0, 1.0, 0.1)
    chol = np.linalg.cholesky(truth.kernel(x, x) + 1e-10 * np.eye(120))
    y = chol @ rng.standard_normal((120, 2)) + 0.1 * rng.standard_normal((120, 2))
    fit = fit_hyperparameters(x, y, np.random.default_rng(0))
    assert fit.length_m == pytest.approx(40.0, rel=0.25)
    assert fit.sigma_f == pytest.approx(1.0, rel=0.25)
    assert fit.sigma_n == pytest.approx(0.1, rel=0.25)
    sub = fit_hyperparameters(x, y, np.random.default_rng(5), max_points=50)
    assert sub == fit_hyperparameters(x, y, np.random.default_rng(5), max_points=50)


def test_fit_keeps_the_length_scale_above_its_floor() -> None:
    """Vehicles waiting at spots a few metres apart pull ℓ down to min_length_m, not below."""
    rng = np.random.default_rng(1)
    x = np.repeat(rng.uniform(0.0, 60.0, (8, 2)), 5, axis=0)
    y = np.repeat(rng.standard_normal((8, 2)), 5, axis=0) + 0.01 * rng.standard_normal((40, 2))
    free = fit_hyperparameters(x, y, np.random.default_rng(0), min_length_m=1.0)
    floored = fit_hyperparameters(x, y, np.random.default_rng(0), min_length_m=30.0)
    assert free.length_m < 30.0
    assert floored.length_m == pytest.approx(30.0)


def test_local_predict_with_every_neighbour_is_the_exact_gp() -> None:
    """With n_neighbours ≥ n the nearest-neighbour GP is the exact posterior; far away it is the
    prior, mean 0 and variance σ_f²."""
    rng = np.random.default_rng(13)
    x = rng.uniform(0.0, 100.0, (60, 2))
    y = np.column_stack([np.sin(x[:, 0] / 20.0), x[:, 1] / 100.0])
    hyper = GPHyper(25.0, 0.8, 0.05)
    xs = np.vstack([rng.uniform(0.0, 100.0, (10, 2)), [[1e5, 1e5]]])
    mean, var = local_predict(x, y, hyper, xs, n_neighbours=100)
    want_mean, want_var = _exact_gp(x, y, hyper, xs)
    np.testing.assert_allclose(mean, want_mean, atol=1e-9)
    np.testing.assert_allclose(var, want_var, atol=1e-9)
    np.testing.assert_allclose(mean[-1], 0.0, atol=1e-12)
    assert var[-1] == pytest.approx(0.8**2)


def test_check_xy_names_the_bad_array() -> None:
    """check_xy returns matching (n, 2) arrays and names too few, ragged or NaN samples."""
    x, y = check_xy([[0.0, 1.0], [2.0, 3.0]], [[1.0, 0.0], [0.0, 1.0]])
    assert x.shape == y.shape == (2, 2)
    cases = [
        (([[0.0, 1.0]], [[1.0, 0.0]]), "positions"),
        (([[0.0, 1.0, 2.0], [2.0, 3.0, 4.0]], [[1.0, 0.0], [0.0, 1.0]]), "positions"),
        (([[0.0, 1.0], [2.0, 3.0]], [[1.0, 0.0]]), "velocities"),
        (([[0.0, 1.0], [2.0, 3.0]], [[1.0, math.nan], [0.0, 1.0]]), "velocities"),
    ]
    for args, field in cases:
        with pytest.raises(InvalidInputError) as err:
            check_xy(*args)  # type: ignore[arg-type]
        assert err.value.field == field
