"""Gaussian-process regression with a Matérn 3/2 kernel: hyper-parameters and local posteriors.

Paper 003 (§ *Target Parameterization*) regresses velocity on position with two independent
zero-mean GPs (one per ground axis), a Matérn ν = 3/2 kernel and Gaussian noise::

    k(r) = σ_f² (1 + √3 r / ℓ) exp(−√3 r / ℓ),      y = f(x) + ε,  ε ~ N(0, σ_n²)

Our choices (the paper gives no details): both axes share ``(ℓ, σ_f, σ_n)``, fitted by maximising
the summed log marginal likelihood (Rasmussen & Williams 2006, eq. 2.30, gradient eq. 5.9) with
L-BFGS-B on a random subsample of the data; predictions use all data through a nearest-neighbour
GP (the exact posterior given the nearest ``n_neighbours`` samples of each query point), which
stays accurate when the learned length scale is short next to the extent of the road network,
where a global sparse (inducing-point) approximation smooths the field away.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_solve, lapack
from scipy.optimize import minimize
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray

log = logging.getLogger("searchtrack.models.gp_regression")

_SQRT3 = math.sqrt(3.0)
_JITTER = 1e-8


def matern32(r: FloatArray, length_m: float, sigma_f: float) -> FloatArray:
    """Matérn 3/2 covariance ``σ_f² (1 + √3 r/ℓ) exp(−√3 r/ℓ)`` at distances ``r``."""
    a = _SQRT3 * np.asarray(r, dtype=np.float64) / length_m
    return np.asarray(sigma_f**2 * (1.0 + a) * np.exp(-a))


@dataclass(frozen=True)
class GPHyper:
    """Kernel length scale ``ℓ`` (m), signal std ``σ_f`` and noise std ``σ_n`` (m/s), all > 0."""

    length_m: float
    sigma_f: float
    sigma_n: float

    def __post_init__(self) -> None:
        for name in ("length_m", "sigma_f", "sigma_n"):
            object.__setattr__(self, name, checks.positive(name, getattr(self, name)))

    def kernel(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """``(n, m)`` covariances between points ``a`` ``(n, 2)`` and ``b`` ``(m, 2)``."""
        return matern32(cdist(a, b), self.length_m, self.sigma_f)


def negative_log_marginal(theta: FloatArray, x: FloatArray, y: FloatArray,
                          r: FloatArray | None = None) -> tuple[float, FloatArray]:
    """``−log p(Y | X, θ)`` summed over the columns of ``y`` and its gradient in
    ``θ = (log ℓ, log σ_f, log σ_n)``."""
    ell, sf, sn = np.exp(theta)
    dist = cdist(x, x) if r is None else r
    a = _SQRT3 * dist / ell
    e = np.exp(-a)
    kf = sf**2 * (1.0 + a) * e
    n, m = y.shape
    k = kf.copy()
    k[np.diag_indices(n)] += sn**2 + _JITTER
    chol, info = lapack.dpotrf(k, lower=1)
    if info != 0:
        return math.inf, np.zeros(3)
    alpha = cho_solve((chol, True), y, check_finite=False)
    nll = 0.5 * float(np.sum(y * alpha)) + m * float(np.sum(np.log(np.diag(chol)))) \
        + 0.5 * n * m * math.log(2.0 * math.pi)
    kinv, info = lapack.dpotri(chol, lower=1)  # lower triangle of K⁻¹
    kinv = np.tril(kinv) + np.tril(kinv, -1).T
    w = m * kinv - alpha @ alpha.T  # −(ααᵀ − m K⁻¹)
    grad = 0.5 * np.array([np.sum(w * (sf**2 * a * a * e)),  # ∂K/∂log ℓ = σ_f² a² e^{−a}
                           2.0 * np.sum(w * kf),  # ∂K/∂log σ_f = 2 K_f
                           2.0 * sn**2 * np.trace(w)])  # ∂K/∂log σ_n = 2 σ_n² I
    return nll, grad


def fit_hyperparameters(x: FloatArray, y: FloatArray, rng: np.random.Generator,
                        max_points: int = 500, min_length_m: float = 10.0) -> GPHyper:
    """Maximum-marginal-likelihood ``(ℓ, σ_f, σ_n)`` on at most ``max_points`` random samples.

    L-BFGS-B in log space from two starting length scales (a twentieth and a fifth of the data's
    extent); the better optimum wins. ``ℓ ≥ min_length_m``: vehicles waiting at one spot give
    many identical samples that a metre-scale kernel would fit exactly (and then predict zero
    velocity for everyone passing there).
    """
    n = x.shape[0]
    idx = np.sort(rng.choice(n, size=max_points, replace=False)) if n > max_points \
        else np.arange(n)
    xs, ys = x[idx], y[idx]
    r = cdist(xs, xs)
    extent = max(float(np.ptp(x[:, 0])), float(np.ptp(x[:, 1])), 1.0)
    scale = max(float(np.std(y)), 1e-3)
    low = max(extent * 1e-3, min_length_m)
    bounds = [(math.log(low), math.log(max(extent * 10.0, 2.0 * low))),
              (math.log(scale * 1e-3), math.log(scale * 100.0)),
              (math.log(scale * 1e-4), math.log(scale * 10.0))]
    best: tuple[float, FloatArray] | None = None
    for frac in (0.05, 0.2):
        start = np.log([max(extent * frac, 1.5 * low), scale, 0.5 * scale])
        res = minimize(negative_log_marginal, start, args=(xs, ys, r), jac=True,
                       method="L-BFGS-B", bounds=bounds)
        log.debug("GP fit from ℓ0=%.1f m: nll=%.3f, %d evaluations", extent * frac, res.fun,
                  res.nfev)
        if best is None or res.fun < best[0]:
            best = (float(res.fun), np.asarray(res.x))
    assert best is not None
    ell, sf, sn = np.exp(best[1])
    return GPHyper(float(ell), float(sf), float(sn))


def local_predict(x: FloatArray, y: FloatArray, hyper: GPHyper, xs: FloatArray,
                  n_neighbours: int = 30) -> tuple[FloatArray, FloatArray]:
    """Nearest-neighbour GP prediction (Datta et al. 2016; Gramacy & Apley 2015).

    Each of the ``(k, 2)`` query points ``xs`` gets the exact GP posterior given only its
    ``n_neighbours`` nearest training points: mean ``(k, m)`` and latent variance ``(k,)``
    (without ``σ_n²``). With ``n_neighbours ≥ n`` it is the exact GP.
    """
    q = min(n_neighbours, x.shape[0])
    tree = cKDTree(x)
    means = np.empty((xs.shape[0], y.shape[1]))
    var = np.empty(xs.shape[0])
    noise = hyper.sigma_n**2 * np.eye(q)
    for s in range(0, xs.shape[0], 2048):
        d, idx = tree.query(xs[s:s + 2048], q)
        d, idx = d.reshape(-1, q), idx.reshape(-1, q)
        xn = x[idx]
        dd = np.sqrt(np.sum((xn[:, :, None, :] - xn[:, None, :, :]) ** 2, axis=3))
        k = matern32(dd, hyper.length_m, hyper.sigma_f) + noise
        ks = matern32(d, hyper.length_m, hyper.sigma_f)
        a = np.linalg.solve(k, ks[:, :, None])[:, :, 0]
        means[s:s + 2048] = np.einsum("bq,bqj->bj", a, y[idx])
        var[s:s + 2048] = hyper.sigma_f**2 - np.sum(a * ks, axis=1)
    return means, np.clip(var, 0.0, hyper.sigma_f**2)


def check_xy(positions: FloatArray, velocities: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(n, 2)`` finite positions and matching ``(n, 2)`` velocities, ``n ≥ 2``."""
    x = checks.finite_array("positions", positions, (None, 2))
    if x.shape[0] < 2:
        raise InvalidInputError("positions", positions, "need at least 2 samples")
    y = checks.finite_array("velocities", velocities, (x.shape[0], 2))
    return np.asarray(x), np.asarray(y)
