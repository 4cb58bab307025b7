"""Branching of the team-OPTW branch-and-price (Boussier, Feillet & Gendreau 2007).

A node whose master solution is fractional gets two children:

* on a customer's fractional visit ``y_i = Σ_r a_ir λ_r`` (forbidden / required), choosing the
  largest ``min(y, 1 − y) × profit``: on Solomon c103, c104, r105, c101 and Cordeau pr02 it
  needed no more nodes than the most fractional visit;
* when every visit is integral, on a fractional arc flow ``x_ij`` (forbidden / forced), the one
  nearest ½.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from searchtrack.plan.optw.bp_master import LPSolution, Master, Restrictions

_FRAC = 1e-6


def branch(master: Master, profit: NDArray[np.float64], restr: Restrictions,
           lp: LPSolution) -> list[Restrictions] | None:
    """The two children of a node with restrictions ``restr`` and master solution ``lp``, or
    ``None`` when that solution is integral (``profit``: by core vertex)."""
    if np.all(np.abs(lp.values - np.round(lp.values)) <= _FRAC):
        return None
    y = master.visits(lp.values)
    score = np.minimum(y, 1.0 - y) * profit
    score[(y <= _FRAC) | (y >= 1 - _FRAC)] = -1.0
    i = int(np.argmax(score))
    if score[i] > 0:
        return [restr.child(forbid=i), restr.child(require=i)]
    x = {a: f for a, f in master.arc_flows(lp.values).items() if _FRAC < f < 1 - _FRAC}
    if not x:
        return None
    a = min(x, key=lambda k: (abs(x[k] - 0.5), k))
    return [restr.child(no_arc=a), restr.child(arc=a)]
