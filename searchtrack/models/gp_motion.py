"""Learned target motion: a Gaussian-process velocity field over the ground (paper 003, *Target
Parameterization*).

Paper 003 learns velocity as a function of position from taxi traces with two zero-mean
Matérn 3/2 GPs and moves each particle by ``x' = ξ + Δt·v``, ``v ~ N(μ(ξ), diag σ²(ξ))``, the GP
posterior mean and variance at the particle. :class:`GPVelocityField` fits the GP (see
:mod:`searchtrack.models.gp_regression`) and tabulates ``μ`` and ``σ²`` on a regular grid so that
a lookup during propagation is O(1) (bilinear interpolation); outside the grid the field is the
GP prior, zero mean and variance ``σ_f²``. :class:`GPMotion` is the motion model.

Whether the paper's ``σ²(ξ)`` includes the observation noise ``σ_n²`` is not said. The latent
variance alone is tiny near data even where vehicles go both ways along a road (the mean there is
~0 and the spread is in ``σ_n``), so :class:`GPMotion` adds ``σ_n²`` by default
(``include_noise=True``): the velocity drawn is that of a new observation.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.gp_regression import GPHyper, check_xy, fit_hyperparameters, local_predict

log = logging.getLogger("searchtrack.models.gp_motion")


_FAR = 6.0
"""Grid nodes farther than ``_FAR · ℓ`` from every sample get the prior directly."""


@dataclass(frozen=True, eq=False)
class GPVelocityField:
    """A GP velocity field tabulated on grid nodes ``lo + i·cell_m`` (use :meth:`fit`).

    Parameters
    ----------
    hyper
        Kernel hyper-parameters ``(ℓ, σ_f, σ_n)``.
    origin
        ``(2,)`` lower-left grid node (m).
    cell_m
        Grid spacing (m), ``> 0``.
    mean
        ``(n_x, n_y, 2)`` posterior mean velocity (m/s) at the nodes, ``n_x, n_y ≥ 2``.
    variance
        ``(n_x, n_y)`` latent posterior variance (m²/s²) at the nodes, shared by both axes, in
        ``[0, σ_f²]``.
    fit_s
        Wall time spent fitting (s), for reports.
    """

    hyper: GPHyper
    origin: FloatArray
    cell_m: float
    mean: FloatArray
    variance: FloatArray
    fit_s: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.hyper, GPHyper):
            raise InvalidInputError("hyper", self.hyper, "must be a GPHyper")
        object.__setattr__(self, "origin", checks.finite_array("origin", self.origin, (2,)))
        object.__setattr__(self, "cell_m", checks.positive("cell_m", self.cell_m))
        mean = checks.finite_array("mean", self.mean, (None, None, 2))
        if mean.shape[0] < 2 or mean.shape[1] < 2:
            raise InvalidInputError("mean", mean.shape, "needs at least 2 × 2 grid nodes")
        var = checks.finite_array("variance", self.variance, mean.shape[:2])
        if np.any(var < 0):
            raise InvalidInputError("variance", self.variance, "must be ≥ 0")
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "variance", var)
        object.__setattr__(self, "fit_s", checks.non_negative("fit_s", self.fit_s))

    @classmethod
    def fit(cls, positions: ArrayLike, velocities: ArrayLike, rng: np.random.Generator, *,
            cell_m: float | None = None, bounds: ArrayLike | None = None, n_hyper: int = 500,
            n_neighbours: int = 30, min_length_m: float = 10.0,
            hyper: GPHyper | None = None) -> GPVelocityField:
        """Fit the GP to ``(n, 2)`` positions (m) and velocities (m/s) and tabulate it.

        Parameters
        ----------
        positions, velocities
            Training pairs, e.g. :meth:`~searchtrack.models.road_traces.Traces.velocities`.
        rng
            Draws the hyper-parameter subsample.
        cell_m
            Grid spacing (m); by default half the length scale, clipped to ``[10, 25]`` m.
        bounds
            ``[[x0, x1], [y0, y1]]`` covered by the grid; the data's bounding box by default.
        n_hyper
            Samples used to maximise the marginal likelihood, ``≥ 2``.
        n_neighbours
            Samples behind each grid node's prediction (nearest-neighbour GP), ``≥ 1``.
        min_length_m
            Smallest length scale the fit may choose (m), ``> 0``.
        hyper
            Fixed hyper-parameters (skips the marginal-likelihood fit).
        """
        start = time.perf_counter()
        x, y = check_xy(np.asarray(positions, dtype=np.float64),
                        np.asarray(velocities, dtype=np.float64))
        rng = checks.generator("rng", rng)
        if cell_m is not None:
            checks.positive("cell_m", cell_m)
        n_h = checks.count("n_hyper", n_hyper, 2)
        n_nb = checks.count("n_neighbours", n_neighbours, 1)
        min_len = checks.positive("min_length_m", min_length_m)
        if hyper is not None and not isinstance(hyper, GPHyper):
            raise InvalidInputError("hyper", hyper, "must be a GPHyper or None")
        if bounds is None:
            box = np.column_stack([x.min(axis=0), x.max(axis=0)])
        else:
            box = checks.finite_array("bounds", bounds, (2, 2))
            if not np.all(box[:, 1] > box[:, 0]):
                raise InvalidInputError("bounds", bounds, "must be [[x0, x1], [y0, y1]], x0 < x1")
        if hyper is None:
            hyper = fit_hyperparameters(x, y, rng, n_h, min_len)
        cell = float(np.clip(0.5 * hyper.length_m, 10.0, 25.0)) if cell_m is None else cell_m
        n_nodes = np.maximum(np.ceil((box[:, 1] - box[:, 0]) / cell).astype(np.int64) + 1, 2)
        gx = box[0, 0] + cell * np.arange(n_nodes[0])
        gy = box[1, 0] + cell * np.arange(n_nodes[1])
        nodes = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1).reshape(-1, 2)
        mean = np.zeros((nodes.shape[0], 2))
        var = np.full(nodes.shape[0], hyper.sigma_f**2)
        near = cKDTree(x).query(nodes, distance_upper_bound=_FAR * hyper.length_m)[0]
        near = np.isfinite(near)
        mean[near], var[near] = local_predict(x, y, hyper, nodes[near], n_nb)
        elapsed = time.perf_counter() - start
        log.info("GP field: %d points, ℓ=%.1f m, σ_f=%.2f, σ_n=%.2f m/s, %d×%d grid of %.1f m, "
                 "%.2f s", x.shape[0], hyper.length_m, hyper.sigma_f, hyper.sigma_n, n_nodes[0],
                 n_nodes[1], cell, elapsed)
        return cls(hyper, box[:, 0].copy(), cell, mean.reshape(*n_nodes, 2),
                   var.reshape(*n_nodes), elapsed)

    @property
    def bounds(self) -> FloatArray:
        """``[[x0, x1], [y0, y1]]`` (m) covered by the grid."""
        size = (np.asarray(self.variance.shape) - 1) * self.cell_m
        return np.column_stack([self.origin, self.origin + size])

    def predict(self, positions: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Mean velocity ``(N, 2)`` (m/s) and latent variance ``(N,)`` (m²/s²) at ``(N, ≥2)``
        positions: bilinear in the grid, the prior (0, ``σ_f²``) outside it."""
        xy = np.asarray(positions, dtype=np.float64)[:, :2]
        f = (xy - self.origin) / self.cell_m
        hi = np.asarray(self.variance.shape) - 1
        inside = np.all((f >= 0.0) & (f <= hi), axis=1)
        i = np.clip(np.floor(f).astype(np.int64), 0, hi - 1)
        t = np.clip(f - i, 0.0, 1.0)
        ix, iy, tx, ty = i[:, 0], i[:, 1], t[:, 0:1], t[:, 1:2]
        w00, w10 = (1 - tx) * (1 - ty), tx * (1 - ty)
        w01, w11 = (1 - tx) * ty, tx * ty
        mu, v = self.mean, self.variance
        mean = (w00 * mu[ix, iy] + w10 * mu[ix + 1, iy] + w01 * mu[ix, iy + 1]
                + w11 * mu[ix + 1, iy + 1])
        var = (w00[:, 0] * v[ix, iy] + w10[:, 0] * v[ix + 1, iy] + w01[:, 0] * v[ix, iy + 1]
               + w11[:, 0] * v[ix + 1, iy + 1])
        mean[~inside] = 0.0
        var[~inside] = self.hyper.sigma_f**2
        return mean, var


