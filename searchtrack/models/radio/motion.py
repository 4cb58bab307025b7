"""Jump-Markov motion of a radio-tagged object (Nguyen et al., §III-C, eqs. 46–47, Table II).

The state of one object is ``[px, vx, py, vy]`` (m, m/s) with a mode ``s ∈ {0 = WD, 1 = CV}``
and a pulse offset ``τ`` (s). One step of ``T0`` seconds:

* kinematics with the *previous* mode: wandering (eq. 46) ``x' = diag(1, 0, 1, 0) x + q``,
  ``q ~ N(0, diag(σ_p², σ_v², σ_p², σ_v²))`` — the velocity is forgotten and redrawn, so a
  switch to CV starts from a fresh velocity; constant velocity (eq. 47)
  ``x' = (I2 ⊗ [[1, T0], [0, 1]]) x + q``, ``q ~ N(0, σ_CV² I2 ⊗ [[T0³/3, T0²/2], [T0²/2, T0]])``
  (the Kronecker order of the paper's eq. 47 is swapped to match the state order above);
* then the mode jumps by the Markov chain ``mode_transition[s, s']``;
* ``τ`` takes a Gaussian random-walk step of standard deviation ``σ_τ T0`` and is wrapped into
  ``[0, T0)``.

All functions are vectorised over any leading shape and never modify their inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.radio.signal import MAX_PERIOD_S

#: Mode index of the wandering model (eq. 46).
WD = 0
#: Mode index of the constant-velocity model (eq. 47).
CV = 1

ModeArray = NDArray[np.int8]

#: Largest noise parameter (variances, ``σ_CV``, ``σ_τ``): squares and cubes stay finite.
MAX_NOISE = 1e6


def _distribution(name: str, value: object) -> tuple[float, float]:
    arr = checks.finite_array(name, value, (2,))  # type: ignore[arg-type]
    if np.any(arr < 0.0) or not math.isclose(float(arr.sum()), 1.0, abs_tol=1e-9):
        raise InvalidInputError(name, value, "must be two probabilities summing to 1")
    return float(arr[0]), float(arr[1])


@dataclass(frozen=True)
class TagMotion:
    """The jump-Markov WD/CV motion and the τ random walk (Table II defaults).

    Parameters
    ----------
    period_s
        The step ``T0`` (s).
    wd_position_var, wd_velocity_var
        Diagonal of ``Q^WD`` (m², (m/s)², eq. 46).
    cv_accel_std
        ``σ_CV`` of eq. 47 (m/s²).
    mode_transition
        Row-stochastic ``2 × 2`` matrix ``P[s, s']`` of the mode chain.
    initial_mode
        Probabilities of WD and CV at birth.
    tau_std
        ``σ_τ``: the τ step has standard deviation ``σ_τ T0`` (s).
    """

    period_s: float = 1.0
    wd_position_var: float = 0.25
    wd_velocity_var: float = 2.25
    cv_accel_std: float = 0.05
    mode_transition: tuple[tuple[float, float], tuple[float, float]] = ((0.99, 0.01),
                                                                        (0.01, 0.99))
    initial_mode: tuple[float, float] = (0.5, 0.5)
    tau_std: float = 1e-4

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "period_s", checks.real("period_s", self.period_s, low=0.0, low_open=True,
                                          high=MAX_PERIOD_S))
        for name in ("wd_position_var", "wd_velocity_var", "cv_accel_std", "tau_std"):
            put(self, name, checks.real(name, getattr(self, name), low=0.0, high=MAX_NOISE))
        rows = checks.finite_array("mode_transition", self.mode_transition,  # type: ignore[arg-type]
                                   (2, 2))
        put(self, "mode_transition", tuple(_distribution(f"mode_transition[{i}]", rows[i])
                                           for i in range(2)))
        put(self, "initial_mode", _distribution("initial_mode", self.initial_mode))

    @property
    def transition_matrix(self) -> FloatArray:
        """The ``(2, 2)`` mode transition matrix."""
        return np.array(self.mode_transition, dtype=np.float64)

    @cached_property
    def matrices(self) -> tuple[FloatArray, FloatArray]:
        """``(F, Q)``, each ``(2, 4, 4)``: transition and noise covariance of WD and CV."""
        t = self.period_s
        f_cv = np.kron(np.eye(2), np.array([[1.0, t], [0.0, 1.0]]))
        q_cv = self.cv_accel_std**2 * np.kron(np.eye(2), np.array([[t**3 / 3.0, t**2 / 2.0],
                                                                   [t**2 / 2.0, t]]))
        f_wd = np.diag([1.0, 0.0, 1.0, 0.0])
        q_wd = np.diag([self.wd_position_var, self.wd_velocity_var] * 2)
        f = checks.readonly(np.stack([f_wd, f_cv]), copy=False)
        q = checks.readonly(np.stack([q_wd, q_cv]), copy=False)
        return f, q

    @cached_property
    def _noise_scales(self) -> tuple[float, float, float, float, float]:
        """WD position/velocity stds and the CV per-axis Cholesky factor ``(c00, c10, c11)``."""
        t, sigma = self.period_s, self.cv_accel_std
        c00 = sigma * math.sqrt(t**3 / 3.0)
        c10 = sigma * (t**2 / 2.0) / math.sqrt(t**3 / 3.0)
        c11 = sigma * math.sqrt(t) / 2.0  # sqrt(T − (T²/2)² / (T³/3)) = sqrt(T/4)
        return math.sqrt(self.wd_position_var), math.sqrt(self.wd_velocity_var), c00, c10, c11


def _check_states(x: object, mode: object) -> tuple[FloatArray, ModeArray]:
    xa = np.asarray(x, dtype=np.float64)
    if xa.ndim < 1 or xa.shape[-1] != 4:
        raise InvalidInputError("x", xa.shape, "must have shape (..., 4): [px, vx, py, vy]")
    ma = _check_modes(mode)
    if ma.shape != xa.shape[:-1]:
        raise InvalidInputError("mode", ma.shape, f"must have the shape {xa.shape[:-1]} of x")
    return xa, ma


def _check_modes(mode: object) -> ModeArray:
    ma = np.asarray(mode)
    if ma.size and (ma.dtype.kind not in "iu" or ma.min() < 0 or ma.max() > 1):
        raise InvalidInputError("mode", mode, "must hold integer modes 0 (WD) or 1 (CV)")
    return ma.astype(np.int8)


def propagate_positions(motion: TagMotion, x: FloatArray, mode: ModeArray,
                        rng: np.random.Generator) -> FloatArray:
    """One step of the kinematics (eqs. 46–47) under each object's current mode.

    Parameters
    ----------
    motion
        The motion model.
    x
        ``(..., 4)`` states ``[px, vx, py, vy]``.
    mode
        ``(...)`` modes (0 = WD, 1 = CV) used for this step.
    rng
        Source of the process noise.

    Returns
    -------
    New ``(..., 4)`` states (the inputs are left unchanged).
    """
    xa, ma = _check_states(x, mode)
    checks.generator("rng", rng)
    sd_p, sd_v, c00, c10, c11 = motion._noise_scales
    t = motion.period_s
    noise = rng.standard_normal(xa.shape)
    cv = ma == CV
    out: FloatArray = np.empty_like(xa)
    for p, v in ((0, 1), (2, 3)):  # per axis; elementwise, vectorised over the leading shape
        n_p, n_v = noise[..., p], noise[..., v]
        out[..., p] = xa[..., p] + np.where(cv, t * xa[..., v] + c00 * n_p, sd_p * n_p)
        out[..., v] = np.where(cv, xa[..., v] + c10 * n_p + c11 * n_v, sd_v * n_v)
    return out


def jump_modes(motion: TagMotion, mode: ModeArray, rng: np.random.Generator) -> ModeArray:
    """The next modes drawn from the Markov chain ``mode_transition`` (same shape)."""
    ma = _check_modes(mode)
    checks.generator("rng", rng)
    switch = motion.transition_matrix[ma, 1 - ma]
    flip = rng.random(ma.shape) < switch
    out: ModeArray = np.where(flip, 1 - ma, ma).astype(np.int8)
    return out


def wrap_tau(motion: TagMotion, tau: FloatArray) -> FloatArray:
    """``τ`` wrapped into ``[0, T0)``."""
    t0 = motion.period_s
    out = np.mod(np.asarray(tau, dtype=np.float64), t0)
    result: FloatArray = np.where(out >= t0, 0.0, out)
    return result


def propagate(motion: TagMotion, x: FloatArray, mode: ModeArray, tau: FloatArray,
              rng: np.random.Generator) -> tuple[FloatArray, ModeArray, FloatArray]:
    """One full step: kinematics with the previous mode, a mode jump, a τ random-walk step.

    Parameters
    ----------
    motion
        The motion model.
    x, mode, tau
        ``(..., 4)`` states, ``(...)`` modes and ``(...)`` pulse offsets (s).
    rng
        Source of randomness (draws: kinematic noise, mode jumps, τ steps, in that order).

    Returns
    -------
    ``(x', mode', τ')``: new arrays of the same shapes; ``τ'`` lies in ``[0, T0)``.
    """
    xa, ma = _check_states(x, mode)
    ta = np.asarray(tau, dtype=np.float64)
    if ta.shape != ma.shape:
        raise InvalidInputError("tau", ta.shape, f"must have the shape {ma.shape} of mode")
    new_x = propagate_positions(motion, xa, ma, rng)
    new_mode = jump_modes(motion, ma, rng)
    step = motion.tau_std * motion.period_s * rng.standard_normal(ta.shape)
    return new_x, new_mode, wrap_tau(motion, ta + step)
