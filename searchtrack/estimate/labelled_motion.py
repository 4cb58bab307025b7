"""The jump-Markov step of the labelled particles (eqs. 46–47) as one Numba pass.

:func:`propagate` is :func:`searchtrack.models.radio.motion.propagate` for ``(B, N)`` particle
arrays, draw for draw: the same NumPy generator calls in the same order (kinematic noise
``(B, N, 4)``, mode-jump uniforms ``(B, N)``, τ-step normals ``(B, N)``), so equal seeds give
equal particles; the arithmetic is done in one pass that writes straight into the caller's
arrays (the prediction's first ``N`` columns, ahead of the birth particles) instead of through
NumPy temporaries. Per axis, with the previous mode: WD (eq. 46) ``p' = p + σ_p n_p``,
``v' = σ_v n_v``; CV (eq. 47) ``p' = p + T0 v + c00 n_p``, ``v' = v + c10 n_p + c11 n_v`` with
``[[c00, 0], [c10, c11]]`` the Cholesky factor of ``σ_CV² [[T0³/3, T0²/2], [T0²/2, T0]]``;
then the mode flips with probability ``P[s, 1 − s]``, and ``τ' = (τ + σ_τ T0 n_τ) mod T0``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.radio.motion import TagMotion

ModeArray = NDArray[np.int8]


def _scales(motion: TagMotion) -> FloatArray:
    """``[σ_p, σ_v, c00, c10, c11, T0, σ_τ T0]``: WD stds, the CV per-axis Cholesky factor
    (the expressions of :mod:`searchtrack.models.radio.motion`), the step and the τ std."""
    t, sigma = motion.period_s, motion.cv_accel_std
    c00 = sigma * math.sqrt(t**3 / 3.0)
    c10 = sigma * (t**2 / 2.0) / math.sqrt(t**3 / 3.0)
    c11 = sigma * math.sqrt(t) / 2.0
    return np.array([math.sqrt(motion.wd_position_var), math.sqrt(motion.wd_velocity_var),
                     c00, c10, c11, t, motion.tau_std * t])


@njit(cache=True)
def _step(x: FloatArray, mode: ModeArray, tau: FloatArray, noise: FloatArray, jump: FloatArray,
          tau_noise: FloatArray, scales: FloatArray, flip: FloatArray, out_x: FloatArray,
          out_mode: ModeArray, out_tau: FloatArray) -> None:
    """The step of the module notes for ``(B, N)`` particles, into ``out_*`` (may be views);
    ``flip[s]`` is the probability of leaving mode ``s``."""
    sd_p, sd_v, c00, c10, c11, t, sd_tau = (scales[0], scales[1], scales[2], scales[3],
                                            scales[4], scales[5], scales[6])
    rows, n = mode.shape
    for b in range(rows):
        for i in range(n):
            s = mode[b, i]
            for p in (0, 2):
                n_p, n_v = noise[b, i, p], noise[b, i, p + 1]
                if s == 1:
                    out_x[b, i, p] = x[b, i, p] + (t * x[b, i, p + 1] + c00 * n_p)
                    out_x[b, i, p + 1] = x[b, i, p + 1] + c10 * n_p + c11 * n_v
                else:
                    out_x[b, i, p] = x[b, i, p] + sd_p * n_p
                    out_x[b, i, p + 1] = sd_v * n_v
            out_mode[b, i] = 1 - s if jump[b, i] < flip[s] else s
            wrapped = (tau[b, i] + sd_tau * tau_noise[b, i]) % t
            out_tau[b, i] = 0.0 if wrapped >= t else wrapped


def propagate(motion: TagMotion, x: FloatArray, mode: ModeArray, tau: FloatArray,
              rng: np.random.Generator, *,
              out: tuple[FloatArray, ModeArray, FloatArray] | None = None,
              ) -> tuple[FloatArray, ModeArray, FloatArray]:
    """One step of every particle: kinematics with the previous mode, a mode jump, a τ step.

    Parameters
    ----------
    motion
        The motion model.
    x, mode, tau
        ``(B, N, 4)`` states ``[px, vx, py, vy]``, ``(B, N)`` modes (0 = WD, 1 = CV) and
        ``(B, N)`` pulse offsets (s); left unchanged.
    rng
        Source of randomness, drawn as :func:`searchtrack.models.radio.motion.propagate` does.
    out
        ``(x', mode', τ')`` arrays of the input shapes (float64, int8, float64; views allowed)
        to write into; new arrays when ``None``.

    Returns
    -------
    ``(x', mode', τ')`` (``out`` when given); ``τ'`` lies in ``[0, T0)``.

    Raises
    ------
    InvalidInputError
        On inconsistent shapes, modes other than 0 and 1, or ``out`` arrays of the wrong
        shape or type.
    """
    rng = checks.generator("rng", rng)
    xa = np.asarray(x, dtype=np.float64)
    if xa.ndim != 3 or xa.shape[2] != 4:
        raise InvalidInputError("x", xa.shape, "must have shape (B, N, 4): [px, vx, py, vy]")
    ma, ta = np.asarray(mode), np.asarray(tau, dtype=np.float64)
    if ma.shape != xa.shape[:2]:
        raise InvalidInputError("mode", ma.shape, f"must have the shape {xa.shape[:2]} of x")
    if ma.size and (ma.dtype.kind not in "iu" or ma.min() < 0 or ma.max() > 1):
        raise InvalidInputError("mode", ma.dtype, "must hold integer modes 0 (WD) or 1 (CV)")
    if ta.shape != ma.shape:
        raise InvalidInputError("tau", ta.shape, f"must have the shape {ma.shape} of mode")
    if out is None:
        out = (np.empty_like(xa), np.empty(ma.shape, np.int8), np.empty_like(ta))
    shapes = [a.shape for a in out] == [xa.shape, ma.shape, ta.shape]
    if not shapes or [a.dtype for a in out] != [np.float64, np.int8, np.float64]:
        raise InvalidInputError("out", [(a.shape, a.dtype) for a in out],
                                "must be float64, int8, float64 arrays shaped as x, mode, tau")
    noise = rng.standard_normal(xa.shape)
    jump = rng.random(ma.shape)
    tau_noise = rng.standard_normal(ta.shape)
    trans = motion.transition_matrix
    _step(xa, ma.astype(np.int8, copy=False), ta, noise, jump, tau_noise, _scales(motion),
          np.array([trans[0, 1], trans[1, 0]]), *out)
    return out
