"""Validated EMD instances: signatures, ground costs or a road graph, and how unequal masses mix.

Masses (thesis §4.3, (4.7)). The thesis normalises both signatures to unit mass, so that
``EMD = Σ d_ig f_ig``. The general definition of Rubner et al. [6] lets the masses differ:
(4.5)/(4.6) become ``≤`` and (4.7) fixes the total flow to ``min(Σp, Σq)``; the EMD is then
``work / total flow``. Three modes choose between these:

* ``"normalize"`` (default, the thesis): each signature is divided by its own total.
* ``"partial"``: Rubner's partial EMD in the caller's units; the heavier side keeps the excess.
* ``"equal"``: the caller's units, masses must agree to ``1e-9`` relative (else an error); the
  round-off difference is removed by rescaling ``q``.

The objective is ``work / total_flow`` in every mode, so the three agree when masses are equal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray

MassMode = Literal["normalize", "partial", "equal"]
MASS_MODES: tuple[str, ...] = get_args(MassMode)

EQUAL_MASS_RTOL = 1e-9


def signature(name: str, values: ArrayLike) -> FloatArray:
    """``values`` as a 1-D float array of finite, non-negative weights with a positive total."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(name, values, "must be a 1-D array of numbers") from None
    if arr.ndim != 1 or arr.size == 0:
        raise InvalidInputError(name, values, f"must be a non-empty 1-D array (shape {arr.shape})")
    _check_entries(name, arr, "weights")
    with np.errstate(over="ignore"):  # an overflowing total is refused below, not warned about
        total = float(arr.sum())
    if not 0.0 < total < math.inf:
        raise InvalidInputError(name, values, f"total mass must be positive and finite, got "
                                f"{total}")
    return arr


def balance(p: FloatArray, q: FloatArray, mass: str) -> tuple[FloatArray, FloatArray, float]:
    """The masses to transport under ``mass`` and the total flow (4.7) they imply."""
    if mass not in MASS_MODES:
        raise InvalidInputError("mass", mass, f"choose one of {list(MASS_MODES)}")
    total_p, total_q = float(p.sum()), float(q.sum())
    if mass == "normalize":
        return p / total_p, q / total_q, 1.0
    if mass == "partial":
        return p, q, min(total_p, total_q)
    if abs(total_p - total_q) > EQUAL_MASS_RTOL * max(total_p, total_q):
        raise InvalidInputError(
            "q", f"sum {total_q!r}",
            f"mass='equal' needs sum(q) == sum(p) = {total_p!r}; use mass='normalize' "
            "(thesis (4.7)) or 'partial' (Rubner's partial EMD)")
    return p, q * (total_p / total_q), total_p


@dataclass(frozen=True, eq=False)
class TransportProblem:
    """The transportation LP (4.3)–(4.7): masses ``p`` (m) to ``q`` (n) at ground cost ``cost``.

    Build it with :meth:`build`, which validates every field; ``p`` and ``q`` are stored as they
    are solved (normalised for ``mass="normalize"``).
    """

    cost: FloatArray
    p: FloatArray
    q: FloatArray
    mass: MassMode
    total_flow: float

    @classmethod
    def build(cls, p: ArrayLike, q: ArrayLike, cost: ArrayLike, mass: str) -> TransportProblem:
        """Validate the inputs of :func:`~searchtrack.estimate.transport.emd`."""
        p_arr, q_arr = signature("p", p), signature("q", q)
        try:
            c = np.ascontiguousarray(cost, dtype=np.float64)
        except (TypeError, ValueError):
            raise InvalidInputError("cost", cost, "must be a 2-D array of numbers") from None
        if c.shape != (p_arr.size, q_arr.size):
            raise InvalidInputError("cost", f"<array of shape {c.shape}>", f"shape must be "
                                    f"(len(p), len(q)) = {(p_arr.size, q_arr.size)}")
        _check_entries("cost", c, "ground distances")
        p_s, q_s, total = balance(p_arr, q_arr, mass)
        return cls(c, p_s, q_s, mass, total)  # type: ignore[arg-type]


@dataclass(frozen=True, eq=False)
class GraphProblem:
    """EMD under the shortest-path metric of a graph, as a min-cost flow on its arcs.

    Arc ``k`` runs ``tails[k] → heads[k]`` with length ``lengths[k]``; ``p`` and ``q`` live on
    the ``n_nodes`` nodes. Build it with :meth:`build`.
    """

    tails: IntArray
    heads: IntArray
    lengths: FloatArray
    n_nodes: int
    p: FloatArray
    q: FloatArray
    mass: MassMode
    total_flow: float

    @classmethod
    def build(cls, adjacency: object, p: ArrayLike, q: ArrayLike, mass: str) -> GraphProblem:
        """Validate the inputs of :func:`~searchtrack.estimate.transport.emd_on_graph`.

        Every stored entry ``adjacency[i, j] = ℓ`` (explicit zeros included, as in
        ``scipy.sparse.csgraph``) is an arc ``i → j`` of length ``ℓ ≥ 0``; a symmetric matrix is
        an undirected graph. Self-loops are dropped.
        """
        if not sp.issparse(adjacency):
            raise InvalidInputError("adjacency", adjacency,
                                    "must be a scipy.sparse matrix (CSR) of edge lengths")
        shape = tuple(adjacency.shape)  # type: ignore[attr-defined]
        if len(shape) != 2 or shape[0] != shape[1]:
            raise InvalidInputError("adjacency", f"<sparse matrix of shape {shape}>",
                                    "must be square (nodes × nodes)")
        p_arr, q_arr = signature("p", p), signature("q", q)
        n = int(shape[0])
        for name, arr in (("p", p_arr), ("q", q_arr)):
            if arr.size != n:
                raise InvalidInputError(name, f"<array of length {arr.size}>",
                                        f"needs one weight per graph node ({n})")
        coo = sp.coo_array(adjacency)
        lengths = np.asarray(coo.data, dtype=np.float64)
        if lengths.size:
            _check_entries("adjacency", lengths, "edge lengths")
        keep = coo.row != coo.col
        p_s, q_s, total = balance(p_arr, q_arr, mass)
        return cls(np.asarray(coo.row[keep], dtype=np.int64),
                   np.asarray(coo.col[keep], dtype=np.int64),
                   np.ascontiguousarray(lengths[keep]), n, p_s, q_s, mass,  # type: ignore[arg-type]
                   total)


def _check_entries(name: str, values: FloatArray, what: str) -> None:
    """Raise naming the first non-finite or negative entry of ``values``."""
    for bad, rule in ((~np.isfinite(values), "finite"), (values < 0, ">= 0")):
        if bad.any():
            where = tuple(int(i) for i in np.argwhere(bad)[0])
            index = ", ".join(map(str, where))
            raise InvalidInputError(name, float(values[where]),
                                    f"{what} must be {rule} ({name}[{index}])")


def is_balanced(total_p: float, total_q: float) -> bool:
    """Whether two masses are equal up to round-off."""
    return math.isclose(total_p, total_q, rel_tol=1e-12)
