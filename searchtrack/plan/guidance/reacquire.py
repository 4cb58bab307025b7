"""Reacquiring a fading target as an orienteering problem with time windows (thesis 001, §5.5).

When a paired UAV's tracker peak falls to ``ϱ`` the UAV plans one route over the tracker's most
probable nodes and follows it with the spring ∇W (5.32). The instance follows §5.5: scores are
the tracker's probabilities, the start is the UAV's position with zero score, every window is
``[0, T_r]`` (time measured from now), service times are zero, travel time is Euclidean
distance / ``S_max`` (Dubins turning ignored), and the end is open (``end=None``), which is what
§5.5's slack end node ``E`` achieves.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.checks import count
from searchtrack.core.deadline import check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result
from searchtrack.estimate.belief import NodePredictor, SparseNodePredictor
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.solve import solve, solve_ils_capped

log = logging.getLogger("searchtrack.plan.guidance.reacquire")

#: Time precision of the instance: 10 ms (a UAV covers 0.36 m at 80 mph).
TIME_DECIMALS = 2


_SUPPORT_TOL = 1e-12  # relative mass below which reacquire_time drops a node from the support


def _probability(name: str, value: ArrayLike, n: int) -> NDArray[np.float64]:
    p = np.asarray(value, dtype=np.float64)
    if p.shape != (n,) or not np.all(np.isfinite(p)) or np.any(p < 0.0):
        raise InvalidInputError(name, value, f"must be non-negative and finite, shape ({n},)")
    return p


def reacquire_time(
    predictor: NodePredictor,
    probability: ArrayLike,
    *,
    p_min: float = 0.07,
    max_steps: int = 2000,
) -> float:
    """``T_r``: seconds until the peak of ``probability`` falls below ``p_min`` under (4.2) alone.

    Simulated with ``predictor`` (the trackers' prediction ``e^{−αLΔt}``, e.g. a
    :class:`~searchtrack.estimate.diffusion.GraphDiffusion`) from the *current* tracker, not
    from a peak of exactly ``ϱ`` as the thesis phrases it: the tracker that triggers
    reacquisition has just crossed ``ϱ``, so the two agree up to one step. Returns 0 if the
    peak is already below ``p_min`` and ``max_steps · Δt`` if it never falls below within
    ``max_steps`` steps.

    Any :class:`~searchtrack.estimate.belief.NodePredictor` will do (full ``propagate`` steps);
    a :class:`~searchtrack.estimate.belief.SparseNodePredictor` with its operator built is
    stepped on the tracker's support only, with the same result.

    Raises
    ------
    InvalidInputError
        ``predictor`` not a NodePredictor, ``probability`` not ``(n,)`` non-negative and
        finite, ``p_min`` outside ``(0, 1)`` or ``max_steps`` < 1.
    """
    if not isinstance(predictor, NodePredictor):
        raise InvalidInputError("predictor", predictor,
                                "must be a NodePredictor (n_nodes, dt_s, propagate), "
                                "e.g. a GraphDiffusion")
    p = _probability("probability", probability, predictor.n_nodes)
    if not (isinstance(p_min, (int, float)) and 0.0 < p_min < 1.0):
        raise InvalidInputError("p_min", p_min, "must be in (0, 1)")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise InvalidInputError("max_steps", max_steps, "must be an integer ≥ 1")
    op = predictor.operator if isinstance(predictor, SparseNodePredictor) else None
    if op is None:
        steps, peak = _full_steps(predictor, p, p_min, max_steps)
    else:
        assert isinstance(predictor, SparseNodePredictor)
        steps, peak = _support_steps(op, predictor.decay_factor, p, p_min, max_steps)
    if peak >= p_min:
        log.debug("peak still %.3g after %d steps; T_r capped", peak, max_steps)
    return steps * float(predictor.dt_s)


def _full_steps(predictor: NodePredictor, p: NDArray[np.float64], p_min: float,
                max_steps: int) -> tuple[int, float]:
    """Steps of ``predictor.propagate`` until the peak is below ``p_min``, and that peak."""
    steps = 0
    while p.max() >= p_min and steps < max_steps:
        p = np.asarray(predictor.propagate(p), dtype=np.float64)
        steps += 1
    return steps, float(p.max())


def _support_steps(op: Any, scale: float, p: NDArray[np.float64], p_min: float,
                   max_steps: int) -> tuple[int, float]:
    """As :func:`_full_steps` on the support only. The tracker is local: the operator is
    symmetric, so the columns the support needs are its rows, a cheap CSR slice; values below
    ``_SUPPORT_TOL`` of the mass are dropped (they cannot hold the peak)."""
    floor = _SUPPORT_TOL * float(p.sum())
    idx = np.flatnonzero(p > floor)
    vals = p[idx]
    steps = 0
    while vals.size and vals.max() >= p_min and steps < max_steps:
        full = np.asarray(op[idx].T @ vals, dtype=np.float64) * scale
        idx = np.flatnonzero(full > floor)
        vals = full[idx]
        steps += 1
    return steps, float(vals.max()) if vals.size else 0.0


def candidate_nodes(
    probability: ArrayLike, *, max_nodes: int = 60, support_mass: float = 0.95
) -> NDArray[np.int64]:
    """The most probable nodes, in decreasing probability, until ``support_mass`` is covered.

    At most ``max_nodes`` are kept (the thesis uses every node of the tracker, which on a city
    map is thousands: too many for a real-time solve); zero-probability nodes never are. Among
    equally probable nodes the lower index comes first, also where ``max_nodes`` cuts.
    """
    p = np.asarray(probability, dtype=np.float64)
    if p.ndim != 1 or not np.all(np.isfinite(p)) or np.any(p < 0.0):
        raise InvalidInputError("probability", probability, "must be non-negative and finite")
    if isinstance(max_nodes, bool) or not isinstance(max_nodes, int) or max_nodes < 1:
        raise InvalidInputError("max_nodes", max_nodes, "must be an integer ≥ 1")
    if not (isinstance(support_mass, (int, float)) and 0.0 < support_mass <= 1.0):
        raise InvalidInputError("support_mass", support_mass, "must be in (0, 1]")
    k = min(max_nodes, int(np.count_nonzero(p)))
    if k == 0:
        return np.empty(0, dtype=np.int64)
    nonzero = np.flatnonzero(p > 0.0)
    if k < nonzero.size:   # the k largest in linear time: above the k-th, then its ties
        values = p[nonzero]
        kth = np.partition(values, values.size - k)[values.size - k]
        above = nonzero[values > kth]
        nonzero = np.concatenate([above, nonzero[values == kth][:k - above.size]])
    # decreasing probability, lower index first on ties (also at the max_nodes cut)
    top = nonzero[np.lexsort((nonzero, -p[nonzero]))]
    cum = np.cumsum(p[top]) / p.sum()
    keep = int(np.searchsorted(cum, support_mass * (1.0 - 1e-12))) + 1
    return np.asarray(top[:keep], dtype=np.int64)


def reacquisition_instance(
    network: RoadNetwork,
    probability: ArrayLike,
    uav_xy_m: ArrayLike,
    speed_mps: float,
    horizon_s: float,
    *,
    max_nodes: int = 60,
    support_mass: float = 0.95,
) -> tuple[OPTWInstance, NDArray[np.int64]]:
    """The OPTW (5.17)–(5.26) adapted to reacquisition, and the road node of each vertex.

    Vertex 0 is the UAV's position (score 0); vertices ``1..k`` are the
    :func:`candidate_nodes`, scored by their probability. Windows are ``[0, horizon_s]``
    (``horizon_s`` = ``T_r``), service times 0, travel times Euclidean / ``speed_mps`` (ceiled
    to :data:`TIME_DECIMALS` decimals), open end. ``node_ids[0]`` is −1 (the UAV).
    """
    p = _probability("probability", probability, network.n_nodes)
    xy = np.asarray(uav_xy_m, dtype=np.float64)
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise InvalidInputError("uav_xy_m", uav_xy_m, "must be one finite point (x, y) (m)")
    if not (isinstance(speed_mps, (int, float)) and math.isfinite(speed_mps) and speed_mps > 0):
        raise InvalidInputError("speed_mps", speed_mps, "must be positive and finite")
    if not (isinstance(horizon_s, (int, float)) and math.isfinite(horizon_s) and horizon_s >= 0):
        raise InvalidInputError("horizon_s", horizon_s, "must be finite and ≥ 0 (s)")
    nodes = candidate_nodes(p, max_nodes=max_nodes, support_mass=support_mass)
    coords = np.vstack([xy[None, :], network.coords[nodes]])
    n = coords.shape[0]
    profit = np.concatenate([[0.0], p[nodes]])
    inst = OPTWInstance.from_coordinates(
        coords, profit, np.zeros(n), np.zeros(n), np.full(n, float(horizon_s)),
        decimals=TIME_DECIMALS, rounding="ceil", speed=float(speed_mps), start=0, end=None,
        tmax=float(horizon_s), name="reacquire",
    )
    return inst, np.concatenate([[-1], nodes]).astype(np.int64)


def check_optw_iterations(backend: str, iterations: int | None) -> None:
    """An iteration cap of the reacquisition OPTW is an integer ≥ 1, and only with the ILS
    (``backend == "ils"``), the one backend that counts iterations."""
    if iterations is None:
        return
    count("optw_iterations", iterations, least=1)
    if backend != "ils":
        raise InvalidInputError("optw_iterations", iterations,
                                f"caps the ILS only; optw_backend is {backend!r}, not 'ils'")


def plan_reacquisition(
    instance: OPTWInstance,
    node_ids: NDArray[np.int64],
    *,
    backend: str = "auto",
    time_limit_s: float = 0.03,
    seed: int = 0,
    max_iterations: int | None = None,
) -> tuple[tuple[int, ...], Result[tuple[tuple[int, ...], ...]]]:
    """Solve the reacquisition OPTW; the route as road node ids (start excluded) and the result.

    An instance with no candidate node, or a result without a plan, gives an empty route.
    ``max_iterations`` caps the ILS's iterations (``backend = "ils"`` only), its answer then
    the same on any machine fast enough to reach the cap within ``time_limit_s``; it is checked
    by the family's validator, as every backend's answer is.
    """
    check_time_limit(time_limit_s)
    check_optw_iterations(backend, max_iterations)
    if node_ids.shape != (instance.n,):
        raise InvalidInputError("node_ids", node_ids, f"must have {instance.n} entries")
    if max_iterations is None:
        result = solve(instance, backend=backend, time_limit_s=time_limit_s, seed=seed)
    else:
        result = solve_ils_capped(instance, time_limit_s=time_limit_s, seed=seed,
                                  max_iterations=max_iterations)
    if result.plan is None or not result.plan:
        return (), result
    route = tuple(int(node_ids[v]) for v in result.plan[0] if v != instance.start)
    return route, result
