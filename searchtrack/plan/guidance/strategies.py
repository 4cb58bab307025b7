"""The Ch. 5 guidance laws as solver backends: search (5.12), loiter (5.15), search-and-loiter
(5.16) and search-and-reacquire (5.33), each ``solve(problem, *, time_limit_s, seed) ->
Result[Guidance]`` (registered by name in :mod:`searchtrack.plan.guidance.solve`).

Per UAV the mode decides the force:

- ``"search"``: ∇R + ∇P + ∇Q (likelihood gradient, Pauli repulsion from every UAV, spring of
  rest length ``ρ`` to ``n_max``), plus, for a UAV paired with no tracker, the coverage force
  when ``coverage_weight > 0`` and the view carries coverage (this library's, off by default);
- ``"loiter"``: ∇L + ∇P, zero-rest spring to the tracker's peak node, repelled only by the other
  loitering or reacquiring UAVs (5.14);
- ``"reacquire"``: ∇W + ∇P, zero-rest spring to the next unserved node of an OPTW route, Pauli
  as for loiter;
- ``"route"`` (the route strategies of :mod:`~searchtrack.plan.guidance.route_strategies`):
  ∇W + ∇P, zero-rest spring to the first node of a search route, Pauli as for search.

Randomness comes from ``numpy.random.default_rng(seed)``: the gradient's tie-break draws for
every UAV every step, whatever the modes, and search-and-reacquire draws one OPTW seed per route
it plans. An answer is deterministic for a seed as long as each OPTW solve finishes within its
share of ``time_limit_s`` (a solve cut off by its time limit may return a different route on a
slower machine).

The answer is ``FEASIBLE`` (nothing is optimised globally), ``bound`` ``None``. Its objective is
the tracker probability the plan sets out to cover: for each loitering UAV its tracker's peak
probability ``𝒫``, for each reacquiring UAV its tracker's probability summed over the route
nodes still to visit; 0 when every UAV searches.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.registry import MAX_SEED, SolveFn
from searchtrack.core.result import Result, Status
from searchtrack.plan.guidance.forces import coverage_force, pauli_force, spring_force
from searchtrack.plan.guidance.pairing import Pairing, pair_checked
from searchtrack.plan.guidance.problem import GuidanceProblem
from searchtrack.plan.guidance.reacquire import (
    plan_reacquisition,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance.view import Guidance, GuidanceView, Reacquisition

log = logging.getLogger("searchtrack.plan.guidance.strategies")

_HELD = ("loiter", "reacquire")

#: Per UAV, ``"search"`` or ``"loiter"`` from the step's pairing.
ModeRule = Callable[[GuidanceProblem, Pairing], list[str]]


def search_modes(problem: GuidanceProblem, pairing: Pairing) -> list[str]:
    """(5.12): every UAV searches; trackers are paired but ignored (experiment 1)."""
    return ["search"] * problem.view.n_uavs


def loiter_modes(problem: GuidanceProblem, pairing: Pairing) -> list[str]:
    """(5.15): paired UAVs loiter over their tracker's peak, the rest search."""
    return ["loiter" if t >= 0 else "search" for t in pairing.tracker]


def search_and_loiter_modes(problem: GuidanceProblem, pairing: Pairing) -> list[str]:
    """(5.16): paired UAVs loiter only while their tracker's peak is ≤ ``ϱ``; no hysteresis."""
    rho = problem.config.revisit_threshold
    return ["loiter" if t >= 0 and p <= rho else "search"
            for t, p in zip(pairing.tracker, pairing.peak_probability, strict=True)]


