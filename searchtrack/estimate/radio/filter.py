"""The labelled particle LMB filter shared by the radio-tag filters of Nguyen et al.

The JMS TBD-LMB filter (§III-C) and the detection-then-track baseline (§IV-B) run the same
recursion on the labelled particles of :mod:`searchtrack.estimate.labelled_particles`, one step
per STFT magnitude matrix ``z`` (``M × L``, eq. 11) taken from a UAV pose:
:func:`~searchtrack.estimate.radio.particles.predict` (eqs. 24–27 with re-birth, ``n_birth =
birth_fraction · N`` birth particles per label), a per-particle log-likelihood ratio,
:func:`~searchtrack.estimate.labelled_particles.update` (eqs. 29–30) and systematic resampling
(:func:`~searchtrack.estimate.labelled_particles.resample`) back to ``N`` particles per label.
They differ only in the log-likelihood ratios, so :class:`LabelledFilter` takes them as a
function (:data:`LogLikelihood`) of the checked ``z``, the pose and the predicted particles:
eq. 22 on the raw cells
(:class:`~searchtrack.estimate.radio.tbd.TbdLmbFilter`) or the detection likelihood on the peaks
(:class:`~searchtrack.estimate.radio.dtt.DttLmbFilter`).

Read-outs: a label is reported when ``r > existence_threshold`` at its weighted mean position;
the number of objects is Poisson-binomial (mean ``Σ r``, variance ``Σ r (1 − r)``). The filter is
a :class:`~searchtrack.estimate.belief.LabelledParticleBelief` (``x``, ``mode``, ``tau``, ``w``,
``r`` of its current state: what the radio planners read) and a
:class:`~searchtrack.estimate.particle_belief.ParticleBelief` (positions of all ``Λ·N``
particles, weights ``r_λ w_i`` summing to ``Σ r``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.labelled_particles import LabelledParticles, resample, update
from searchtrack.estimate.radio.particles import initial_state, predict
from searchtrack.models.radio.scenario import RadioScenario

log = logging.getLogger("searchtrack.estimate.radio.filter")

BirthProposal = Callable[[FloatArray, FloatArray], FloatArray]
"""``(z (M, L), uav_pose (3,)) -> (Λ, C)`` proposal over the τ cells for this step's birth
particles (:mod:`~searchtrack.estimate.radio.birth_proposal`); called before the likelihood."""

MAX_PARTICLES_PER_LABEL = 1_000_000
"""Most particles per label ``N`` (20 times the paper's 50 000)."""

MAX_PARTICLES = 2**23
"""Most particles ``Λ·N`` of one filter (about 8.4 million: the paper's four labels at two
million each would exceed it)."""

LogLikelihood = Callable[[FloatArray, FloatArray, LabelledParticles], FloatArray]
"""``(z (M, L), uav_pose (3,), predicted particles) -> (Λ, N)`` finite log-likelihood ratios of
every predicted particle; given checked inputs, it must not raise nor draw random numbers."""


@dataclass(frozen=True)
class FilterConfig:
    """Particle budget and read-out of the labelled particle LMB filters.

    Parameters
    ----------
    particles_per_label
        ``N``: particles per label after resampling (the paper's ``N_s`` = 50 000), at most
        :data:`MAX_PARTICLES_PER_LABEL`.
    birth_fraction
        Birth particles appended per label at each prediction, as a fraction of ``N`` in
        ``(0, 1]`` (at least one particle).
    existence_threshold
        A label is reported when its existence probability exceeds this, in ``(0, 1)``.
    data_driven_births
        Draw the birth particles' pulse offsets from the filter's measurement-driven proposal,
        reweighted to the uniform birth density (:mod:`.birth_proposal`); ``False``: the uniform
        draw of the paper's birth density.
    roughening_m
        ``σ_r ≥ 0`` (m): after resampling, every particle's ground position is jittered by
        ``N(0, σ_r²)`` per axis (roughening, Gordon, Salmond and Smith 1993, at a fixed
        width). At high SNR the likelihood resolves a tag's position to well under a metre, the
        resampled cloud collapses onto one particle (spread 0), and a collapsed cloud that
        drifts from its object cannot come back; the jitter keeps it wide enough to follow.
        Gordon et al.'s width ``K E N^{−1/4}`` is not used: a label's extent ``E`` (largest
        minus smallest coordinate) is set by its few farthest particles, and jittering a
        well-localised cloud by it costs tracking accuracy. 0 (default): the paper's filter,
        no roughening.
    temper
        ``β ∈ (0, 1]``: the update uses ``g^β``, the log-likelihood ratios times ``β`` (a
        tempered likelihood). 1 is the paper's. Spectrograms computed from a real signal have
        correlated neighbouring bins, which eq. 22 counts as independent evidence; ``β`` below
        1 counts them as their effective number
        (:func:`~searchtrack.estimate.radio.likelihood.correlated_cells_temper`).
    """

    particles_per_label: int = 50_000
    birth_fraction: float = 0.1
    existence_threshold: float = 0.5
    data_driven_births: bool = True
    roughening_m: float = 0.0
    temper: float = 1.0

    def __post_init__(self) -> None:
        n = checks.count("particles_per_label", self.particles_per_label, least=1)
        if n > MAX_PARTICLES_PER_LABEL:
            raise InvalidInputError("particles_per_label", n,
                                    f"must be an integer in [1, {MAX_PARTICLES_PER_LABEL}]")
        object.__setattr__(self, "birth_fraction", checks.real(
            "birth_fraction", self.birth_fraction, low=0.0, high=1.0, low_open=True))
        object.__setattr__(self, "existence_threshold", checks.probability(
            "existence_threshold", self.existence_threshold))
        object.__setattr__(self, "roughening_m", checks.real(
            "roughening_m", self.roughening_m, low=0.0, high=1e4))
        object.__setattr__(self, "temper", checks.real("temper", self.temper, low=0.0,
                                                       high=1.0, low_open=True))
        if not isinstance(self.data_driven_births, bool):
            raise InvalidInputError("data_driven_births", self.data_driven_births,
                                    "must be true or false")

    @property
    def n_birth(self) -> int:
        """Birth particles per label and step, ``max(1, round(birth_fraction · N))``."""
        return max(1, round(self.birth_fraction * self.particles_per_label))


def roughen(state: LabelledParticles, sigma_m: float, rng: np.random.Generator) -> None:
    """Jitter the ground positions of ``state``'s particles in place by ``N(0, σ²)`` per axis,
    ``σ = sigma_m`` (:attr:`FilterConfig.roughening_m`); velocities and pulse times are kept."""
    x = state.x
    for axis in (0, 2):
        x[:, :, axis] += sigma_m * rng.standard_normal(x.shape[:2])


def _frozen(state: LabelledParticles) -> LabelledParticles:
    for arr in (state.x, state.mode, state.tau, state.w, state.r):
        arr.setflags(write=False)
    return state


class LabelledFilter:
    """Labelled particle LMB filter over the scenario's known labels (tag frequencies).

    The initial state (before the first step) has ``r = r_B`` for every label and particles
    drawn from the birth density.

    Parameters
    ----------
    scenario
        Signal, motion, birth and survival models (:class:`~searchtrack.models.radio.
        RadioScenario`).
    config
        Particle budget and read-out.
    likelihood
        The update's log-likelihood ratios (:data:`LogLikelihood`).
    proposal
        The births' τ proposal (:data:`BirthProposal`), used when the configuration asks for
        data-driven births; ``None``: uniform births.
    seed
        Seed of the filter's random generator: equal seeds and inputs give equal states.
    """

    def __init__(self, scenario: RadioScenario, config: FilterConfig | None = None, *,
                 likelihood: LogLikelihood, proposal: BirthProposal | None = None,
                 seed: int = 0) -> None:
        if not isinstance(scenario, RadioScenario):
            raise InvalidInputError("scenario", scenario, "must be a RadioScenario")
        config = FilterConfig() if config is None else config
        if not isinstance(config, FilterConfig):
            raise InvalidInputError("config", config, "must be a FilterConfig")
        if not callable(likelihood):
            raise InvalidInputError("likelihood", likelihood, "must be callable")
        total = scenario.signal.n_labels * config.particles_per_label
        if total > MAX_PARTICLES:
            raise InvalidInputError("particles_per_label", config.particles_per_label,
                                    f"{scenario.signal.n_labels} labels × "
                                    f"{config.particles_per_label} = {total} particles exceed "
                                    f"the {MAX_PARTICLES} a filter may hold")
        self.scenario = scenario
        self.config = config
        self._likelihood = likelihood
        self._proposal = proposal if config.data_driven_births else None
        self._rng = np.random.default_rng(checks.count("seed", seed))
        self._state = _frozen(initial_state(scenario, config.particles_per_label, self._rng))
        self._positions: FloatArray | None = None
        self._steps = 0

    @property
    def state(self) -> LabelledParticles:
        """The current particle LMB (read-only arrays; :meth:`labelled_particles` for a copy)."""
        return self._state

    @property
    def steps(self) -> int:
        """Number of measurements processed so far."""
        return self._steps

    def labelled_particles(self) -> LabelledParticles:
        """A writable copy of the current particle LMB."""
        return self._state.copy()

    @property
    def x(self) -> FloatArray:
        """``(Λ, N, 4)`` particle states of the current particle LMB (read-only)."""
        return self._state.x

    @property
    def mode(self) -> NDArray[np.int8]:
        """``(Λ, N)`` motion modes of the current particle LMB (read-only)."""
        return self._state.mode

    @property
    def tau(self) -> FloatArray:
        """``(Λ, N)`` pulse offsets (s) of the current particle LMB (read-only)."""
        return self._state.tau

    @property
    def w(self) -> FloatArray:
        """``(Λ, N)`` per-label particle weights, each row summing to 1 (read-only)."""
        return self._state.w

    @property
    def r(self) -> FloatArray:
        """``(Λ,)`` existence probabilities (read-only)."""
        return self._state.r

    def step(self, z: FloatArray, uav_pose: ArrayLike) -> None:
        """Predict, update with the STFT magnitudes ``z`` ``(M, L)`` taken at ``uav_pose``
        ``(x, y, heading)``, and resample.

        Raises
        ------
        InvalidInputError
            ``z`` not a finite non-negative ``(M, L)`` array, or a pose that is not three finite
            numbers; the state and the random generator are then unchanged.
        """
        signal = self.scenario.signal
        zz = checks.finite_array("z", z, (signal.frames, signal.fft_size))
        if np.any(zz < 0.0):
            raise InvalidInputError("z", zz.shape, "STFT magnitudes must be non-negative")
        pose = checks.finite_array("uav_pose", uav_pose, (3,))
        q = None if self._proposal is None else self._proposal(zz, pose)
        pred = predict(self._state, self.scenario, self._rng, n_birth=self.config.n_birth,
                       tau_proposal=q)
        post = update(pred, self._likelihood(zz, pose, pred))
        state = resample(post, self._rng, self.config.particles_per_label)
        if self.config.roughening_m > 0.0:
            roughen(state, self.config.roughening_m, self._rng)
        self._state = _frozen(state)
        self._positions = None
        self._steps += 1
        if log.isEnabledFor(logging.DEBUG):
            log.debug("%s step %d: r = %s", type(self).__name__, self._steps,
                      np.array2string(self._state.r, precision=4))

    def estimates(self) -> list[tuple[int, FloatArray]]:
        """``(label, xy)`` of every label with ``r > existence_threshold``, at its weighted mean
        ground position (m)."""
        means = self._state.mean_xy()
        return [(int(lab), means[lab]) for lab in
                np.flatnonzero(self._state.r > self.config.existence_threshold)]

    def cardinality(self) -> FloatArray:
        """``(Λ + 1,)`` distribution of the number of objects (Poisson-binomial)."""
        return self._state.cardinality()

    def cardinality_mean(self) -> float:
        """Expected number of objects ``Σ r``."""
        return float(self._state.r.sum())

    def cardinality_variance(self) -> float:
        """Variance of the number of objects ``Σ r (1 − r)``."""
        r = self._state.r
        return float((r * (1.0 - r)).sum())

    @property
    def positions(self) -> FloatArray:
        """``(Λ·N, 2)`` ground positions of all particles, label by label (read-only)."""
        if self._positions is None:
            pos = np.ascontiguousarray(self._state.x[:, :, ::2]).reshape(-1, 2)
            pos.setflags(write=False)
            self._positions = pos
        return self._positions

    @property
    def weights(self) -> FloatArray:
        """``(Λ·N,)`` particle masses ``r_λ w_i``, summing to :meth:`expected_count`."""
        w = (self._state.r[:, None] * self._state.w).ravel()
        w.setflags(write=False)
        return w

    def expected_count(self) -> float:
        """Expected number of objects ``Σ r``."""
        return self.cardinality_mean()
