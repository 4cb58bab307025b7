"""Search parameters of the OPTW iterated local search (:mod:`searchtrack.plan.optw.ils`),
validated."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.checks import boolean, count, non_negative, real
from searchtrack.core.errors import InvalidInputError

_RUINS = ("w_segment", "w_random", "w_related", "w_target", "w_fit", "w_route")
_SWITCHES = ("local_search", "relocate", "split", "replace")


@dataclass(frozen=True)
class Tuning:
    """Search parameters (defaults tuned on the Solomon and Cordeau OPTW benchmarks, m = 1, and on
    the Cordeau TOPTW benchmark, m = 1 to 4, for ``split`` and ``k_max``, m = 4 for ``replace``,
    m = 2 to 4 for the route pool; ``w_route``, ``relocate`` and ``elite`` are off by default).

    A value out of its domain, or ruin weights that are all zero, raises
    :class:`~searchtrack.core.errors.InvalidInputError` naming the field.

    Parameters
    ----------
    k_frac
        Ruin size is uniform in ``[1, max(k_frac · visits, min(visits, 4))]``.
    temperature
        Start temperature of each annealing cycle, as a multiple of the mean customer profit.
    t_end
        Temperature at the end of a cycle, as a fraction of the start temperature.
    cycle0, grow
        Length in iterations of the first cycle and growth factor of the next ones; each cycle
        restarts from the best solution.
    p_equal
        Probability of accepting an equal-profit solution that takes longer.
    alpha_lo, alpha_hi
        Range of the profit exponent ``a`` of the insertion score ``P^a / Shift``.
    noise
        Each insertion score is multiplied by ``1 + noise · U[0, 1)``.
    w_segment, w_random, w_related, w_target, w_fit
        Relative weights of the ruin operators: consecutive visits, random visits, visits related
        to a random visit, visits related to an unvisited customer (then inserted), and the
        same removing only until that customer fits.
    local_search
        Reorder routes (2-opt, or-opt) and re-insert after each recreate.
    w_route
        Relative weight of the route ruin: every visit of one random route.
    k_max
        Upper bound on the ruin size (at least 4): on large team instances many small ruins find
        more than fewer large ones in the same time.
    relocate
        Also move visits between routes when that shortens the total travel, in the local search.
    split
        The segment ruin removes ``ceil(k / vehicles)`` visits from each route (else ``k`` from
        each, which with several vehicles wipes out most of the plan).
    replace
        In the local search, also swap visits for unvisited customers of more profit in their
        place (:func:`searchtrack.plan.optw.ils_moves.replace`).
    elite
        With more than 1, keep this many distinct solutions (the best and the ends of cycles,
        ranked by profit then time) and restart each cycle from a random one of them instead of
        the best.
    pool
        With more than one vehicle, recombine routes (Hu & Lim 2014;
        :mod:`searchtrack.plan.optw.ils_pool`): pool the routes of local optima within this
        fraction of the best profit (0: off) and pack the best disjoint ones into a plan.
    pool_size, pack_every, pack_nodes
        At most ``pool_size`` pooled routes; a packing each time ``pack_every`` are new, and at
        the end, of at most ``pack_nodes`` branch-and-bound nodes.
    pack_s
        Seconds kept for the last packing (at most 5 % of the time limit).
    """

    k_frac: float = 0.5
    temperature: float = 2.5
    t_end: float = 0.01
    cycle0: int = 1000
    grow: float = 1.5
    p_equal: float = 0.5
    alpha_lo: float = 1.0
    alpha_hi: float = 3.0
    noise: float = 1.0
    w_segment: float = 0.5
    w_random: float = 0.5
    w_related: float = 0.0
    w_target: float = 1.0
    w_fit: float = 1.0
    local_search: bool = True
    w_route: float = 0.0
    k_max: int = 15
    relocate: bool = False
    split: bool = True
    elite: int = 0
    replace: bool = True
    pool: float = 0.03
    pool_size: int = 2000
    pack_every: int = 100
    pack_nodes: int = 100_000
    pack_s: float = 0.02

    def __post_init__(self) -> None:
        real("k_frac", self.k_frac, low=0.0, high=1.0)
        non_negative("temperature", self.temperature)
        real("t_end", self.t_end, low=0.0, high=1.0)
        count("cycle0", self.cycle0, least=1)
        real("grow", self.grow, low=1.0)
        real("p_equal", self.p_equal, low=0.0, high=1.0)
        non_negative("alpha_lo", self.alpha_lo)
        real("alpha_hi", self.alpha_hi, low=real("alpha_lo", self.alpha_lo))
        non_negative("noise", self.noise)
        for name in _RUINS:
            non_negative(name, getattr(self, name))
        if sum(getattr(self, name) for name in _RUINS) <= 0.0:
            raise InvalidInputError("w_segment", self.w_segment,
                                    "and the other ruin weights are all zero: nothing to ruin")
        for name in _SWITCHES:
            boolean(name, getattr(self, name))
        count("k_max", self.k_max, least=4)
        count("elite", self.elite)
        real("pool", self.pool, low=0.0, high=1.0, high_open=True)
        for name in ("pool_size", "pack_every", "pack_nodes"):
            count(name, getattr(self, name), least=1)
        non_negative("pack_s", self.pack_s)

    def array(self, vehicles: int) -> NDArray[np.float64]:
        """Parameters in the order of the ``ils_search.P_*`` indices, for ``vehicles`` routes
        (one route: no route pool, nothing to recombine)."""
        return np.array([self.k_frac, self.temperature, self.t_end, self.cycle0, self.grow,
                         self.p_equal, self.alpha_lo, self.alpha_hi, self.noise,
                         self.w_segment, self.w_random, self.w_related, self.w_target,
                         self.w_fit, float(self.local_search), self.w_route, float(self.k_max),
                         float(self.relocate), float(self.split), float(self.elite),
                         float(self.replace), self.pool if vehicles > 1 else 0.0],
                        dtype=np.float64)
