"""The EMD of one tracker–measurement pair of Algorithm 1, straight on the network simplex.

An EMD matrix (thesis §4.3) solves thousands of small transportation LPs (4.3)–(4.7) whose
inputs are already valid: the truncated signatures hold positive weights and the distance block
is finite and non-negative. :func:`pair_emd` solves one of them as :func:`~.solve.emd` does with
``mass="normalize"`` (each signature scaled to unit mass, the network simplex of
:mod:`.simplex` on the cost matrix in place), without re-validating the inputs or building a
:class:`~searchtrack.core.result.Result`, and from the least-cost starting basis of
:mod:`.simplex_start` rather than from artificial arcs. The plan's marginals are still checked
(as the registry checks every plan), and anything other than an optimal, checked plan or a
proven infeasibility is handed to :func:`~.solve.emd` with its fallback chain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.transport.network import map_status
from searchtrack.estimate.transport.plan import TransportPlan
from searchtrack.estimate.transport.simplex import min_cost_flow
from searchtrack.estimate.transport.solve import CHECK_RTOL, emd


@dataclass(frozen=True, eq=False)
class PairEMD:
    """Outcome of :func:`pair_emd`.

    ``status`` is ``OPTIMAL`` (``value`` the EMD, ``rows``/``cols`` the cells the plan uses),
    ``INFEASIBLE`` (mass cannot cross between components) or what :func:`~.solve.emd` returned;
    ``result`` is that fallback's result, ``None`` on the direct path.
    """

    status: Status
    value: float | None
    rows: IntArray
    cols: IntArray
    result: Result[TransportPlan] | None = None


_NONE = np.zeros(0, dtype=np.int64)


def pair_emd(p: FloatArray, q: FloatArray, cost: FloatArray, deadline: Deadline) -> PairEMD:
    """EMD (m) of positive weights ``p`` (m) and ``q`` (n) under the finite ``(m, n)`` ``cost``."""
    pn, qn = p / float(p.sum()), q / float(q.sum())
    flat = np.ascontiguousarray(cost, dtype=np.float64).ravel()
    ncols = qn.size
    solution = min_cost_flow(np.concatenate([pn, -qn]), flat, deadline, ncols=ncols,
                             mass_scale=1.0, least_cost_start=True)
    status = map_status(solution)
    if status is Status.INFEASIBLE:
        return PairEMD(status, None, _NONE, _NONE)
    if status is Status.OPTIMAL:
        rows, cols = solution.arcs // ncols, solution.arcs % ncols
        amounts = solution.amounts
        out = np.bincount(rows, weights=amounts, minlength=pn.size)
        into = np.bincount(cols, weights=amounts, minlength=ncols)
        if (amounts >= 0.0).all() and max(float(np.abs(out - pn).max()),
                                          float(np.abs(into - qn).max())) <= CHECK_RTOL:
            return PairEMD(status, float(flat[solution.arcs] @ amounts), rows, cols)
    result = emd(p, q, cost, time_limit_s=max(deadline.remaining(), 1e-3))
    plan = result.plan
    rows, cols = (plan.rows, plan.cols) if plan is not None else (_NONE, _NONE)
    return PairEMD(result.status, result.objective, rows, cols, result)
