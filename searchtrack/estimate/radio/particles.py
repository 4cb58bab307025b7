"""Labelled particles: one Bernoulli particle filter per tag label, all labels in one array.

Nguyen et al.'s JMS TBD-LMB filter (§III-C) keeps, for every known label ``λ`` (a tag
frequency), an existence probability ``r_λ`` and a density over ``(x, s, τ)``: the state
``[px, vx, py, vy]``, the motion mode ``s`` (0 = WD, eq. 46; 1 = CV, eq. 47) and the pulse
offset ``τ``. Under the separable likelihood (Proposition 1) the LMB prediction (eqs. 24–27) and
update (eqs. 28–30) never couple labels, so the filter is a bank of Bernoulli filters; here they
share ``(Λ, N, ...)`` arrays so every step is vectorised across labels.

Births (one Bernoulli per known label, re-born by mixing): the predicted existence is
``r⁺ = p_S r + r_B (1 − r)`` and the predicted density the mixture
``(p_S r p_E + r_B (1 − r) p_B) / r⁺`` of the propagated density ``p_E`` (eq. 26) and the birth
density ``p_B``: the equal mixture of the scenario's birth Gaussians, the mode from the initial
mode probabilities and ``τ`` uniform on ``[0, T0)``. :func:`predict` appends ``n_birth`` birth
particles per label carrying the birth share of the weight, :func:`update` applies eqs. 29–30 in
log space and :func:`resample` (systematic, per label) brings every label back to ``N``.

Once a label's evidence exceeds about 32 nats, float64 rounds its updated ``r`` to exactly 1, so
``1 − r`` and with it the birth term would vanish for good and a track locked onto a wrong
hypothesis (say, the right pulse frame at a wrong birth site) could never be re-born at the
right one. The birth term therefore uses ``max(1 − r, 1e-12)``: a departure from the exact
recursion far below anything a read-out can show.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.radio.birth_proposal import draw_tau
from searchtrack.estimate.radio.propagation import propagate
from searchtrack.models.radio import RadioSignal
from searchtrack.models.radio.scenario import RadioScenario

log = logging.getLogger("searchtrack.estimate.radio.particles")

#: Number of motion modes (0 = WD, 1 = CV).
N_MODES = 2
#: Floor on the non-existence ``1 − r`` entering the birth term (see :func:`predict`).
_MIN_ABSENCE = 1e-12


@dataclass
class LabelledParticles:
    """The particle LMB density: per label ``λ`` a weighted particle set and an existence ``r_λ``.

    Parameters
    ----------
    x
        ``(Λ, N, 4)`` states ``[px, vx, py, vy]`` (m, m/s).
    mode
        ``(Λ, N)`` motion modes (0 = WD, 1 = CV).
    tau
        ``(Λ, N)`` pulse offsets (s) in ``[0, T0)``.
    w
        ``(Λ, N)`` weights, each row normalised to 1.
    r
        ``(Λ,)`` existence probabilities.
    """

    x: FloatArray
    mode: NDArray[np.int8]
    tau: FloatArray
    w: FloatArray
    r: FloatArray

    def __post_init__(self) -> None:
        if self.x.ndim != 3 or self.x.shape[2] != 4:
            raise InvalidInputError("x", self.x.shape, "must have shape (Λ, N, 4)")
        n_labels, n = self.x.shape[:2]
        for name in ("mode", "tau", "w"):
            if getattr(self, name).shape != (n_labels, n):
                raise InvalidInputError(name, getattr(self, name).shape,
                                        f"must have shape ({n_labels}, {n})")
        if self.r.shape != (n_labels,):
            raise InvalidInputError("r", self.r.shape, f"must have shape ({n_labels},)")

    @property
    def n_labels(self) -> int:
        """Number of labels ``Λ``."""
        return int(self.x.shape[0])

    @property
    def n_particles(self) -> int:
        """Particles per label ``N``."""
        return int(self.x.shape[1])

    def copy(self) -> LabelledParticles:
        """A deep copy (writable arrays)."""
        return LabelledParticles(self.x.copy(), self.mode.copy(), self.tau.copy(), self.w.copy(),
                                 self.r.copy())

    def mean_xy(self) -> FloatArray:
        """``(Λ, 2)`` weighted mean ground position ``(px, py)`` of each label (m)."""
        return np.asarray(np.einsum("ln,lnk->lk", self.w, self.x[:, :, ::2]), dtype=np.float64)

    def frame_mode(self, signal: RadioSignal) -> IntArray:
        """``(Λ,)`` weighted mode of the pulse frame ``m(τ)`` (eq. 16) of each label (the
        lowest frame on ties)."""
        frames = np.asarray(signal.frame_of(self.tau), dtype=np.int64)
        low = int(frames.min())
        span = int(frames.max()) - low + 1
        rows = np.arange(self.n_labels)[:, None] * span
        mass = np.bincount((rows + frames - low).ravel(), weights=self.w.ravel(),
                           minlength=self.n_labels * span).reshape(self.n_labels, span)
        return np.asarray(mass.argmax(axis=1) + low, dtype=np.int64)

    def cardinality(self) -> FloatArray:
        """``(Λ + 1,)`` distribution of the number of objects: the Poisson-binomial law of
        ``Σ_λ Bernoulli(r_λ)`` (the LMB cardinality, §II-B)."""
        dist = np.zeros(self.n_labels + 1)
        dist[0] = 1.0
        for r in self.r:
            dist[1:] = dist[1:] * (1.0 - r) + dist[:-1] * r
            dist[0] *= 1.0 - r
        return dist

    def mode_probabilities(self) -> FloatArray:
        """``(Λ, 2)`` posterior probability of each motion mode (WD, CV) per label."""
        return np.stack([(self.w * (self.mode == j)).sum(axis=1) for j in range(N_MODES)],
                        axis=1)


def birth_particles(scenario: RadioScenario, n: int,
                    rng: np.random.Generator) -> tuple[FloatArray, NDArray[np.int8], FloatArray]:
    """``n`` draws from the birth density: ``(x (n, 4), mode (n,), tau (n,))``.

    ``x`` from the equal mixture of Gaussians with the scenario's ``birth_means`` and covariance
    ``diag(birth_cov_diag)``; the mode from ``motion.initial_mode``; ``τ`` uniform on
    ``[0, T0)``.
    """
    n = checks.count("n", n)
    rng = checks.generator("rng", rng)
    means = np.asarray(scenario.birth_means, dtype=np.float64)
    std = np.sqrt(np.asarray(scenario.birth_cov_diag, dtype=np.float64))
    component = rng.integers(0, means.shape[0], n)
    x = means[component] + rng.standard_normal((n, 4)) * std
    p_cv = float(scenario.motion.initial_mode[1])
    mode = (rng.random(n) < p_cv).astype(np.int8)
    tau = rng.random(n) * scenario.signal.period_s
    return x, mode, tau


def initial_state(scenario: RadioScenario, n: int, rng: np.random.Generator) -> LabelledParticles:
    """The state before the first measurement: every label ``r = r_B``, ``n`` particles from the
    birth density with equal weights."""
    n = checks.count("n", n, least=1)
    n_labels = scenario.signal.n_labels
    x, mode, tau = birth_particles(scenario, n_labels * n, rng)
    return LabelledParticles(x.reshape(n_labels, n, 4), mode.reshape(n_labels, n),
                             tau.reshape(n_labels, n), np.full((n_labels, n), 1.0 / n),
                             np.full(n_labels, float(scenario.birth_probability)))


def predict(state: LabelledParticles, scenario: RadioScenario, rng: np.random.Generator, *,
            n_birth: int, tau_proposal: FloatArray | None = None) -> LabelledParticles:
    """Eqs. 24–27 with re-birth: propagate every particle, append ``n_birth`` birth particles per
    label and mix.

    Survivors keep their relative weights and carry ``p_S r / r⁺`` in total, the birth particles
    share ``r_B (1 − r) / r⁺`` equally, with ``r⁺ = p_S r + r_B (1 − r)`` (``1 − r`` floored at
    1e-12, see the module notes). The result has ``N + n_birth`` particles per label; the input
    is unchanged. With ``n_birth = 0`` the density is the propagated one alone (``r⁺`` as
    above). The motion step is :func:`~searchtrack.estimate.radio.propagation.propagate` (the
    motion model's draws, then the births').

    ``tau_proposal`` (``(Λ, C)`` over the τ cells of
    :mod:`~searchtrack.estimate.radio.birth_proposal`) draws the births' offsets from it instead
    of the uniform birth density; their shares of ``r_B (1 − r) / r⁺`` are then the importance
    ratios ``p_B / q``, self-normalised, so the predicted density is unchanged in expectation.
    """
    n_birth = checks.count("n_birth", n_birth)
    rng = checks.generator("rng", rng)
    n_labels, n = state.n_labels, state.n_particles
    size = n + n_birth
    x, tau = np.empty((n_labels, size, 4)), np.empty((n_labels, size))
    mode = np.empty((n_labels, size), dtype=np.int8)
    propagate(scenario.motion, state.x, state.mode, state.tau, rng,
              out=(x[:, :n], mode[:, :n], tau[:, :n]))
    p_s, r_b = float(scenario.survival_probability), float(scenario.birth_probability)
    surv = p_s * state.r
    born = r_b * np.maximum(1.0 - state.r, _MIN_ABSENCE)
    r_pred = surv + born
    w = np.empty((n_labels, size))
    if n_birth:
        np.multiply(state.w, (surv / r_pred)[:, None], out=w[:, :n])
        bx, bmode, btau = birth_particles(scenario, n_labels * n_birth, rng)
        x[:, n:] = bx.reshape(n_labels, n_birth, 4)
        mode[:, n:] = bmode.reshape(n_labels, n_birth)
        if tau_proposal is None:
            tau[:, n:] = btau.reshape(n_labels, n_birth)
            w[:, n:] = (born / r_pred / n_birth)[:, None]
        else:
            tau[:, n:], ratio = draw_tau(scenario.signal, tau_proposal, n_birth, rng)
            w[:, n:] = ratio * (born / r_pred / ratio.sum(axis=1))[:, None]
    else:
        w[:] = state.w
    log.debug("predict: %d labels × %d particles + %d births", n_labels, n, n_birth)
    return LabelledParticles(x, mode, tau, w, r_pred)


def update(state: LabelledParticles, log_lik: FloatArray) -> LabelledParticles:
    """Eqs. 29–30 with per-particle log-likelihood ratios ``log_lik`` ``(Λ, N)`` (eq. 22).

    ``η_λ = Σ_i w_i g_i`` by log-sum-exp, ``r ← r η / (1 − r + r η)``, ``w_i ← w_i g_i / η``;
    finite for log-likelihoods of any magnitude. The input is unchanged.

    Raises
    ------
    InvalidInputError
        When ``log_lik`` is not a finite ``(Λ, N)`` array.
    """
    ll = np.asarray(log_lik, dtype=np.float64)
    if ll.shape != state.w.shape:
        raise InvalidInputError("log_lik", ll.shape, f"must have shape {state.w.shape}")
    if not np.all(np.isfinite(ll)):
        raise InvalidInputError("log_lik", ll.shape, "must be finite")
    with np.errstate(divide="ignore"):
        logw = np.log(state.w) + ll
        peak = logw.max(axis=1, keepdims=True)
        w = np.exp(logw - peak)
        mass = w.sum(axis=1)
        w /= mass[:, None]
        log_eta = peak[:, 0] + np.log(mass)
        a = np.log(state.r) + log_eta
        b = np.log1p(-state.r)
    r = np.exp(a - np.logaddexp(a, b))
    return LabelledParticles(state.x, state.mode, state.tau, w, r)


def resample(state: LabelledParticles, rng: np.random.Generator, n: int) -> LabelledParticles:
    """Systematic resampling of every label to ``n`` equally weighted particles (``r`` kept)."""
    n = checks.count("n", n, least=1)
    rng = checks.generator("rng", rng)
    n_labels = state.n_labels
    idx = _systematic(state.w, rng.random(n_labels), n)
    x, tau = np.empty((n_labels, n, 4)), np.empty((n_labels, n))
    mode = np.empty((n_labels, n), dtype=state.mode.dtype)
    _gather(np.asarray(state.x, dtype=np.float64), state.mode,
            np.asarray(state.tau, dtype=np.float64), idx, x, mode, tau)
    return LabelledParticles(x, mode, tau, np.full((n_labels, n), 1.0 / n), state.r.copy())


@njit(cache=True)
def _gather(x: FloatArray, mode: NDArray[np.integer[Any]], tau: FloatArray, idx: IntArray,
            out_x: FloatArray, out_mode: NDArray[np.integer[Any]], out_tau: FloatArray) -> None:
    """``out_*[b, j] = *[b, idx[b, j]]``: row-wise copies of the chosen particles."""
    for b in range(idx.shape[0]):
        for j in range(idx.shape[1]):
            k = idx[b, j]
            for c in range(4):
                out_x[b, j, c] = x[b, k, c]
            out_mode[b, j] = mode[b, k]
            out_tau[b, j] = tau[b, k]


@njit(cache=True)
def _systematic(w: FloatArray, u: FloatArray, n: int) -> IntArray:
    """``(B, n)`` systematic resampling indices of each row of weights ``w`` ``(B, m)``: row
    ``b`` takes, for ``j = 0..n−1``, the first particle whose cumulative weight exceeds
    ``(u_b + j) / n`` of the row's total, for offsets ``u`` ``(B,)`` in ``[0, 1)``."""
    rows, m = w.shape
    idx = np.empty((rows, n), dtype=np.int64)
    for b in range(rows):
        total = 0.0
        for i in range(m):
            total += w[b, i]
        k = 0
        cum = w[b, 0]
        for j in range(n):
            target = (u[b] + j) / n * total
            while cum <= target and k < m - 1:
                k += 1
                cum += w[b, k]
            idx[b, j] = k
    return idx
