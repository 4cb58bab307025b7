"""Iterated local search for the (team) OPTW, after Vansteenwegen et al. (2009), with extensions.

The hot loops live in :mod:`searchtrack.plan.optw.ils_kernels` (Numba); this module packs the
instance into flat arrays, drives the search in short batches so the deadline is honoured, and
turns the best solution back into routes.
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
from numpy.typing import NDArray

from searchtrack.errors import InvalidInputError
from searchtrack.plan.optw import ils_kernels as K
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.reach import reach
from searchtrack.plan.result import Result, Status
from searchtrack.plan.stop import Deadline, check_time_limit

log = logging.getLogger("searchtrack.plan.optw.ils")

_BATCH_S = 2e-3  # target wall-clock seconds per kernel call

Arrays = tuple[NDArray[np.int64], ...]


def _pack(inst: OPTWInstance) -> tuple[tuple[object, ...], NDArray[np.bool_], int]:
    """Kernel arrays ``(T, S, O, C, P, cand)`` with a sink vertex ``n`` for the end."""
    n = inst.n
    rc = reach(inst)
    T = np.zeros((n + 1, n + 1), dtype=np.int64)
    T[:n, :n] = inst.travel
    if inst.end is not None:
        T[:n, n] = inst.travel[:, inst.end]
    S = np.append(inst.service, 0).astype(np.int64)
    O = np.append(inst.open, 0).astype(np.int64)
    end_close = inst.latest_finish
    if inst.end is not None:
        end_close = min(end_close, int(inst.close[inst.end]))
    C = np.append(inst.close, end_close).astype(np.int64)
    P = np.append(inst.profit, 0.0).astype(np.float64)
    cand = np.flatnonzero(rc.vertex_ok & (inst.profit > 0)).astype(np.int64)
    return (T, S, O, C, P, cand), rc.vertex_ok, n


def _empty(inst: OPTWInstance, m: int, cap: int, sink: int) -> Arrays:
    rt = np.zeros((m, cap), dtype=np.int64)
    rt[:, 0] = inst.start
    rt[:, 1] = sink
    ln = np.full(m, 2, dtype=np.int64)
    arr = np.zeros((m, cap), dtype=np.int64)
    st = np.zeros((m, cap), dtype=np.int64)
    ms = np.zeros((m, cap), dtype=np.int64)
    own = np.full(sink + 1, -1, dtype=np.int64)
    return (rt, ln, arr, st, ms, own)


def _routes(inst: OPTWInstance, sol: Arrays) -> Routes:
    rt, ln = sol[0], sol[1]
    out = []
    for r in range(ln.shape[0]):
        inner = tuple(int(v) for v in rt[r, 1 : ln[r] - 1])
        tail = () if inst.end is None else (inst.end,)
        out.append((inst.start, *inner, *tail))
    return tuple(out)


def solve_ils(
    instance: OPTWInstance,
    *,
    time_limit_s: float = 1.0,
    seed: int = 0,
    initial: Routes | None = None,
    max_iterations: int | None = None,
) -> Result[Routes]:
    """Solve a (team) OPTW heuristically within ``time_limit_s`` seconds."""
    deadline = Deadline(check_time_limit(time_limit_s))
    inst = instance
    m = inst.vehicles
    ins, vertex_ok, sink = _pack(inst)
    cap = int(ins[5].shape[0]) + 2  # type: ignore[attr-defined]
    cur = _empty(inst, m, cap, sink)
    best = _empty(inst, m, cap, sink)
    for r in range(m):
        K.schedule(ins, cur, r)
        K.schedule(ins, best, r)
    rng = np.array([np.random.default_rng(seed).integers(0, 2**63)], dtype=np.uint64)
    ctl = np.array([0, 1, 0, 0, max(2, ins[5].shape[0] // (3 * m))], dtype=np.int64)  # type: ignore[attr-defined]
    fctl = np.array([-1.0, 0.0])
    batch = 1
    while not deadline.expired():
        if max_iterations is not None and ctl[3] >= max_iterations:
            break
        k = batch if max_iterations is None else min(batch, max_iterations - int(ctl[3]))
        t0 = time.perf_counter()
        K.run_ils(ins, cur, best, rng, ctl, fctl, k)
        dt = time.perf_counter() - t0
        if dt < _BATCH_S / 2:
            batch *= 2
        elif dt > _BATCH_S and batch > 1:
            batch //= 2
    plan = _routes(inst, best)
    profit = float(fctl[0])
    total = float(inst.profit[vertex_ok].sum())
    status = Status.OPTIMAL if profit >= total - 1e-9 else Status.FEASIBLE
    return Result(
        status=status,
        objective=profit,
        bound=profit if status is Status.OPTIMAL else None,
        runtime_s=deadline.elapsed(),
        backend="ils",
        plan=plan,
        stats={"iterations": float(ctl[3])},
    )
