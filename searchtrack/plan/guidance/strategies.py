"""The Ch. 5 guidance strategies: search (5.12), loiter (5.15), search-and-loiter (5.16) and
search-and-reacquire (5.33), chosen by name from :data:`STRATEGIES`.

Every strategy is built as ``STRATEGIES[name](config, tracker_diffusion)`` and answers
``guide(view, rng) -> Guidance`` once per step. Per UAV the mode decides the force:

- ``"search"``: ∇R + ∇P + ∇Q (likelihood gradient, Pauli repulsion from every UAV, spring of
  rest length ``ρ`` to ``n_max``);
- ``"loiter"``: ∇L + ∇P, zero-rest spring to the tracker's peak node, repelled only by the other
  loitering or reacquiring UAVs (5.14);
- ``"reacquire"``: ∇W + ∇P, zero-rest spring to the next unserved node of an OPTW route, Pauli
  as for loiter.

The gradient's random tie-break draws from ``rng`` for every UAV every step, whatever the modes,
so runs are reproducible for a seed. :class:`SearchAndReacquire` keeps routes between steps (a
small mutable object; :meth:`~SearchAndReacquire.reset` forgets them); its choices are
deterministic for a seed as long as each OPTW solve finishes within its budget (a solve cut off
by its time limit may return a different route on a slower machine).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance.forces import GradientField, pauli_force, spring_force
from searchtrack.plan.guidance.pairing import Pairing, pair_uavs
from searchtrack.plan.guidance.reacquire import (
    plan_reacquisition,
    reacquire_time,
    reacquisition_instance,
)
from searchtrack.plan.guidance.view import Guidance, GuidanceView, StrategyConfig

log = logging.getLogger("searchtrack.plan.guidance.strategies")

_HELD = ("loiter", "reacquire")


class Strategy(Protocol):
    """A guidance law: forces for every UAV from the current view."""

    name: str

    def guide(self, view: GuidanceView, rng: np.random.Generator) -> Guidance:
        """The step's forces, pairing, modes and routes."""
        ...

    def reset(self) -> None:
        """Forget any memory kept between steps."""
        ...


class _Potential:
    """The shared machinery: the gradient field per network and the force assembly."""

    name = "potential"

    def __init__(self, config: StrategyConfig, diffusion: GraphDiffusion) -> None:
        if not isinstance(config, StrategyConfig):
            raise InvalidInputError("config", config, "must be a StrategyConfig")
        if not isinstance(diffusion, GraphDiffusion):
            raise InvalidInputError("diffusion", diffusion, "must be a GraphDiffusion")
        self.config = config
        self.diffusion = diffusion
        self._field: GradientField | None = None

    def reset(self) -> None:
        """Forget any memory kept between steps (none here)."""

    def _gradient(self, network: RoadNetwork) -> GradientField:
        if self._field is None or self._field.network is not network:
            if network.n_nodes != self.diffusion.n_nodes:
                raise InvalidInputError("network", network,
                                        f"must have the diffusion's {self.diffusion.n_nodes} nodes")
            self._field = GradientField(network)
        return self._field

    def _modes(self, view: GuidanceView, pairing: Pairing) -> list[str]:
        return ["search"] * view.n_uavs

    def _assemble(self, view: GuidanceView, rng: np.random.Generator, modes: list[str],
                  anchors: NDArray[np.float64]) -> NDArray[np.float64]:
        """Net force per UAV for the given modes; ``anchors`` are the held UAVs' spring ends."""
        cfg = self.config
        grad, n_max = self._gradient(view.network).force(view.uav_xy_m, view.llr,
                                                         cfg.sensor_range_m, rng)
        held = np.array([m in _HELD for m in modes])
        repellers = np.where(held[:, None], held[None, :], True)
        force = pauli_force(view.uav_xy_m, cfg.sigma, epsilon=cfg.epsilon, repellers=repellers)
        search = ~held
        if search.any():
            q = spring_force(view.uav_xy_m[search], view.network.coords[n_max[search]],
                             cfg.k_spring, cfg.sensor_range_m)
            force[search] += grad[search] + q
        if held.any():
            force[held] += spring_force(view.uav_xy_m[held], anchors[held], cfg.k_loiter)
        return force

    def guide(self, view: GuidanceView, rng: np.random.Generator) -> Guidance:
        """The step's forces from the modes of :meth:`_modes`, holding over tracker peaks."""
        if not isinstance(view, GuidanceView):
            raise InvalidInputError("view", view, "must be a GuidanceView")
        pairing = pair_uavs(view.network, view.uav_xy_m, view.bank)
        modes = self._modes(view, pairing)
        anchors = _peak_anchors(view, pairing)
        force = self._assemble(view, rng, modes, anchors)
        return Guidance(force, pairing, tuple(modes), ((),) * view.n_uavs, 0.0)


def _peak_anchors(view: GuidanceView, pairing: Pairing) -> NDArray[np.float64]:
    anchors = np.array(view.uav_xy_m, copy=True)
    for j, node in enumerate(pairing.peak_node):
        if node >= 0:
            anchors[j] = view.network.coords[node]
    return anchors


class Search(_Potential):
    """Every UAV searches, ∇R + ∇P + ∇Q (5.12); trackers are paired but ignored (experiment 1)."""

    name = "search"


class Loiter(_Potential):
    """Paired UAVs loiter over their tracker's peak, the rest search (5.15)."""

    name = "loiter"

    def _modes(self, view: GuidanceView, pairing: Pairing) -> list[str]:
        return ["loiter" if t >= 0 else "search" for t in pairing.tracker]


