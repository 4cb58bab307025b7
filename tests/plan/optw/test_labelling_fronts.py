"""Time-sorted label fronts: on random streams of labels over several groups sharing one pool,
the dominance answers, the labels marked dead (in the label's own group, and from a later time
on in another) and each group's kept labels match a brute-force list, with and without
subset-row cut states."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.plan.optw.labelling_fronts import (
    front_dominated,
    front_kill,
    front_put,
    front_room,
)


def _owed(a: int, b: int, sig: np.ndarray) -> float:
    """``Σ sig[c]`` over the cut bits set in ``a`` and not in ``b``."""
    return float(sum(sig[c] for c in range(64) if (a & ~b) >> c & 1))


def _dominates(x: tuple[int, float, int], y: tuple[int, float, int], sig: np.ndarray) -> bool:
    """Label ``x = (time, profit, cut state)`` dominates ``y`` within one group."""
    return x[0] <= y[0] and x[1] - _owed(x[2], y[2], sig) >= y[1]


@pytest.mark.parametrize("cuts", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_fronts_match_a_brute_force_list(seed: int, cuts: bool) -> None:
    rng = np.random.default_rng(seed)
    groups, n = 3, 400
    sig = np.zeros(64)
    sig[:4] = rng.uniform(0.0, 3.0, size=4)
    lc = np.zeros((n, 1 if cuts else 0), dtype=np.uint64)
    alive = np.zeros(n, dtype=np.bool_)
    gstart = np.zeros(groups, dtype=np.int64)
    glen = np.zeros(groups, dtype=np.int64)
    gcap = np.zeros(groups, dtype=np.int64)
    size = 8 * n
    ft = np.zeros(size, dtype=np.int64)
    fp = np.zeros(size)
    fl = np.zeros(size, dtype=np.int64)
    work = np.zeros(1, dtype=np.int64)
    kept: list[list[int]] = [[] for _ in range(groups)]
    label: list[tuple[int, float, int]] = []
    used = 0
    for s in range(n):
        g = int(rng.integers(groups))
        t = int(rng.integers(0, 60))
        p = float(rng.integers(0, 40))  # ties in time and profit are frequent
        bits = int(rng.integers(0, 16)) if cuts else 0
        label.append((t, p, bits))
        state = np.array([bits] if cuts else [], dtype=np.uint64)
        if cuts:
            lc[s, 0] = bits
        expect = any(_dominates(label[x], label[s], sig) for x in kept[g])
        got = front_dominated(ft, fp, fl, lc, sig, gstart[g], glen[g], t, p, state, work)
        assert got == expect
        if got:
            continue
        alive[s] = True
        other = int(rng.integers(groups))
        t0 = t + int(rng.integers(0, 20))  # in another group: from a later time on
        for h, since in ((g, t), (other, t0)):
            glen[h] = front_kill(ft, fp, fl, alive, lc, sig, gstart[h], glen[h], since, p, state,
                                 work)
            killed = [x for x in kept[h]
                      if label[x][0] >= since and _dominates((since, p, bits), label[x], sig)]
            assert not alive[killed].any()
            kept[h] = [x for x in kept[h] if x not in killed]
            assert alive[kept[h]].all()
        if glen[g] >= gcap[g]:
            assert used + front_room(gcap[g]) <= size
        used = front_put(ft, fp, fl, gstart, glen, gcap, g, used, t, p, s)
        kept[g].append(s)
        for h in range(groups):
            seg = slice(gstart[h], gstart[h] + glen[h])
            assert sorted(fl[seg].tolist()) == sorted(kept[h])
            assert np.all(np.diff(ft[seg]) >= 0)  # sorted by time
            if not cuts:  # a Pareto front: times and profits both strictly increasing
                assert np.all(np.diff(ft[seg]) > 0) and np.all(np.diff(fp[seg]) > 0)
            assert np.array_equal(ft[seg], [label[x][0] for x in fl[seg]])
            assert np.array_equal(fp[seg], [label[x][1] for x in fl[seg]])
    assert sum(len(k) for k in kept) >= groups  # the stream kept labels in every group
