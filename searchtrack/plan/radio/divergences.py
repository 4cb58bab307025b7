"""Divergences and the void probability of labelled multi-Bernoulli densities on shared particles
(Nguyen et al., §III-D, eqs. 37–44).

Both densities of a label are represented on the same particles with different weights (eq. 39),
so every integral becomes a weighted sum (eq. 40). Because an LMB's label-set weight factorises,
``w(L) = Π_{λ∉L} (1 − r_λ) Π_{λ∈L} r_λ``, the sums over the ``2^|𝕃|`` label sets of eqs. 41, 43
and 44 factorise into one term per label:

* Rényi (eq. 41): ``D_R = 1/(α−1) Σ_λ log[(1−r₂)^α (1−r₁)^{1−α} + r₂^α r₁^{1−α} Σ_i ω₂^α ω₁^{1−α}]``
  for ``α > 0, α ≠ 1``; at ``α = 1`` its limit, the Kullback–Leibler divergence
  ``Σ_λ [(1−r₂) log((1−r₂)/(1−r₁)) + r₂ log(r₂/r₁) + r₂ Σ_i ω₂ log(ω₂/ω₁)]``.
* Cauchy–Schwarz (eqs. 42–43): ``⟨π_i, π_j⟩_K = Π_λ [(1−r_i)(1−r_j) + K r_i r_j Σ_k ω_i ω_j]``
  and ``D_CS = −log ⟨π₂,π₁⟩_K + ½ log ⟨π₂,π₂⟩_K + ½ log ⟨π₁,π₁⟩_K``.
* Void probability (eq. 44): ``B(S) = Π_λ [1 − r_λ P_λ(S)]`` with ``P_λ(S)`` the particle mass of
  label λ in ``S``, here the disc of ground radius ``r_min`` (strict ``<``) around a point, or a
  disc of its own radius per label (:func:`disc_mass`).

Every function broadcasts over leading axes: existence probabilities ``(..., Λ)``, weights
``(..., Λ, N)`` (normalised per label), and returns one value per leading index. The divergence is
that of ``π₂`` (the posterior) from ``π₁`` (the prediction), ``D(π₂, π₁)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def _arrays(r1: ArrayLike, w1: ArrayLike, r2: ArrayLike,
            w2: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    return (np.asarray(r1, dtype=np.float64), np.asarray(w1, dtype=np.float64),
            np.asarray(r2, dtype=np.float64), np.asarray(w2, dtype=np.float64))


def renyi_terms(r1: ArrayLike, w1: ArrayLike, r2: ArrayLike, w2: ArrayLike,
                alpha: float) -> FloatArray:
    """Per-label Rényi divergences ``(..., Λ)`` of the Bernoulli components (their sum over λ is
    eq. 41); ``α = 1`` gives the Kullback–Leibler terms."""
    checks.positive("alpha", alpha)
    p1, q1, p2, q2 = _arrays(r1, w1, r2, w2)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if alpha == 1.0:
            inner = np.sum(np.where(q2 > 0, q2 * np.log(q2 / q1), 0.0), axis=-1)
        else:
            inner = np.sum(np.where(q2 > 0, q2**alpha * q1 ** (1 - alpha), 0.0), axis=-1)
    return renyi_label_terms(p1, p2, inner, alpha)


def renyi_label_terms(r1: FloatArray, r2: FloatArray, inner: FloatArray,
                      alpha: float) -> FloatArray:
    """:func:`renyi_terms` from the particle sums ``inner`` ``(..., Λ)``:
    ``Σ_i ω₂^α ω₁^{1−α}``, or ``Σ_i ω₂ log(ω₂/ω₁)`` at ``α = 1``."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if alpha == 1.0:
            absent = np.where(r2 < 1, (1 - r2) * np.log((1 - r2) / (1 - r1)), 0.0)
            present = np.where(r2 > 0, r2 * (np.log(r2 / r1) + inner), 0.0)
            return np.asarray(absent + present, dtype=np.float64)
        absent = np.where(r2 < 1, (1 - r2) ** alpha * (1 - r1) ** (1 - alpha), 0.0)
        present = np.where(r2 > 0, r2**alpha * r1 ** (1 - alpha) * inner, 0.0)
        return np.asarray(np.log(absent + present) / (alpha - 1), dtype=np.float64)


def renyi(r1: ArrayLike, w1: ArrayLike, r2: ArrayLike, w2: ArrayLike,
          alpha: float) -> FloatArray:
    """Rényi divergence ``D_R(π₂, π₁)`` of order ``α > 0`` of two LMBs on shared particles
    (eq. 41, factorised per label); ``α = 1`` is the Kullback–Leibler divergence.

    Parameters
    ----------
    r1, w1
        Existence probabilities ``(..., Λ)`` and particle weights ``(..., Λ, N)`` of ``π₁``.
    r2, w2
        The same for ``π₂``, on the same particles.
    alpha
        The order, ``> 0``.

    Returns
    -------
    FloatArray
        ``(...)`` divergences (``inf`` where ``π₂`` puts mass where ``π₁`` has none and α ≥ 1).

    Raises
    ------
    InvalidInputError
        ``alpha`` not positive.
    """
    return np.asarray(np.sum(renyi_terms(r1, w1, r2, w2, alpha), axis=-1), dtype=np.float64)


