"""Longest-first submission order of a campaign's runs."""

from __future__ import annotations

import pytest

from searchtrack.sim.campaigns.schedule import LongestFirst, cell_of
from searchtrack.sim.campaigns.spec import RunSpec


def _runs(cells: dict[str, int], seeds: int) -> list[RunSpec]:
    return [RunSpec(f"{name}-{s}", "toy", {"cell": name}, s)
            for name in cells for s in range(seeds)]


def test_probes_every_cell_once_in_grid_order_then_takes_the_slowest() -> None:
    queue = LongestFirst(_runs({"a": 0, "b": 0, "c": 0}, 3))
    probes = [queue.pop() for _ in range(3)]
    assert [r.params["cell"] for r in probes] == ["a", "b", "c"]
    assert [r.seed for r in probes] == [0, 0, 0]
    for run, seconds in zip(probes, (1.0, 5.0, 2.0), strict=True):
        queue.record(run, seconds)
    order = [queue.pop() for _ in range(len(queue))]
    assert [r.params["cell"] for r in order] == ["b", "b", "c", "c", "a", "a"]
    assert [r.seed for r in order[:2]] == [1, 2]


def test_a_cell_still_running_counts_as_slow() -> None:
    queue = LongestFirst(_runs({"a": 0, "b": 0}, 3))
    first, second = queue.pop(), queue.pop()
    queue.record(first, 10.0)  # b's probe has not finished: it is not known to be faster
    assert queue.pop().params["cell"] == second.params["cell"]


def test_every_run_comes_out_exactly_once() -> None:
    runs = _runs({"a": 0, "b": 0, "c": 0, "d": 0}, 5)
    queue = LongestFirst(runs)
    out: list[RunSpec] = []
    while queue:
        run = queue.pop()
        queue.record(run, float(len(out) % 3))
        out.append(run)
    assert sorted(r.key for r in out) == sorted(r.key for r in runs)
    with pytest.raises(IndexError):
        queue.pop()


def test_cell_ignores_the_seed_and_the_parameter_order() -> None:
    a = RunSpec("k1", "toy", {"x": 1, "y": 2}, 0)
    b = RunSpec("k2", "toy", {"y": 2, "x": 1}, 7)
    assert cell_of(a) == cell_of(b)