def assemble(problem: GuidanceProblem, rng: np.random.Generator, modes: list[str],
             anchors: NDArray[np.float64], pairing: Pairing | None = None
             ) -> NDArray[np.float64]:
    """Net force per UAV for the given modes; ``anchors`` are the held and routed UAVs' spring
    ends (a ``"route"`` UAV feels ∇P from every UAV, as a searching one, and the zero-rest
    spring ∇W to its anchor instead of ∇R + ∇Q).

    With a positive ``coverage_weight`` and a view that carries coverage, the searching UAVs
    that ``pairing`` pairs with no tracker (all searching UAVs without a pairing) also feel the
    coverage force (:func:`~searchtrack.plan.guidance.forces.coverage_force`).
    """
    cfg, view = problem.config, problem.view
    grad, n_max = problem.gradient_field.force(view.uav_xy_m, view.field.node_score(),
                                               cfg.sensor_range_m, rng)
    held = np.array([m in _HELD for m in modes])
    routed = np.array([m == "route" for m in modes])
    repellers = np.where(held[:, None], held[None, :], True)
    force = pauli_force(view.uav_xy_m, cfg.sigma, epsilon=cfg.epsilon, repellers=repellers)
    search = ~held & ~routed
    if routed.any():
        force[routed] += spring_force(view.uav_xy_m[routed], anchors[routed], cfg.k_loiter)
    if search.any():
        q = spring_force(view.uav_xy_m[search], view.network.coords[n_max[search]],
                         cfg.k_spring, cfg.sensor_range_m)
        force[search] += grad[search] + q
    if held.any():
        force[held] += spring_force(view.uav_xy_m[held], anchors[held], cfg.k_loiter)
    if cfg.coverage_weight > 0.0 and view.coverage is not None:
        free = search if pairing is None else search & (np.array(pairing.tracker) < 0)
        if free.any():
            rho = cfg.sensor_range_m
            push = coverage_force(view.network, view.uav_xy_m[free], view.coverage, rho,
                                  2.0 * rho)
            force[free] += cfg.coverage_weight * push
    return force


def peak_anchors(view: GuidanceView, pairing: Pairing) -> NDArray[np.float64]:
    """Per UAV its tracker's peak node's position, its own position when unpaired."""
    anchors = np.array(view.uav_xy_m, copy=True)
    for j, node in enumerate(pairing.peak_node):
        if node >= 0:
            anchors[j] = view.network.coords[node]
    return anchors


def covered_probability(problem: GuidanceProblem, guidance: Guidance) -> float:
    """The objective of an answer: per loitering UAV its tracker's peak probability, per
    reacquiring UAV its tracker's probability on the remaining route nodes (module docstring)."""
    bank, pairing = problem.view.bank, guidance.pairing
    total = 0.0
    for j, mode in enumerate(guidance.mode):
        if mode == "loiter":
            total += pairing.peak_probability[j]
        elif mode == "reacquire":
            belief = bank[pairing.tracker[j]]
            p = belief.node_probability() / belief.mass()
            total += float(p[list(guidance.route[j])].sum())
    return total


def answer(problem: GuidanceProblem, guidance: Guidance, backend: str, clock: Deadline,
           plans: int) -> Result[Guidance]:
    """The ``FEASIBLE`` result of a strategy's ``guidance`` (``plans`` routes planned)."""
    return Result(Status.FEASIBLE, covered_probability(problem, guidance), None, clock.elapsed(),
                  backend, guidance, message=f"modes {','.join(guidance.mode)}",
                  stats={"plans": float(plans), "plan_ms": guidance.plan_ms})


def potential(rule: ModeRule, name: str) -> SolveFn[GuidanceProblem, Guidance]:
    """The backend that flies the modes of ``rule``, holding over tracker peaks."""

    def solve(problem: GuidanceProblem, *, time_limit_s: float, seed: int) -> Result[Guidance]:
        clock = Deadline(time_limit_s)
        rng = np.random.default_rng(seed)
        view = problem.view
        pairing = pair_checked(view.network, view.uav_xy_m, view.bank)
        modes = rule(problem, pairing)
        force = assemble(problem, rng, modes, peak_anchors(view, pairing), pairing)
        guidance = Guidance(force, pairing, tuple(modes), ((),) * view.n_uavs, 0.0)
        return answer(problem, guidance, name, clock, 0)

    solve.__name__ = f"solve_{name}"
    solve.__doc__ = f"The ``{name}`` backend: {rule.__doc__}"
    return solve


solve_search = potential(search_modes, "search")
solve_loiter = potential(loiter_modes, "loiter")
solve_search_and_loiter = potential(search_and_loiter_modes, "search_and_loiter")


