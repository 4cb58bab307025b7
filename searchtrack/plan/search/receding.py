"""The receding-horizon search planner of paper 004 (§4.1, eqs. 7–8), by exhaustive enumeration.

Every sequence of ``τ`` lattice moves from the current position (eq. 7) that stays in the search
box is scored ``α E(q) + T(q)`` (eq. 8): ``E`` the exploration bonus along the sequence (eq. 10),
``T`` the problem's refinement term. The best sequence is the plan; only its first waypoint is
flown before replanning. The enumeration is exhaustive (``6^τ`` sequences for 3-D moves, ``4^τ``
for the planar moves of ``dims=2``, which keep the altitude), so a completed run is ``OPTIMAL``
over the lattice; ties go to the first sequence in lexicographic move order
(``+x, +y, +z, −x, −y, −z``). Sequences are scored in blocks; a time limit that stops the
scoring returns the best sequence of the blocks scored (``FEASIBLE``).
"""

from __future__ import annotations

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.plan.search.lattice import lattice_moves, lattice_sequences
from searchtrack.plan.search.problem import SearchPlan, SearchProblem

#: Sequences scored between two looks at the deadline (one block for ``τ ≤ 3``).
BLOCK = 256


def solve_receding(problem: SearchProblem, *, time_limit_s: float = 10.0,
                   seed: int = 0) -> Result[SearchPlan]:
    """Maximise ``α E(q) + T(q)`` over every in-box move sequence from the problem's position.

    OPTIMAL with the best score when every sequence was scored; FEASIBLE (no bound) when the
    time limit stopped the scoring; INFEASIBLE when no sequence stays in the box. ``seed`` is
    unused (deterministic).
    """
    del seed
    deadline = Deadline(time_limit_s)
    settings = problem.settings
    moves = lattice_moves(settings.step_m, settings.dims)  # (2·dims, 3): planar moves keep z
    seqs = lattice_sequences(problem.position, moves, settings.horizon, problem.bounds)
    total = int(seqs.shape[0])
    if total == 0:
        return Result(Status.INFEASIBLE, None, None, deadline.elapsed(), "receding", None,
                      message="receding: no move sequence stays inside the bounds")
    best: SearchPlan | None = None
    scored = 0
    for lo in range(0, total, BLOCK):
        if lo > 0 and deadline.expired():
            break
        block = seqs[lo:lo + BLOCK]
        ex, ref, score = problem.scores(block)
        i = int(np.argmax(score))
        if best is None or score[i] > best.score:
            best = SearchPlan(block[i], float(ex[i]), float(ref[i]), float(score[i]), total)
        scored += block.shape[0]
    assert best is not None
    done = scored == total
    return Result(Status.OPTIMAL if done else Status.FEASIBLE, best.score,
                  best.score if done else None, deadline.elapsed(), "receding", best,
                  message=f"receding: {scored}/{total} sequences scored",
                  stats={"sequences": float(total), "scored": float(scored)})
