"""Settings of the SMC-PHD filter and its grid birth intensity (frozen, validated)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.birth_grids import BirthSurvivalGrid

EXTRACTIONS = ("attribution", "kmeans")
BACKENDS = ("numba", "numpy")


@runtime_checkable
class SurvivalMap(Protocol):
    """State-dependent survival (paper 003's survival grid): the probability that a target at
    each of ``positions`` survives ``dt_s`` seconds."""

    def survival(self, positions: FloatArray, dt_s: float | None = None) -> FloatArray: ...


@dataclass(frozen=True)
class BirthGrid:
    """A birth intensity on a regular grid (paper 003's birth counts; uniform when all equal).

    Parameters
    ----------
    bounds
        ``(p, 2)`` ``[[x0, x1], [y0, y1], ...]`` (m) covered by the grid.
    cell_weights
        Array of ``p`` dimensions (``n_x × n_y × ...`` cells), non-negative, not all 0: the relative
        birth intensity per cell (e.g. birth counts).
    mass
        Expected number of births per scan ``∫ b(x) dx``, ``≥ 0``.
    particles
        Birth particles drawn per scan, ``≥ 1``.
    """

    bounds: FloatArray
    cell_weights: FloatArray
    mass: float
    particles: int

    def __post_init__(self) -> None:
        b = np.array(self.bounds, dtype=np.float64)
        if b.ndim != 2 or b.shape[1] != 2 or not np.all(np.isfinite(b)) or not np.all(
                b[:, 1] > b[:, 0]):
            raise InvalidInputError("bounds", self.bounds, "must be (p, 2) with low < high")
        w = np.array(self.cell_weights, dtype=np.float64)
        if w.ndim != b.shape[0] or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
            raise InvalidInputError("cell_weights", self.cell_weights,
                                    f"must be a {b.shape[0]}-D array of non-negative numbers, "
                                    "not all 0")
        b.setflags(write=False)
        w.setflags(write=False)
        object.__setattr__(self, "bounds", b)
        object.__setattr__(self, "cell_weights", w)
        object.__setattr__(self, "mass", checks.non_negative("mass", self.mass))
        object.__setattr__(self, "particles", checks.count("particles", self.particles, 1))

    @classmethod
    def from_counts(cls, grid: BirthSurvivalGrid, dt_s: float, particles: int) -> BirthGrid:
        """The birth intensity of paper 003's count grid for scans ``dt_s`` apart: cells
        weighted by their birth counts, mass ``rate · Δt``."""
        if not isinstance(grid, BirthSurvivalGrid):
            raise InvalidInputError("grid", grid, "must be a BirthSurvivalGrid")
        lo = grid.bounds[:, 0]
        bounds = np.column_stack([lo, lo + grid.cell_m * np.asarray(grid.shape)])
        return cls(bounds, grid.birth_counts, grid.birth_mass(dt_s), particles)

    @classmethod
    def uniform(cls, bounds: ArrayLike, mass: float, particles: int) -> BirthGrid:
        """A uniform birth intensity over ``bounds``."""
        b = np.asarray(bounds, dtype=np.float64)
        return cls(b, np.ones((1,) * (b.shape[0] if b.ndim == 2 else 1)), mass, particles)

    def sample(self, rng: np.random.Generator) -> FloatArray:
        """``(particles, p)`` positions: a cell drawn by weight, then a uniform point in it."""
        w = self.cell_weights
        flat = np.cumsum(w.ravel())
        cells = np.searchsorted(flat, rng.random(self.particles) * flat[-1], side="right")
        cells = np.minimum(cells, w.size - 1)
        idx = np.column_stack(np.unravel_index(cells, w.shape))
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        size = (hi - lo) / np.asarray(w.shape)
        return np.asarray(lo + (idx + rng.random(idx.shape)) * size, dtype=np.float64)


@dataclass(frozen=True)
class PHDConfig:
    """Settings of the SMC-PHD filter (Vo, Singh & Doucet 2005; birth of Ristic et al. 2010/12).

    Parameters
    ----------
    survival_probability
        ``p_s`` per scan, in ``(0, 1]``.
    survival_map
        Optional state-dependent survival (e.g. a
        :class:`~searchtrack.models.birth_grids.BirthSurvivalGrid`); when given it replaces
        ``survival_probability``, evaluated at each particle's position before the move.
    birth_mass
        Expected number of targets born per scan from measurements; shared by the measurements of
        the last update in proportion to how little the existing PHD explains them (``1 − ρ_z``).
        With ``adaptive_birth`` it is instead the birth mass of one wholly unexplained
        measurement, in ``[0, 1]``.
    adaptive_birth
        Scale the birth by what the PHD leaves unexplained instead of injecting ``birth_mass``
        every scan: measurement ``z`` seeds ``birth_mass · (1 − ρ_z)``, the weights of Ristic et
        al. (2012) without their renormalisation to a constant total, so a scan's births are
        ``birth_mass · Σ_z (1 − ρ_z) ≤ birth_mass · |Z|`` and vanish when the PHD explains every
        measurement. Without clutter ``1 − ρ_z`` is the part of ``z`` that no existing target
        explains, which must come from a target not yet in the PHD: with ``birth_mass = 1`` each
        measurement then adds exactly one unit of mass, ``ρ_z`` in the update and ``1 − ρ_z`` at
        the next prediction (see :mod:`searchtrack.estimate.phd.update`). Off by default.
    birth_particles_per_measurement
        Newborn particles drawn around each measurement, ``≥ 1``.
    birth_position_sigma_m
        Standard deviation (m) of a newborn's position around its measurement, ``> 0``.
    birth_velocity_sigma_mps
        Standard deviation (m/s) of each newborn velocity component (mean 0), ``> 0``; used when
        the state has velocity columns.
    birth_grid
        Optional extra birth intensity on a grid (``None``: measurement-driven births only).
    particles_per_target
        Particles kept per unit of expected count when resampling, ``≥ 1``.
    max_particles, min_particles
        Cap and floor of the particle count after resampling.
    extraction
        ``"attribution"`` (default: each measurement whose term of the update carries mass above
        ``attribution_threshold`` gives the weighted mean of that term) or ``"kmeans"``
        (weighted k-means with ``round(λ)`` clusters seeded at the highest-weight particles).
    attribution_threshold
        Mass a measurement's term needs to yield an estimate, in ``(0, ∞)``; 0.5 by default.
    kmeans_iterations
        Lloyd iterations of the k-means extraction, ``≥ 1``.
    kmeans_seed_radius_m
        Particles closer than this to a chosen seed cannot seed another cluster, ``> 0``.
    merge_radius_m
        Estimates closer than this are merged (matters with several sensors), ``≥ 0``.
    report_missed
        Attribution extraction also reports targets missed in this scan whose Bernoulli
        existence passes ``attribution_threshold`` (see :mod:`searchtrack.estimate.phd.update`).
    region
        Optional ``(p, 2)`` surveillance region ``[[x0, x1], [y0, y1], ...]`` (m): particles
        predicted outside it are dropped. ``None``: no region.
    backend
        ``"numba"`` (default): compiled passes over the particles for the nearly-constant-velocity
        motion, the Gaussian position sensor and the resampling, falling back to the NumPy
        equations for other models; ``"numpy"``: the NumPy reference equations throughout. Both
        give the same particles from the same generator, up to floating-point rounding.
    """

    survival_probability: float = 0.99
    survival_map: SurvivalMap | None = None
    birth_mass: float = 0.25
    adaptive_birth: bool = False
    birth_particles_per_measurement: int = 60
    birth_position_sigma_m: float = 10.0
    birth_velocity_sigma_mps: float = 5.0
    birth_grid: BirthGrid | None = None
    particles_per_target: int = 400
    max_particles: int = 10_000
    min_particles: int = 100
    extraction: str = "attribution"
    attribution_threshold: float = 0.5
    kmeans_iterations: int = 5
    kmeans_seed_radius_m: float = 30.0
    merge_radius_m: float = 0.0
    report_missed: bool = True
    region: FloatArray | None = None
    backend: str = "numba"

    def __post_init__(self) -> None:
        c = checks
        object.__setattr__(self, "survival_probability", c.real(
            "survival_probability", self.survival_probability, low=0.0, high=1.0, low_open=True))
        if self.survival_map is not None and not isinstance(self.survival_map, SurvivalMap):
            raise InvalidInputError("survival_map", self.survival_map,
                                    "must have a survival(positions, dt_s) method, or be None")
        object.__setattr__(self, "birth_mass", c.non_negative("birth_mass", self.birth_mass))
        c.boolean("adaptive_birth", self.adaptive_birth)
        if self.adaptive_birth and self.birth_mass > 1.0:
            raise InvalidInputError("birth_mass", self.birth_mass,
                                    "must be ≤ 1 with adaptive_birth (mass per measurement)")
        object.__setattr__(self, "birth_particles_per_measurement", c.count(
            "birth_particles_per_measurement", self.birth_particles_per_measurement, 1))
        for name in ("birth_position_sigma_m", "birth_velocity_sigma_mps",
                     "kmeans_seed_radius_m", "attribution_threshold"):
            object.__setattr__(self, name, c.positive(name, getattr(self, name)))
        if self.birth_grid is not None and not isinstance(self.birth_grid, BirthGrid):
            raise InvalidInputError("birth_grid", self.birth_grid, "must be a BirthGrid or None")
        for name in ("particles_per_target", "max_particles", "min_particles",
                     "kmeans_iterations"):
            object.__setattr__(self, name, c.count(name, getattr(self, name), 1))
        if self.min_particles > self.max_particles:
            raise InvalidInputError("min_particles", self.min_particles,
                                    f"must be ≤ max_particles = {self.max_particles}")
        if self.backend not in BACKENDS:
            raise InvalidInputError("backend", self.backend, f"must be one of {BACKENDS}")
        if self.extraction not in EXTRACTIONS:
            raise InvalidInputError("extraction", self.extraction, f"must be one of {EXTRACTIONS}")
        object.__setattr__(self, "merge_radius_m",
                           c.non_negative("merge_radius_m", self.merge_radius_m))
        c.boolean("report_missed", self.report_missed)
        if self.region is not None:
            r = np.array(self.region, dtype=np.float64)
            if r.ndim != 2 or r.shape[1] != 2 or not np.all(np.isfinite(r)) or not np.all(
                    r[:, 1] > r[:, 0]):
                raise InvalidInputError("region", self.region, "must be (p, 2) with low < high")
            r.setflags(write=False)
            object.__setattr__(self, "region", r)