def cs_products(ra: ArrayLike, wa: ArrayLike, rb: ArrayLike, wb: ArrayLike,
                k: float) -> FloatArray:
    """Per-label factors ``(..., Λ)`` of the K-scaled inner product ``⟨π_a, π_b⟩_K`` (eq. 43):
    ``(1−r_a)(1−r_b) + K r_a r_b Σ_k ω_a ω_b``."""
    checks.positive("cs_k", k)
    pa, qa, pb, qb = _arrays(ra, wa, rb, wb)
    return cs_factors(pa, pb, np.sum(qa * qb, axis=-1), k)


def cs_factors(ra: FloatArray, rb: FloatArray, inner: FloatArray, k: float) -> FloatArray:
    """:func:`cs_products` from the particle sums ``inner = Σ_k ω_a ω_b`` ``(..., Λ)``."""
    return np.asarray((1 - ra) * (1 - rb) + k * ra * rb * inner, dtype=np.float64)


def cauchy_schwarz_of_sums(r1: FloatArray, r2: FloatArray, cross: FloatArray, own2: FloatArray,
                           own1: FloatArray, k: float) -> FloatArray:
    """:func:`cauchy_schwarz` from the particle sums ``Σ ω₂ω₁``, ``Σ ω₂²``, ``Σ ω₁²``
    ``(..., Λ)``."""
    with np.errstate(divide="ignore"):
        terms = (-np.log(cs_factors(r2, r1, cross, k)) + 0.5 * np.log(cs_factors(r2, r2, own2, k))
                 + 0.5 * np.log(cs_factors(r1, r1, own1, k)))
    return np.asarray(np.sum(terms, axis=-1), dtype=np.float64)


def cauchy_schwarz(r1: ArrayLike, w1: ArrayLike, r2: ArrayLike, w2: ArrayLike,
                   k: float) -> FloatArray:
    """Cauchy–Schwarz divergence ``D_CS(π₂, π₁)`` of two LMBs on shared particles (eqs. 42–43,
    factorised per label); symmetric in its two densities and never negative.

    Parameters
    ----------
    r1, w1, r2, w2
        As :func:`renyi`.
    k
        ``K``, the unit of hyper-volume (> 0).

    Raises
    ------
    InvalidInputError
        ``k`` not positive.
    """
    with np.errstate(divide="ignore"):
        terms = (-np.log(cs_products(r2, w2, r1, w1, k))
                 + 0.5 * np.log(cs_products(r2, w2, r2, w2, k))
                 + 0.5 * np.log(cs_products(r1, w1, r1, w1, k)))
    return np.asarray(np.sum(terms, axis=-1), dtype=np.float64)


def disc_mass(w: ArrayLike, xy: ArrayLike, centres: ArrayLike,
              radius_m: float | ArrayLike) -> FloatArray:
    """Particle mass of each label within ground distance ``radius_m`` (strictly) of each centre.

    Parameters
    ----------
    w
        ``(Λ, N)`` particle weights.
    xy
        ``(Λ, N, 2)`` particle ground positions (m).
    centres
        ``(..., 2)`` disc centres (m).
    radius_m
        The disc radius (≥ 0; 0 gives the empty disc): one for every label, or ``(Λ,)``, one
        per label (the keep-out radius inflated by each label's spread).

    Returns
    -------
    FloatArray
        ``(..., Λ)`` masses ``P_λ``.
    """
    weights = np.asarray(w, dtype=np.float64)
    radii = label_radii(radius_m, weights.shape[0])
    pos = np.asarray(xy, dtype=np.float64)
    c = np.asarray(centres, dtype=np.float64)
    lead = c.shape[:-1]
    flat = c.reshape(-1, 2)
    dx = pos[None, :, :, 0] - flat[:, 0, None, None]
    dy = pos[None, :, :, 1] - flat[:, 1, None, None]
    inside = (dx * dx + dy * dy) < (radii * radii)[None, :, None]
    mass = np.einsum("kln,ln->kl", inside, weights)
    return np.asarray(mass.reshape(*lead, weights.shape[0]), dtype=np.float64)


def label_radii(radius_m: float | ArrayLike, n_labels: int) -> FloatArray:
    """``(Λ,)`` disc radii from one radius or one per label (each finite and ≥ 0)."""
    radii = np.asarray(radius_m, dtype=np.float64)
    if radii.ndim == 0:
        checks.non_negative("radius_m", float(radii))
        return np.full(n_labels, float(radii))
    if radii.shape != (n_labels,) or not np.all(np.isfinite(radii)) or np.any(radii < 0.0):
        raise InvalidInputError("radius_m", radii.tolist(),
                                f"must be one radius ≥ 0 or {n_labels}, one per label")
    return radii


def void_probability(r: ArrayLike, w: ArrayLike, xy: ArrayLike, centres: ArrayLike,
                     radius_m: float | ArrayLike) -> FloatArray:
    """Void probability ``B = Π_λ [1 − r_λ P_λ]`` of the discs of radius ``radius_m`` around
    ``centres`` (eq. 44, factorised): the probability that no object lies within ground distance
    ``r_min`` of each centre.

    Parameters
    ----------
    r
        ``(Λ,)`` existence probabilities.
    w, xy, centres, radius_m
        As :func:`disc_mass`.

    Returns
    -------
    FloatArray
        ``(...)`` void probabilities, one per centre.
    """
    mass = disc_mass(w, xy, centres, radius_m)
    return np.asarray(np.prod(1.0 - np.asarray(r, dtype=np.float64) * mass, axis=-1),
                      dtype=np.float64)
