"""Signatures for the EMD of road beliefs (thesis §4.3): truncation and lower bounds.

A diffused tracker or a Gaussian measurement density is nonzero on almost every node, so each is
*truncated*: keep the smallest set of nodes holding at least ``support_mass`` (default 0.999) of
its mass — the heaviest nodes, ties to the lower index — and renormalise it to 1. By the
triangle inequality for W1, the EMD between truncated signatures differs from the full one by at
most ``(1 − support_mass)`` times the farthest road distance from a dropped node to the kept
ones, per side; in practice far less (``benchmarks/association.py`` prints the relative error).

Two lower bounds, both exact for the truncated signatures
``p`` (nodes ``i``) and ``q`` (nodes ``j``) and any optimal flow ``f`` (``Σ f = 1``):

* centroid bound, before any distance is computed: with ``κ`` =
  :attr:`RoadMetric.lower_bound_factor` (road distance ≥ ``κ`` × straight line),
  ``EMD = Σ f_ij d_ij ≥ κ Σ f_ij ‖ψ_i − ψ_j‖ ≥ κ ‖Σ f_ij (ψ_i − ψ_j)‖ = κ ‖ψ̄_p − ψ̄_q‖``
  (triangle inequality for the norm; the marginals of ``f`` are ``p`` and ``q``);
* nearest-support bound, from the distance block: ``Σ_ij f_ij d_ij ≥ Σ_i (Σ_j f_ij) min_j d_ij
  = Σ_i p_i min_j d_ij``, and symmetrically ``Σ_j q_j min_i d_ij``; both are at least the
  distance between the two supports' nearest nodes.

A relative slack of 1e-9 protects against round-off in the bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.kernel_threads import threads_for
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import signature_kernels as kernels
from searchtrack.models.road_metric import RoadMetric

#: Relative round-off allowance before a lower bound may skip a pair.
SLACK = 1e-9


@dataclass(frozen=True, eq=False)
class Signature:
    """A truncated signature: ascending ``nodes`` and their ``weights`` (> 0, summing to 1)."""

    nodes: IntArray
    weights: FloatArray

    @property
    def size(self) -> int:
        """Number of support nodes."""
        return int(self.nodes.size)


def check_support_mass(support_mass: object) -> float:
    """``support_mass`` as a float in ``(0, 1]``, else :class:`InvalidInputError`."""
    if isinstance(support_mass, bool) or not isinstance(
            support_mass, (int, float, np.integer, np.floating)):
        raise InvalidInputError("support_mass", support_mass, "must be a number in (0, 1]")
    value = float(support_mass)
    if not 0.0 < value <= 1.0:
        raise InvalidInputError("support_mass", support_mass, "must be in (0, 1]")
    return value


def check_gate(gate_m: object, *, inf_ok: bool) -> float:
    """``gate_m`` as a positive float (finite unless ``inf_ok``)."""
    if isinstance(gate_m, bool) or not isinstance(gate_m, (int, float, np.integer, np.floating)):
        raise InvalidInputError("gate_m", gate_m, "must be a positive number of metres")
    value = float(gate_m)
    if math.isnan(value) or value <= 0.0 or (value == math.inf and not inf_ok):
        raise InvalidInputError("gate_m", gate_m, "must be positive" +
                                ("" if inf_ok else " and finite") + " (m)")
    return value


def distributions(name: str, values: ArrayLike, n_nodes: int) -> FloatArray:
    """``values`` as an ``(r, n_nodes)`` array of finite, non-negative rows with positive sums."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(name, values, "must be a 2-D array of numbers") from None
    if arr.ndim != 2 or arr.shape[1] != n_nodes:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"must have shape (rows, {n_nodes}), one column per node")
    if arr.size and arr.flags.c_contiguous != arr.flags.f_contiguous:
        with threads_for(arr.size):
            bad, empty_row = kernels.faults(arr, arr.flags.f_contiguous)
        if not bad:  # else the checks below name the fault
            if empty_row >= 0:
                raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                        f"row {empty_row} has no mass")
            return arr
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be finite")
    if np.any(arr < 0.0):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be non-negative")
    empty = np.flatnonzero(arr.sum(axis=1) <= 0.0)
    if empty.size:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"row {int(empty[0])} has no mass")
    return arr


