"""The radio planning backends: exhaustive, beam, greedy and the straight-path baseline
(Nguyen et al., §III-D eq. 45 and §IV-B Experiment 2).

Each builds the solve's :class:`~searchtrack.plan.radio.tree.Scorer` from ``seed`` (the
look-ahead draws, so one seed scores every backend's sequences identically) and searches:

* ``exhaustive``: all ``N_θ^H`` sequences (depth first, shared prefixes); ``OPTIMAL``.
* ``beam``: the ``width`` best prefixes per level; ``FEASIBLE`` without a bound (none is known
  for the divergence reward), ``OPTIMAL`` when nothing was dropped.
* ``greedy``: a beam of width 1, one level at a time.
* ``straight``: the Experiment 2 baseline, :func:`~searchtrack.models.radio.uav.
  straight_sweep_heading` for every interval; its reward and constraint are still scored.

:func:`~searchtrack.plan.radio.search.answer` gives the shared answer conventions.
"""

from __future__ import annotations

import numpy as np

from searchtrack.core import checks
from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.models.radio import fly_heading, straight_sweep_heading
from searchtrack.plan.radio.problem import RadioPlan, RadioPlanProblem
from searchtrack.plan.radio.search import (
    Best,
    answer,
    beam_search,
    exhaustive_search,
    key_of,
)
from searchtrack.plan.radio.tree import Scorer

#: Prefixes kept per level by ``beam`` by default.
DEFAULT_WIDTH = 8


def solve_exhaustive(problem: RadioPlanProblem, *, time_limit_s: float = 10.0, seed: int = 0,
                     initial: RadioPlan | None = None,
                     scorer: Scorer | None = None) -> Result[RadioPlan]:
    """Every action sequence, depth first; ``OPTIMAL`` (or the least-violating plan, proven)
    when the search completes, else the best so far (``FEASIBLE``) or ``NO_SOLUTION``.

    ``initial`` (a plan of the same problem and seed, e.g. beam's) starts the search as the
    incumbent, so the answer is never worse and more subtrees can be dropped; ``scorer`` (built
    from the same problem and seed, e.g. for beam) saves drawing the look-ahead again.
    """
    deadline = Deadline(time_limit_s)
    scorer = Scorer(problem, seed) if scorer is None else scorer
    incumbent = None
    if initial is not None:
        incumbent = Best(key_of(initial, problem.settings.discount,
                                problem.settings.p_void_min), initial,
                         initial.objective(problem.settings.discount))
    found = exhaustive_search(scorer, deadline, incumbent)
    note = "every sequence" if found.complete else "stopped at the time limit"
    return answer(scorer, found, "exhaustive", deadline, exact=True,
                  note=f"{note} ({found.nodes} nodes)")


def solve_beam(problem: RadioPlanProblem, *, time_limit_s: float = 10.0, seed: int = 0,
               width: int = DEFAULT_WIDTH, scorer: Scorer | None = None) -> Result[RadioPlan]:
    """Beam search keeping ``width`` prefixes per level (``scorer``: as for
    :func:`solve_exhaustive`).

    Raises
    ------
    InvalidInputError
        ``width`` not a positive integer.
    """
    checks.count("width", width, 1)
    deadline = Deadline(time_limit_s)
    scorer = Scorer(problem, seed) if scorer is None else scorer
    found = beam_search(scorer, deadline, width)
    return answer(scorer, found, "beam", deadline, exact=True,
                  note=f"width {width} ({found.nodes} nodes"
                  + (", nothing dropped)" if not found.pruned else ")"))


def solve_greedy(problem: RadioPlanProblem, *, time_limit_s: float = 10.0,
                 seed: int = 0) -> Result[RadioPlan]:
    """The best primitive one interval at a time (a beam of width 1)."""
    deadline = Deadline(time_limit_s)
    scorer = Scorer(problem, seed)
    found = beam_search(scorer, deadline, 1)
    return answer(scorer, found, "greedy", deadline, exact=True,
                  note=f"best primitive per interval ({found.nodes} nodes)")


def solve_straight(problem: RadioPlanProblem, *, time_limit_s: float = 10.0,
                   seed: int = 0) -> Result[RadioPlan]:
    """The straight-path baseline of Experiment 2, scored like every other plan (``FEASIBLE``;
    the least-violating convention when it breaks the void constraint)."""
    deadline = Deadline(time_limit_s)
    scorer = Scorer(problem, seed)
    sc = problem.scenario

    def sweep(pose: FloatArray) -> tuple[FloatArray, FloatArray]:
        heading = straight_sweep_heading(sc.uav, pose, sc.area_m)
        path = fly_heading(sc.uav, pose, heading, sc.uav.plan_interval_s)
        return np.array([heading]), path[None]

    found = beam_search(scorer, Deadline(float("inf")), 1, actions=sweep)
    found.pruned = True  # one fixed sequence: nothing is proven
    return answer(scorer, found, "straight", deadline, exact=False,
                  note="straight sweep between (0, 0) and (W, H)")