class SearchAndLoiter(_Potential):
    """Paired UAVs loiter only while their tracker's peak is ≤ ``ϱ`` (5.16); no hysteresis."""

    name = "search_and_loiter"

    def _modes(self, view: GuidanceView, pairing: Pairing) -> list[str]:
        rho = self.config.revisit_threshold
        return ["loiter" if t >= 0 and p <= rho else "search"
                for t, p in zip(pairing.tracker, pairing.peak_probability, strict=True)]


@dataclass
class _Route:
    uav: int
    nodes: tuple[int, ...]
    served: NDArray[np.bool_]

    def remaining(self) -> tuple[int, ...]:
        return tuple(n for n, s in zip(self.nodes, self.served.tolist(), strict=True) if not s)


class SearchAndReacquire(SearchAndLoiter):
    """As (5.16), but a fading tracker's UAV flies an OPTW route over its likely nodes (5.33).

    When a paired UAV's peak is ≤ ``ϱ`` it plans a route once (:mod:`.reacquire`) and follows it
    with ∇W toward the next unserved node; a node is served once within ``ρ`` of the UAV. It
    re-plans when the route is exhausted or its tracker now has another UAV, and drops the route
    when the peak is back above ``ϱ`` (reacquired), the tracker is unpaired or dissolved. A UAV
    whose plan is empty loiters over the peak (mode ``"loiter"``) and re-plans next step.
    Routes are kept by ``track_id``.
    """

    name = "search_and_reacquire"

    def __init__(self, config: StrategyConfig, diffusion: GraphDiffusion) -> None:
        super().__init__(config, diffusion)
        self._routes: dict[int, _Route] = {}

    def reset(self) -> None:
        """Forget every route."""
        self._routes.clear()

    def _plan(self, view: GuidanceView, uav: int, tracker: int, rng: np.random.Generator,
              budget: Deadline, waiting: int) -> _Route:
        """Plan ``uav``'s route; the OPTW gets an equal share of what is left of the step's
        ``budget`` among the ``waiting`` plans still to make (this one included)."""
        cfg = self.config
        probability = view.bank[tracker].probability
        horizon = reacquire_time(self.diffusion, probability, p_min=cfg.p_min,
                                 max_steps=cfg.max_reacquire_steps)
        inst, node_ids = reacquisition_instance(
            view.network, probability, view.uav_xy_m[uav], cfg.speed_mps, horizon,
            max_nodes=cfg.max_route_nodes, support_mass=cfg.support_mass)
        seed = int(rng.integers(0, 2**31 - 1))
        nodes, result = plan_reacquisition(inst, node_ids, backend=cfg.optw_backend,
                                           time_limit_s=max(1e-3, budget.remaining() / waiting),
                                           seed=seed)
        log.debug("uav %d, track %d: T_r=%.1f s, %d candidates, %s route of %d nodes (%.3g)",
                  uav, view.bank[tracker].track_id, horizon, inst.n - 1, result.status.name,
                  len(nodes), result.objective or 0.0)
        return _Route(uav, nodes, np.zeros(len(nodes), dtype=bool))

    def guide(self, view: GuidanceView, rng: np.random.Generator) -> Guidance:
        """(5.33): search, or follow (planning if needed) a reacquisition route."""
        if not isinstance(view, GuidanceView):
            raise InvalidInputError("view", view, "must be a GuidanceView")
        pairing = pair_uavs(view.network, view.uav_xy_m, view.bank)
        modes = self._modes(view, pairing)
        anchors = _peak_anchors(view, pairing)
        routes: list[tuple[int, ...]] = [()] * view.n_uavs
        fading = {pairing.track_id[j]: j for j, m in enumerate(modes) if m == "loiter"}
        for track in [t for t in self._routes if t not in fading]:
            del self._routes[track]  # reacquired, unpaired or dissolved
        rho = self.config.sensor_range_m
        stale: list[tuple[int, int]] = []
        for track, j in fading.items():
            route = self._routes.get(track)
            if route is not None and route.uav == j:
                _serve(route, view, rho)
            if route is None or route.uav != j or route.served.all():
                stale.append((track, j))
        budget = Deadline(self.config.optw_budget_s)  # one budget per step, shared
        for k, (track, j) in enumerate(stale):
            route = self._plan(view, j, pairing.tracker[j], rng, budget, len(stale) - k)
            _serve(route, view, rho)
            self._routes[track] = route
        plan_s = budget.elapsed() if stale else 0.0
        for track, j in fading.items():
            route = self._routes[track]
            left = route.remaining()
            if left:
                modes[j] = "reacquire"
                anchors[j] = view.network.coords[left[0]]
                routes[j] = left
        force = self._assemble(view, rng, modes, anchors)
        return Guidance(force, pairing, tuple(modes), tuple(routes), 1000.0 * plan_s)


def _serve(route: _Route, view: GuidanceView, radius_m: float) -> None:
    """Mark the route nodes within ``radius_m`` of the route's UAV as served."""
    if not route.nodes:
        return
    d = view.network.coords[list(route.nodes)] - view.uav_xy_m[route.uav]
    route.served |= np.hypot(d[:, 0], d[:, 1]) <= radius_m


StrategyFactory = Callable[[StrategyConfig, GraphDiffusion], Strategy]

#: The strategies by name: ``STRATEGIES[name](config, tracker_diffusion)``.
STRATEGIES: dict[str, StrategyFactory] = {
    Search.name: Search,
    Loiter.name: Loiter,
    SearchAndLoiter.name: SearchAndLoiter,
    SearchAndReacquire.name: SearchAndReacquire,
}
