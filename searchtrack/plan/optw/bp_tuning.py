"""Knobs of the team-OPTW branch-and-price (:mod:`searchtrack.plan.optw.bp`), validated."""

from __future__ import annotations

from dataclasses import dataclass

from searchtrack.core.checks import boolean, count, non_negative, real
from searchtrack.core.errors import InvalidInputError


@dataclass(frozen=True)
class Tuning:
    """Knobs of the branch-and-price (defaults: the measured best).

    A value out of its domain, or a combination that would silently do nothing, raises
    :class:`~searchtrack.core.errors.InvalidInputError` naming the field.
    """

    smoothing: float = 0.5  # Wentges α in [0, 1) (0: off)
    heuristic_cap: int = 0  # labels of a guided pricing pass (0: off; needs whole passes)
    table_ng: int | None = 4  # ng-size of the completion-table pass (whole passes only)
    bidirectional: bool = True  # exact pricing by half passes joined at the split time
    half_tables: bool = False  # bidirectional: table passes bound the half passes' completions
    collect: int = 200  # most columns per pricing call
    ils_share: float = 0.02  # of the time limit, at most ils_max_s
    ils_max_s: float = 1.5
    ils_iterations: int = 20000  # the ILS stops here unless its time share ends first
    ils_again_share: float = 0.1  # of the limit (at most ils_again_max_s): the ILS from the
    ils_again_max_s: float = 30.0  # incumbent once the root leaves a gap (0: never)
    ils_again_iterations: int = 500000
    primal_s: float = 2.0  # CP-SAT on the column pool, after the root and every primal_every
    primal_every: int = 50
    cuts_per_round: int = 20  # subset-row cuts separated at once (0: no cuts)
    cuts_max: int = 240  # subset-row cuts in the master at most
    cut_rounds: int = 16  # separation rounds per node
    cut_depth: int = 0  # separate at nodes of at most this depth
    strong: int = 1  # branching candidates tried on the pooled master (1: the best ranked)
    enum_labels: int = 4_000_000  # route enumeration's label budget at a node (0: off)
    enum_routes: int = 200_000  # most routes it may list for the set packing
    enum_mip_s: float = 30.0  # CP-SAT's time on that set packing
    fix_arcs: bool = False  # fix the arcs no route of a better plan uses, after the root

    def __post_init__(self) -> None:
        real("smoothing", self.smoothing, low=0.0, high=1.0, high_open=True)
        count("heuristic_cap", self.heuristic_cap)
        if self.table_ng is not None:
            count("table_ng", self.table_ng, least=1)
        boolean("bidirectional", self.bidirectional)
        boolean("half_tables", self.half_tables)
        boolean("fix_arcs", self.fix_arcs)
        if self.heuristic_cap > 0 and self.bidirectional:
            raise InvalidInputError("heuristic_cap", self.heuristic_cap,
                                    "needs bidirectional=False (the guided pass reads the "
                                    "forward table of whole passes)")
        count("collect", self.collect, least=1)
        real("ils_share", self.ils_share, low=0.0, high=1.0)
        real("ils_again_share", self.ils_again_share, low=0.0, high=1.0)
        for name in ("ils_max_s", "ils_again_max_s", "primal_s", "enum_mip_s"):
            non_negative(name, getattr(self, name))
        for name in ("ils_iterations", "ils_again_iterations", "cuts_per_round", "cuts_max",
                     "cut_rounds", "cut_depth", "enum_labels", "enum_routes"):
            count(name, getattr(self, name))
        count("primal_every", self.primal_every, least=1)
        count("strong", self.strong, least=1)
