"""Diffusion on the road graph: the propagators ``e^{−α(L + I/C)Δt}`` (3.8) and ``e^{−αLΔt}`` (4.2).

Two ways to apply them, with identical results to about 1e-15:

``"cached"`` (the default, measured faster: see ``benchmarks/graph_filters.py``)
    The operator for the fixed ``Δt`` is built once as a sparse matrix — a Taylor series with
    scaling and squaring in sparse arithmetic, dropping entries below ``drop_tol`` — and each
    step is one sparse product. Entries of ``e^{−τL}`` fall off faster than geometrically with hop
    distance, so for the thesis values (``αΔt ≈ 0.13`` per hop²) the operator holds a few dozen
    entries per node. If it would exceed ``max_nnz_per_node`` the build is abandoned (logged) and
    ``expm_multiply`` is used instead.
``"expm_multiply"``
    :func:`scipy.sparse.linalg.expm_multiply` on every call (Al-Mohy and Higham), no set-up.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.linalg import expm_multiply

from searchtrack.core.checks import real
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.diffusion")

Method = Literal["cached", "expm_multiply"]
Weighting = Literal["unweighted", "length"]

_SCALED_NORM = 0.5  # scale −τL to this 1-norm before the Taylor series


def _number(name: str, value: object, *, positive: bool, inf_ok: bool = False) -> float:
    """A real ``≥ 0`` (``> 0`` if ``positive``); ``inf`` only if ``inf_ok``."""
    if inf_ok and isinstance(value, (float, np.floating)) and value == math.inf:
        return math.inf
    x = real(name, value)
    if x < 0.0 or (positive and x == 0.0):
        raise InvalidInputError(name, value, "must be > 0" if positive else "must be ≥ 0")
    return x


def _max_abs(a: sp.sparray | NDArray[np.float64]) -> float:
    data = a.data if sp.issparse(a) else np.asarray(a)
    return float(np.abs(data).max(initial=0.0))


def _prune(a: sp.csr_array, tol: float) -> sp.csr_array:
    a.data[np.abs(a.data) < tol] = 0.0
    a.eliminate_zeros()
    return a


def sparse_expm(a: sp.csr_array, drop_tol: float, max_nnz: int) -> sp.csr_array | None:
    """``e^A`` as a sparse matrix, entries below ``drop_tol`` dropped; ``None`` past ``max_nnz``.

    Scaling and squaring: ``A/2^s`` has 1-norm ≤ 0.5, its Taylor series is summed until a term's
    1-norm falls below ``drop_tol``, pruning every term, then squared ``s`` times with pruning.
    Meant for ``A = −τL``, whose exponential is a stochastic matrix with entries in ``[0, 1]``
    that fall off quickly with hop distance.
    """
    n = a.shape[0]
    norm = _max_abs(abs(a).sum(axis=0))
    squarings = max(0, math.ceil(math.log2(norm / _SCALED_NORM))) if norm > 0 else 0
    a = sp.csr_array(a / 2.0**squarings)
    term = sp.eye_array(n, format="csr")
    total = sp.eye_array(n, format="csr")
    for k in range(1, 60):
        term = _prune(sp.csr_array(term @ a) / k, drop_tol)
        if term.nnz == 0:
            break
        total = sp.csr_array(total + term)
        if _max_abs(abs(term).sum(axis=0)) < drop_tol:
            break
    if total.nnz > max_nnz:
        return None
    for _ in range(squarings):
        total = _prune(sp.csr_array(total @ total), drop_tol)
        if total.nnz > max_nnz:
            return None
    return total


@dataclass(frozen=True, eq=False)
class GraphDiffusion:
    """Propagate node values by ``e^{−α(L + I/C)Δt}`` over a fixed step ``Δt``.

    With ``decay_c = inf`` this is the mass-conserving random walk of the trackers (4.1)–(4.2);
    with finite ``C`` it is the LRT prediction (3.6)–(3.8), which also relaxes every value toward
    0 (neutral log-likelihood ratio) at the rate ``α/C``.

    Parameters
    ----------
    laplacian
        ``(n, n)`` symmetric graph Laplacian (rows summing to 0), e.g.
        :attr:`RoadNetwork.laplacian <searchtrack.models.roads.RoadNetwork.laplacian>`.
    alpha
        Diffusivity ``α ≥ 0``. Its unit follows the Laplacian: 1/s (hops²/s) for the thesis's
        unweighted ``L``, m²/s for ``L`` weighted by ``1/length²`` (see :meth:`on_network`).
    dt_s
        Time step ``Δt > 0`` (s).
    decay_c
        The LRT decay constant ``C > 0`` of (3.6), or ``inf`` for no decay.
    method
        ``"cached"`` or ``"expm_multiply"`` (module docstring).
    drop_tol
        Entries of the cached operator below this are dropped.
    max_nnz_per_node
        Give up caching (fall back to ``expm_multiply``) beyond this many entries per node.
    """

    laplacian: sp.csr_array
    alpha: float
    dt_s: float
    decay_c: float = math.inf
    method: Method = "cached"
    drop_tol: float = 1e-16
    max_nnz_per_node: int = 2000

    def __post_init__(self) -> None:
        lap = self.laplacian
        if not sp.issparse(lap) or lap.ndim != 2 or lap.shape[0] != lap.shape[1]:
            raise InvalidInputError("laplacian", lap, "must be a square scipy.sparse matrix")
        lap = sp.csr_array(lap, dtype=np.float64)
        if not np.all(np.isfinite(lap.data)) or _max_abs(lap - lap.T) > 1e-12:
            raise InvalidInputError("laplacian", lap, "must be finite and symmetric")
        if _max_abs(lap.sum(axis=1)) > 1e-9:
            raise InvalidInputError("laplacian", lap, "rows must sum to 0")
        set_ = object.__setattr__
        set_(self, "laplacian", lap)
        set_(self, "alpha", _number("alpha", self.alpha, positive=False))
        set_(self, "dt_s", _number("dt_s", self.dt_s, positive=True))
        set_(self, "decay_c", _number("decay_c", self.decay_c, positive=True, inf_ok=True))
        if self.method not in ("cached", "expm_multiply"):
            raise InvalidInputError("method", self.method, "must be 'cached' or 'expm_multiply'")
        set_(self, "drop_tol", _number("drop_tol", self.drop_tol, positive=False))
        if isinstance(self.max_nnz_per_node, bool) or not isinstance(
            self.max_nnz_per_node, (int, np.integer)
        ) or self.max_nnz_per_node < 1:
            raise InvalidInputError("max_nnz_per_node", self.max_nnz_per_node, "must be an int ≥ 1")

    @classmethod
    def on_network(
        cls,
        network: RoadNetwork,
        alpha: float,
        dt_s: float,
        *,
        decay_c: float = math.inf,
        weighting: Weighting = "unweighted",
        method: Method = "cached",
    ) -> GraphDiffusion:
        """Diffusion on ``network``'s Laplacian.

        ``weighting="unweighted"`` is the thesis's ``L = D − A`` (2.4): every edge counts as one
        hop, so ``α`` is in hops²/s. ``weighting="length"`` uses ``B diag(1/length²) Bᵀ``, the
        finite-difference ``−∇²`` of (2.6) for uneven spacing, so ``α`` is in m²/s.
        """
        if weighting == "unweighted":
            lap = network.laplacian
        elif weighting == "length":
            lap = network.weighted_laplacian(1.0 / network.lengths_m**2)
        else:
            raise InvalidInputError("weighting", weighting, "must be 'unweighted' or 'length'")
        return cls(lap, alpha, dt_s, decay_c=decay_c, method=method)

    @property
    def n_nodes(self) -> int:
        """Number of nodes ``n``."""
        return int(self.laplacian.shape[0])

    @property
    def decay_factor(self) -> float:
        """``e^{−αΔt/C}``: how much a uniform field shrinks per step (1 without decay)."""
        return math.exp(-self.alpha * self.dt_s / self.decay_c)

    @cached_property
    def operator(self) -> sp.csr_array | None:
        """The cached sparse ``e^{−αLΔt}`` (without the decay factor), or ``None`` if too large
        or ``method="expm_multiply"``."""
        if self.method != "cached":
            return None
        n = self.n_nodes
        total = sparse_expm(sp.csr_array(self.laplacian * (-self.alpha * self.dt_s)),
                            self.drop_tol, self.max_nnz_per_node * n)
        if total is None:
            log.warning("cached propagator exceeds %d entries per node; using expm_multiply",
                        self.max_nnz_per_node)
            return None
        total.sum_duplicates()  # canonical: sorted indices, faster products
        if total.nnz < np.iinfo(np.int32).max:  # smaller index arrays: less memory traffic
            total = sp.csr_array((total.data, total.indices.astype(np.int32),
                                  total.indptr.astype(np.int32)), shape=total.shape)
        log.debug("cached propagator: n=%d, %.1f entries per node", n, total.nnz / n)
        return total

    def propagate(self, values: ArrayLike) -> NDArray[np.float64]:
        """Values after one step: ``e^{−α(L + I/C)Δt} values`` for ``(n,)`` or ``(n, k)`` input.

        Returns a new array; the input is not modified.
        """
        x = np.asarray(values, dtype=np.float64)
        if x.ndim not in (1, 2) or x.shape[0] != self.n_nodes:
            raise InvalidInputError("values", values, f"must have shape ({self.n_nodes},) or "
                                    f"({self.n_nodes}, k)")
        op = self.operator
        if op is not None:
            out = np.asarray(op @ x, dtype=np.float64)
            if self.decay_factor != 1.0:
                out *= self.decay_factor
            return out
        return self.propagate_expm_multiply(x)

    def propagate_expm_multiply(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        """One step by :func:`scipy.sparse.linalg.expm_multiply` on ``−α(L + I/C)Δt`` (3.8)."""
        rate = self._rate
        return np.asarray(expm_multiply(rate, values, traceA=self._trace), dtype=np.float64)

    @cached_property
    def _rate(self) -> sp.csr_array:
        shift = 0.0 if math.isinf(self.decay_c) else 1.0 / self.decay_c
        ident = sp.eye_array(self.n_nodes, format="csr")
        return sp.csr_array((self.laplacian + ident * shift) * (-self.alpha * self.dt_s))

    @cached_property
    def _trace(self) -> float:
        return float(self._rate.diagonal().sum())