@dataclass(frozen=True, eq=False)
class GPMotion:
    """Particles drift with the GP velocity field: ``x' = x + Δt·v``, ``v ~ N(μ(x), σ²(x) I)``.

    Parameters
    ----------
    field
        The fitted velocity field.
    max_step_s
        ``None`` (default): one Euler step over the whole ``dt_s``, paper 003's model. A positive
        number splits ``dt_s`` into sub-steps of at most this length, re-reading ``μ`` and ``σ``
        at each, with one standard-normal draw per particle shared by the sub-steps (so one
        sub-step is exactly the paper's model and the noise scale does not depend on the split).
    include_noise
        Add the observation noise ``σ_n²`` to the latent variance (see the module docstring).
    """

    field: GPVelocityField
    max_step_s: float | None = None
    include_noise: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.field, GPVelocityField):
            raise InvalidInputError("field", self.field, "must be a GPVelocityField")
        if self.max_step_s is not None:
            object.__setattr__(self, "max_step_s",
                               checks.positive("max_step_s", self.max_step_s))
        checks.boolean("include_noise", self.include_noise)

    @property
    def state_dim(self) -> int:
        """The state is the ground position ``[x, y]``."""
        return 2

    @property
    def position_dim(self) -> int:
        """Ground positions: 2."""
        return 2

    def velocity(self, positions: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Mean ``(N, 2)`` and standard deviation ``(N,)`` (m/s) of the velocity drawn at each
        position."""
        mean, var = self.field.predict(positions)
        if self.include_noise:
            var = var + self.field.hyper.sigma_n**2
        return mean, np.sqrt(var)

    def propagate(self, states: FloatArray, dt_s: float, rng: np.random.Generator) -> FloatArray:
        """New ``(N, 2)`` positions after ``dt_s`` seconds."""
        x = np.array(states, dtype=np.float64)
        if x.ndim != 2 or x.shape[1] != 2:
            raise InvalidInputError("states", x.shape, "must have shape (N, 2)")
        dt = checks.non_negative("dt_s", dt_s)
        n_sub = 1 if self.max_step_s is None else max(1, math.ceil(dt / self.max_step_s))
        h = dt / n_sub
        eps = rng.standard_normal(x.shape)
        for _ in range(n_sub):
            mean, std = self.velocity(x)
            x += h * (mean + std[:, None] * eps)
        return x
