"""Entropy-based target weights and weighted edge values (Moore et al. 2021, §4.1).

The sigmoid weight of target ``m`` (Eq. 20) is ``γ_m = 1 / (1 + exp(−a (η H_m − 0.5)))``: a
target whose entropy ``H_m`` is high relative to the others gets a weight near 1, a well-localised
one a weight near 0, so a planner does not keep circling the tight target (the failure of the
naive value, Eq. 17, shown in the paper's Fig. 2). The paper leaves the normaliser ``η`` open;
``"sum"`` is ``η = 1 / Σ_m H_m`` (the authors' code), ``"max"`` is ``η = 1 / max_m H_m``, which
keeps the most uncertain target at weight ``1 / (1 + e^{−a/2})`` for any ``M`` (with ``"sum"``
and ``M > 2`` every weight falls below 0.5). When every entropy is 0 the normalised entropies are
taken equal, ``1/M`` (``"sum"``) or 1 (``"max"``), their limit for equal entropies.

The weighted value of directed edge ``e`` (Eq. 21) is ``Σ_m γ_m Σ_n w_{mn} δ(e_{mn}, e)``,
divided by the edge length when ``per_length`` (as printed) or not (as in the authors' code),
counting the particles of both directions of the road when ``both_directions`` (the camera sees
both lanes). Particle weights ``w`` replace the paper's counts: with equal weights ``1/N`` they
are the fractions ``count / N`` of the code. ``weighting="uniform"`` gives ``γ_m = 1``: Eq. 17.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray

Normalization = Literal["sum", "max"]
Weighting = Literal["entropy", "uniform"]
NORMALIZATIONS: tuple[Normalization, ...] = ("sum", "max")
WEIGHTINGS: tuple[Weighting, ...] = ("entropy", "uniform")


def target_weights(entropy: FloatArray, *, gain: float = 10.0,
                   normalization: Normalization = "sum",
                   weighting: Weighting = "entropy") -> FloatArray:
    """``(M,)`` target weights ``γ_m`` (Eq. 20), or ones for ``weighting="uniform"`` (Eq. 17).

    Parameters
    ----------
    entropy
        ``(M,)`` non-negative entropies ``H_m`` (nats, Eq. 19).
    gain
        The sigmoid gain ``a`` (10 in the paper's simulation), ≥ 0.
    normalization
        ``"sum"`` (``η = 1/Σ H``) or ``"max"`` (``η = 1/max H``).
    weighting
        ``"entropy"`` (Eq. 20) or ``"uniform"`` (every ``γ_m = 1``, the naive value).

    Raises
    ------
    InvalidInputError
        Negative or non-finite entropies, a bad gain or an unknown option.
    """
    h = checks.finite_array("entropy", entropy, (None,))
    if h.size == 0:
        raise InvalidInputError("entropy", entropy, "needs one entropy per target (M ≥ 1)")
    if np.any(h < 0.0):
        raise InvalidInputError("entropy", entropy, "entropies must be >= 0")
    a = checks.non_negative("gain", gain)
    checks.choice("normalization", normalization, NORMALIZATIONS)
    checks.choice("weighting", weighting, WEIGHTINGS)
    if weighting == "uniform":
        return np.ones(h.size)
    scale = float(h.sum() if normalization == "sum" else h.max())
    if scale > 0.0:
        normalised = h / scale
    else:
        normalised = np.full(h.size, 1.0 / h.size if normalization == "sum" else 1.0)
    out: FloatArray = 1.0 / (1.0 + np.exp(-a * (normalised - 0.5)))
    return out


def edge_values(length_m: FloatArray, edge: IntArray, weight: FloatArray, gamma: FloatArray, *,
                per_length: bool = False, both_directions: bool = True) -> FloatArray:
    """``(E,)`` weighted value of every directed edge (Eq. 21).

    Parameters
    ----------
    length_m
        ``(E,)`` directed edge lengths (m); edges ``2k`` and ``2k + 1`` are one road's two
        directions (:class:`~searchtrack.models.road_particles.DirectedRoads`).
    edge, weight
        ``(M, N)`` particle edges and weights (zero for particles already counted).
    gamma
        ``(M,)`` target weights (:func:`target_weights`).
    per_length
        Divide by the edge length (Eq. 21 as printed).
    both_directions
        Count the particles of the reverse edge too.
    """
    n_edges = int(length_m.size)
    mass: FloatArray = np.bincount(edge.reshape(-1), minlength=n_edges,
                                   weights=(weight * gamma[:, None]).reshape(-1)).astype(float)
    if both_directions:
        mass = mass + mass[np.arange(n_edges) ^ 1]
    return mass / length_m if per_length else mass
