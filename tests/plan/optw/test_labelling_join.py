"""Bidirectional labelling: half passes split at ``t_m`` and their join, against every
elementary path of random instances."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.labelling_core import (
    CAP_MAX,
    base_ng,
    build_cores,
    initial_ng,
    run_pass,
)
from searchtrack.plan.optw.labelling_join import Joined, backward_stop, join, split_time
from searchtrack.plan.optw.labelling_kernels import DONE
from tests.plan.optw.small import elementary_paths, random_instance


def _wide(seed: int) -> OPTWInstance:
    """Ten customers on a square with wide windows: routes of several customers, so that most
    paths cross the split."""
    rng = np.random.default_rng(seed)
    n = 11
    xy = rng.uniform(0, 20, size=(n, 2))
    travel = np.ceil(np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1)))
    opn = rng.integers(0, 40, size=n)
    opn[0] = 0
    close = opn + rng.integers(20, 80, size=n)
    close[0] = 120
    return OPTWInstance(travel=travel.astype(int), service=rng.integers(1, 5, size=n),
                        profit=rng.integers(1, 9, size=n).astype(float), open=opn, close=close,
                        tmax=int(rng.integers(60, 120)), name=f"wide-{seed}")


def _bidirectional(inst: OPTWInstance, prof: np.ndarray, floor: float, keep: int,
                   tm: int | None = None) -> tuple[list[tuple[float, tuple[int, ...]]], Joined]:
    """The forward half pass's complete paths and the join, as ``(value, path)`` pairs."""
    fwd, rev, _ = build_cores(inst)
    fwd, rev = dataclasses.replace(fwd, prof=prof), dataclasses.replace(rev, prof=prof)
    ng = base_ng(fwd) | initial_ng(fwd, fwd.n)
    tm = split_time(fwd) if tm is None else tm
    bprof = np.maximum(prof, 0.0)
    kw = {"lb": floor, "gap": 1e-6, "cap": CAP_MAX, "deadline": Deadline(30.0),
          "collect": 1 << 40, "bprof": bprof}
    f = run_pass(fwd, ng, None, tstop=tm, **kw)  # type: ignore[arg-type]
    b = run_pass(rev, ng, None, tstop=backward_stop(fwd, tm), **kw)  # type: ignore[arg-type]
    assert f.code == DONE and b.code == DONE
    assert b.found.size == 0 and b.sinks.size == 0  # no whole path ends in the backward half
    assert (f.lt[: f.labels] <= tm).all()
    assert (fwd.horizon - b.lt[1 : b.labels] > tm).all()
    j = join(fwd, f, b, tm, target=floor + 1e-6, keep=keep, deadline=Deadline(30.0))
    assert j.code == DONE
    whole = [(float(f.lp[s]), tuple(f.path(s))) for s in f.found.tolist()]
    return whole + [(v, tuple(p)) for v, p in zip(j.values, j.paths, strict=True)], j


@pytest.mark.parametrize("seed", range(12))
def test_joins_reach_the_best_path_once(seed: int) -> None:
    """With random (also negative) profits and floors: every path returned is elementary,
    feasible, of its claimed value, above the floor and made once; one is returned whenever some
    path beats the floor; the best value found and the join's bound cover the best path."""
    inst = _wide(seed) if seed % 2 else random_instance(seed)
    fwd, _, _ = build_cores(inst)
    every = elementary_paths(fwd)
    rng = np.random.default_rng(seed)
    for trial in range(5):
        prof = fwd.prof - np.r_[0, rng.uniform(0, 1.3, fwd.n - 2) * fwd.prof[1:-1], 0]
        best = max(float(prof[list(p)].sum()) for p in every)
        floor = -1.0 if trial == 0 else best - rng.uniform(-1, 3)
        got, j = _bidirectional(inst, prof, floor, keep=1 << 20)
        paths = [p for _, p in got]
        assert len(set(paths)) == len(paths)
        for value, path in got:
            assert path in every and value == pytest.approx(float(prof[list(path)].sum()))
            assert value > floor
        assert bool(got) == (best > floor + 1e-6)
        if got:
            assert max(v for v, _ in got) == pytest.approx(best)
            assert max(j.upper, max(v for v, _ in got)) >= best - 1e-9


@pytest.mark.parametrize("seed", [1, 3, 5])
def test_any_split_gives_the_same_best(seed: int) -> None:
    """The split time only moves work between the halves: at the departure, a quarter, half and
    three quarters of the way, and at the end, the best path is the same."""
    inst = _wide(seed)
    fwd, _, _ = build_cores(inst)
    dep, end = int(fwd.opn[fwd.src]), int(fwd.cls[fwd.snk])
    best = max(float(fwd.prof[list(p)].sum()) for p in elementary_paths(fwd))
    for share in (0.0, 0.25, 0.5, 0.75, 1.0):
        got, _ = _bidirectional(inst, fwd.prof.copy(), -1.0, keep=1 << 20,
                                tm=dep + int(share * (end - dep)))
        assert max(v for v, _ in got) == pytest.approx(best)


@pytest.mark.parametrize("seed", [1, 3, 7])
def test_keep_returns_the_best_joins(seed: int) -> None:
    """Asked for the ``k`` best joins, the join returns the ``k`` highest values among all of
    them, and the same bound."""
    inst = _wide(seed)
    fwd, _, _ = build_cores(inst)
    _, every = _bidirectional(inst, fwd.prof.copy(), -1.0, keep=1 << 20)
    assert len(every.values) > 10
    for k in (1, 3, 10):
        _, some = _bidirectional(inst, fwd.prof.copy(), -1.0, keep=k)
        assert sorted(some.values, reverse=True) == pytest.approx(
            sorted(every.values, reverse=True)[:k])
        assert some.upper == every.upper
        assert not some.relaxed


def test_split_time_is_midway() -> None:
    """``t_m`` lies midway between the departure and the sink's latest arrival, and the backward
    half keeps the latest starts after it."""
    fwd, _, _ = build_cores(_wide(0))
    tm = split_time(fwd)
    assert fwd.opn[fwd.src] <= tm <= fwd.cls[fwd.snk]
    assert fwd.horizon - backward_stop(fwd, tm) == tm + 1
    assert math.isfinite(tm)
