"""The order in which a campaign's runs are submitted: longest first, learned as it goes.

Runs of one grid cell (the same parameters, different seeds) take about the same time, and cells
can differ by an order of magnitude (a big map against a small one). Submitted in grid order, the
slowest cell's last runs may end the campaign alone on one worker while the others idle. The
classic cure is *longest processing time first*; the runtimes are not known in advance, so
:class:`LongestFirst` learns them: it first takes one run of every cell not yet timed, then
always a run of the cell whose finished runs took longest on average.
"""

from __future__ import annotations

import json
from collections.abc import Iterable

from searchtrack.sim.campaigns.spec import RunSpec


def cell_of(run: RunSpec) -> str:
    """The grid cell of ``run``: its parameters as canonical JSON."""
    return json.dumps(run.params, sort_keys=True)


class LongestFirst:
    """A queue of runs: untimed cells first (in grid order), then the slowest cell's runs."""

    def __init__(self, runs: Iterable[RunSpec]) -> None:
        self._left: dict[str, list[RunSpec]] = {}
        for run in runs:
            self._left.setdefault(cell_of(run), []).append(run)
        for queue in self._left.values():
            queue.reverse()  # pop() takes the lowest seed first
        self._spent: dict[str, tuple[float, int]] = {}
        self._probing: set[str] = set()
        self._size = sum(len(q) for q in self._left.values())

    def __len__(self) -> int:
        return self._size

    def pop(self) -> RunSpec:
        """The next run to submit (:class:`IndexError` when none is left)."""
        if not self._size:
            raise IndexError("no run left")
        untimed = [c for c in self._left if c not in self._spent and c not in self._probing]
        if untimed:
            cell = untimed[0]
            self._probing.add(cell)
        else:
            cell = max(self._left, key=lambda c: self._mean(c))
        queue = self._left[cell]
        run = queue.pop()
        if not queue:
            del self._left[cell]
        self._size -= 1
        return run

    def record(self, run: RunSpec, runtime_s: float) -> None:
        """Learn that ``run`` took ``runtime_s`` seconds."""
        cell = cell_of(run)
        total, n = self._spent.get(cell, (0.0, 0))
        self._spent[cell] = (total + max(float(runtime_s), 0.0), n + 1)

    def _mean(self, cell: str) -> float:
        total, n = self._spent.get(cell, (0.0, 0))
        # A cell probed but not yet finished is at least as slow as the slowest timed one.
        return total / n if n else float("inf")