def truncate_signature(weights: ArrayLike, support_mass: float = 0.999) -> Signature:
    """The smallest node set holding ≥ ``support_mass`` of ``weights``' mass, renormalised.

    Nodes are taken heaviest first (ties: lower index first); ``support_mass = 1`` keeps every
    node of positive weight. Only nodes heavier than ``(1 − support_mass) · total / n`` are
    sorted: the lighter ones hold at most ``(1 − support_mass) · total`` together, so they are
    exactly the lightest nodes and never needed.

    Raises
    ------
    InvalidInputError
        ``weights`` not a non-empty 1-D array of finite non-negative numbers with a positive
        sum, or ``support_mass`` outside ``(0, 1]``.
    """
    mass = check_support_mass(support_mass)
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 1 or w.size == 0:
        raise InvalidInputError("weights", weights, "must be a non-empty 1-D array")
    return truncate(distributions("weights", w[None, :], w.size)[0], mass)


def truncate(w: FloatArray, mass: float) -> Signature:
    """:func:`truncate_signature` for a validated row ``w`` and ``mass``."""
    if mass < 1.0:
        return truncate_rows(w[None, :], mass)[0]
    return _signature(w, np.flatnonzero(w > 0.0).astype(np.int64))


def truncate_rows(arr: FloatArray, mass: float) -> list[Signature]:
    """:func:`truncate` of every row of a validated ``(r, n)`` array, in one sweep of it.

    Row totals are NumPy's pairwise sums of the rows, as ``row.sum()`` gives them (for a
    Fortran-ordered array, a transposed bank, by :func:`_row_sums` in memory order).
    """
    if mass >= 1.0 or arr.shape[0] == 0 or arr.shape[1] == 0:
        return [truncate(row, mass) for row in arr]
    by_column = bool(arr.flags.f_contiguous and not arr.flags.c_contiguous)
    with threads_for(arr.size):
        if by_column:
            total = kernels.row_sums_by_column(arr, *kernels.pairwise_program(arr.shape[1]))
        elif arr.flags.c_contiguous:
            total = kernels.row_sums(arr, *kernels.pairwise_program(arr.shape[1]))
        else:
            total = np.array([row.sum() for row in arr])
        nodes, offsets = kernels.heaviest(arr, total, mass, by_column)
    return [_signature(arr[r], nodes[offsets[r]:offsets[r + 1]]) for r in range(arr.shape[0])]


def _signature(w: FloatArray, nodes: IntArray) -> Signature:
    kept = w[nodes] / w[nodes].sum()
    nodes = nodes.copy()
    nodes.setflags(write=False)
    kept.setflags(write=False)
    return Signature(nodes, kept)


def warm_up() -> None:
    """Compile (or load from numba's cache) the truncation kernels, for C- and Fortran-ordered
    rows and a row past the candidate buffer."""
    w = np.array([[0.5, 0.25, 0.25], [0.0, 1.0, 0.0]])
    for arr in (w, np.asfortranarray(w)):
        distributions("warm-up", arr, 3)
        truncate_rows(arr, 0.9)
    kernels.candidates(w, np.zeros(2), False, 0, np.array([0, 3, 4]))
    kernels.candidates(np.asfortranarray(w), np.zeros(2), True, 0, np.array([0, 3, 4]))


def centroid_bound(metric: RoadMetric, left: list[Signature],
                   right: list[Signature]) -> FloatArray:
    """``(len(left), len(right))`` lower bounds ``κ ‖ψ̄_p − ψ̄_q‖`` on the EMD (m)."""
    xy = metric.network.coords

    def centroids(sigs: list[Signature]) -> FloatArray:
        return np.array([s.weights @ xy[s.nodes] for s in sigs]).reshape(len(sigs), 2)

    a, b = centroids(left), centroids(right)
    gap = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return np.asarray(metric.lower_bound_factor * gap, dtype=np.float64)


def nearest_support_bound(cost: FloatArray, p: FloatArray, q: FloatArray) -> float:
    """``max(Σ_i p_i min_j d_ij, Σ_j q_j min_i d_ij)`` ≤ EMD (``inf`` if some mass is cut off)."""
    return float(max(p @ cost.min(axis=1), q @ cost.min(axis=0)))
