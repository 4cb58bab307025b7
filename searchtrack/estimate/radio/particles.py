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

The store :class:`LabelledParticles`, :func:`update` and :func:`resample` are the belief seam's
(:mod:`searchtrack.estimate.labelled_particles`, where planners read them); they are
re-exported here with the filter's own steps, :func:`birth_particles`, :func:`initial_state`
and :func:`predict`.

Once a label's evidence exceeds about 32 nats, float64 rounds its updated ``r`` to exactly 1, so
``1 − r`` and with it the birth term would vanish for good and a track locked onto a wrong
hypothesis (say, the right pulse frame at a wrong birth site) could never be re-born at the
right one. The birth term therefore uses ``max(1 − r, 1e-12)``: a departure from the exact
recursion far below anything a read-out can show.
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.types import FloatArray
from searchtrack.estimate.labelled_motion import propagate
from searchtrack.estimate.labelled_particles import N_MODES, LabelledParticles, resample, update
from searchtrack.estimate.radio.birth_proposal import draw_tau
from searchtrack.models.radio.scenario import RadioScenario

__all__ = ["N_MODES", "LabelledParticles", "birth_particles", "initial_state", "predict",
           "resample", "update"]

log = logging.getLogger("searchtrack.estimate.radio.particles")

#: Floor on the non-existence ``1 − r`` entering the birth term (see :func:`predict`).
_MIN_ABSENCE = 1e-12


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
    above). The motion step is :func:`~searchtrack.estimate.labelled_motion.propagate` (the
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