def _plan(problem: GuidanceProblem, uav: int, tracker: int, rng: np.random.Generator,
          budget: Deadline, waiting: int) -> tuple[int, ...]:
    """Plan ``uav``'s route; the OPTW gets an equal share of what is left of the step's
    ``budget`` among the ``waiting`` plans still to make (this one included)."""
    cfg, view = problem.config, problem.view
    belief = view.bank[tracker]
    probability = belief.node_probability() / belief.mass()
    horizon = reacquire_time(problem.predictor, probability, p_min=cfg.p_min,
                             max_steps=cfg.max_reacquire_steps)
    inst, node_ids = reacquisition_instance(
        view.network, probability, view.uav_xy_m[uav], cfg.speed_mps, horizon,
        max_nodes=cfg.max_route_nodes, support_mass=cfg.support_mass)
    seed = int(rng.integers(0, MAX_SEED))
    nodes, result = plan_reacquisition(inst, node_ids, backend=cfg.optw_backend,
                                       time_limit_s=max(1e-3, budget.remaining() / waiting),
                                       seed=seed, max_iterations=cfg.optw_iterations)
    log.debug("uav %d, track %d: T_r=%.1f s, %d candidates, %s route of %d nodes (%.3g)",
              uav, belief.track_id, horizon, inst.n - 1, result.status.name, len(nodes),
              result.objective or 0.0)
    return nodes


def reacquire_fading(problem: GuidanceProblem, pairing: Pairing, modes: list[str],
                     anchors: NDArray[np.float64], routes: list[tuple[int, ...]],
                     rng: np.random.Generator, budget: Deadline, later: int = 0
                     ) -> tuple[tuple[Reacquisition, ...], int]:
    """(5.33) for the UAVs ``modes`` holds over a fading tracker (``"loiter"``): the routes they
    keep flying and the number of routes planned this step.

    Serves, keeps or re-plans each fading tracker's route (:func:`solve_search_and_reacquire`)
    and turns a UAV with nodes left to ``"reacquire"``, its ``anchors`` row to the next node and
    its ``routes`` entry to the nodes left (``modes``, ``anchors`` and ``routes`` are changed in
    place). The plans share ``budget`` with ``later`` plans the caller makes after them.
    """
    view, rho = problem.view, problem.config.sensor_range_m
    fading = {pairing.track_id[j]: j for j, m in enumerate(modes) if m == "loiter"}
    kept = {r.track_id: r for r in problem.reacquisitions if r.track_id in fading}
    stale: list[tuple[int, int]] = []  # reacquired, unpaired or dissolved tracks are dropped
    for track, j in fading.items():
        route = kept.get(track)
        if route is not None and route.uav == j:
            route = kept[track] = route.serve(view.network, view.uav_xy_m, rho)
        if route is None or route.uav != j or route.done:
            stale.append((track, j))
    for k, (track, j) in enumerate(stale):
        nodes = _plan(problem, j, pairing.tracker[j], rng, budget, len(stale) - k + later)
        kept[track] = Reacquisition.planned(track, j, nodes).serve(view.network, view.uav_xy_m,
                                                                   rho)
    for track, j in fading.items():
        left = kept[track].remaining()
        if left:
            modes[j] = "reacquire"
            anchors[j] = view.network.coords[left[0]]
            routes[j] = left
    return tuple(kept[track] for track in fading), len(stale)


def solve_search_and_reacquire(problem: GuidanceProblem, *, time_limit_s: float,
                               seed: int) -> Result[Guidance]:
    """(5.33): as (5.16), but a fading tracker's UAV flies an OPTW route over its likely nodes.

    When a paired UAV's peak is ≤ ``ϱ`` it plans a route once (:mod:`.reacquire`) and follows
    it with ∇W toward the next unserved node; a node is served once within ``ρ`` of the UAV. It
    re-plans when the route is exhausted or its tracker now has another UAV, and drops the route
    when the peak is back above ``ϱ`` (reacquired), the tracker is unpaired or dissolved. A UAV
    whose plan is empty loiters over the peak (mode ``"loiter"``) and re-plans next step.
    Routes are kept by ``track_id`` in :attr:`Guidance.reacquisitions`; the route plans of one
    step share ``time_limit_s``.
    """
    clock = Deadline(time_limit_s)
    rng = np.random.default_rng(seed)
    view = problem.view
    pairing = pair_checked(view.network, view.uav_xy_m, view.bank)
    modes = search_and_loiter_modes(problem, pairing)
    anchors = peak_anchors(view, pairing)
    routes: list[tuple[int, ...]] = [()] * view.n_uavs
    budget = Deadline(time_limit_s)  # one budget per step, shared
    kept, plans = reacquire_fading(problem, pairing, modes, anchors, routes, rng, budget)
    plan_s = budget.elapsed() if plans else 0.0
    force = assemble(problem, rng, modes, anchors, pairing)
    guidance = Guidance(force, pairing, tuple(modes), tuple(routes), 1000.0 * plan_s, kept)
    return answer(problem, guidance, "search_and_reacquire", clock, plans)
