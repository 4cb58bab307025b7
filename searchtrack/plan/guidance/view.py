"""What a guidance backend sees each step (:class:`GuidanceView`), what it answers
(:class:`Guidance`, with the :class:`Reacquisition` and
:class:`~searchtrack.plan.guidance.search_routes.SearchRoute` routes it keeps flying) and how it
is configured (:class:`StrategyConfig`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.checks import count, non_negative, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import BeliefBank, SearchField
from searchtrack.models.dubins import MPS_PER_MPH
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance.forces import default_loiter_k, default_spring_k
from searchtrack.plan.guidance.pairing import Pairing
from searchtrack.plan.guidance.reacquire import check_optw_iterations
from searchtrack.plan.guidance.search_routes import SearchRoute
from searchtrack.plan.optw.solve import BACKENDS

MODES = ("search", "loiter", "reacquire", "route")
ANCHORED_MODES = ("loiter", "reacquire", "route")
"""The modes whose UAVs a zero-rest spring pulls to an anchor (∇L, ∇W): a tracker's peak or a
route's next node. Only the searching UAVs climb the gradient."""
STEERINGS: tuple[str, ...] = ("turn_back", "thesis")
"""How the guidance force turns the UAVs: ``"turn_back"`` (this library's) steers the anchored
UAVs with :mod:`searchtrack.models.dubins`'s turning back, so one that overflies its anchor
turns back at once, and the searching UAVs by (5.3); ``"thesis"`` steers every UAV by (5.3)."""


#: The settings of the route strategies' search OPTW, as :class:`StrategyConfig` names them.
SEARCH_SETTINGS = ("search_iterations", "search_horizon_s", "search_replan_s",
                   "search_route_nodes", "search_cell_m", "search_serve_m")


def whole_count(name: str, value: object) -> int:
    """``value`` if it is an integer ≥ 1 (not a bool), else :class:`InvalidInputError`."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InvalidInputError(name, value, "must be an integer ≥ 1")
    return value


def check_search_settings(spec: object) -> None:
    """Check the search settings of ``spec`` (a :class:`StrategyConfig` or a guidance spec):
    counts ≥ 1, times and cell side > 0, serve distance ≥ 0 (``None``: derived from ``ρ``)."""
    for name in ("search_iterations", "search_route_nodes"):
        whole_count(name, getattr(spec, name))
    for name in ("search_horizon_s", "search_replan_s"):
        positive(name, getattr(spec, name))
    for name, check in (("search_cell_m", positive), ("search_serve_m", non_negative),
                        ("search_discount_s", positive)):
        value = getattr(spec, name, None)
        if value is not None:
            check(name, value)


@dataclass(frozen=True)
class StrategyConfig:
    """Parameters of the Ch. 5 guidance laws (defaults: Tables 6.2 and 6.4).

    ``α`` and ``Δt`` are those of the tracker predictor of the
    :class:`~searchtrack.plan.guidance.problem.GuidanceProblem`.

    Parameters
    ----------
    sensor_range_m
        Footprint radius ``ρ`` (120 m).
    sigma_m
        Pauli ``σ``; ``None`` means ``2ρ``.
    epsilon
        Pauli ``ε`` (1).
    spring_k
        ``K`` of ∇Q; ``None`` means :func:`~searchtrack.plan.guidance.forces.default_spring_k`.
    loiter_k
        ``K`` of ∇L and ∇W; ``None`` means
        :func:`~searchtrack.plan.guidance.forces.default_loiter_k`.
    revisit_threshold
        ``ϱ`` (0.3): a paired UAV searches while its tracker's peak exceeds it.
    p_min
        ``P_min`` (0.07), the dissolve threshold that ends ``T_r``.
    speed_mps
        ``S_max`` (80 mph), the OPTW travel speed.
    optw_backend
        Backend of the reacquisition OPTW. Its planning budget is the guidance solve's
        ``time_limit_s``: the UAVs that re-plan in the same step share it (``T_r`` simulation
        and instance building included, each OPTW solve gets an equal share of what is left,
        at least 1 ms).
    optw_iterations
        With ``optw_backend = "ils"``, a cap on the ruin-and-recreate iterations of each
        reacquisition OPTW, so that the route does not depend on the machine's speed (the solve
        still stops at its share of the budget); ``None`` (default): the share of the budget
        alone. Only the ILS counts iterations, so another backend with a cap is an error.
    max_route_nodes, support_mass
        Candidate truncation of the OPTW (see
        :func:`~searchtrack.plan.guidance.reacquire.candidate_nodes`).
    max_reacquire_steps
        Cap on the prediction steps simulated for ``T_r``.
    coverage_weight
        Weight ``w ≥ 0`` of the coverage force added to every free UAV (searching, paired with
        no tracker) when the view carries a coverage field: ``w`` times
        :func:`~searchtrack.plan.guidance.forces.coverage_force` over the ring ``ρ < r ≤ 2ρ``
        (the road a UAV could cover next). 0 (default): the thesis's forces, unchanged.
    search_iterations
        Ruin-and-recreate iterations of the iterated local search that solves the route
        strategies' search OPTW (:mod:`~searchtrack.plan.guidance.search_routes`): a fixed
        count, so that the route does not depend on the machine's speed (a few milliseconds
        for the default instance, within 1 % of the optimum); the solve also stops at its share
        of the step's budget, as ``optw_backend``'s do.
    search_horizon_s
        Look-ahead of the search OPTW (s): its time budget, the longest flight time of a
        route.
    search_replan_s
        A search route this old (s) is planned again even if its first node is not reached.
    search_route_nodes
        Most candidate cells of the search OPTW.
    search_cell_m
        Side of the search OPTW's cells (m); ``None`` means ``√2 ρ``.
    search_serve_m
        A search route's first node counts as reached within this distance (m); ``None``
        means ``ρ/2``.
    search_discount_s
        Discount time ``τ`` (s) of the partitioned route strategies' prizes ``m / (1 + t/τ)``.
    """

    sensor_range_m: float = 120.0
    sigma_m: float | None = None
    epsilon: float = 1.0
    spring_k: float | None = None
    loiter_k: float | None = None
    revisit_threshold: float = 0.3
    p_min: float = 0.07
    speed_mps: float = 80.0 * MPS_PER_MPH
    optw_backend: str = "auto"
    optw_iterations: int | None = None
    max_route_nodes: int = 60
    support_mass: float = 0.95
    max_reacquire_steps: int = 2000
    coverage_weight: float = 0.0
    search_iterations: int = 500
    search_horizon_s: float = 45.0
    search_replan_s: float = 10.0
    search_route_nodes: int = 30
    search_cell_m: float | None = None
    search_serve_m: float | None = None
    search_discount_s: float = 15.0

    def __post_init__(self) -> None:
        rho = positive("sensor_range_m", self.sensor_range_m)
        set_ = object.__setattr__
        set_(self, "sigma_m", 2.0 * rho if self.sigma_m is None
             else positive("sigma_m", self.sigma_m))
        positive("epsilon", self.epsilon)
        speed = positive("speed_mps", self.speed_mps)
        set_(self, "spring_k", default_spring_k(rho) if self.spring_k is None
             else positive("spring_k", self.spring_k))
        set_(self, "loiter_k", default_loiter_k(rho, speed) if self.loiter_k is None
             else positive("loiter_k", self.loiter_k))
        for name in ("revisit_threshold", "p_min", "support_mass"):
            v = positive(name, getattr(self, name))
            if v > 1.0 or (v == 1.0 and name != "support_mass"):
                raise InvalidInputError(name, getattr(self, name), "must be in (0, 1)")
        check_optw_iterations(self.optw_backend, self.optw_iterations)
        if self.p_min >= self.revisit_threshold:
            raise InvalidInputError("p_min", self.p_min, "must be below revisit_threshold")
        if self.optw_backend not in BACKENDS.names():
            raise InvalidInputError("optw_backend", self.optw_backend,
                                    f"must be one of {sorted(BACKENDS.names())}")
        for name in ("max_route_nodes", "max_reacquire_steps"):
            whole_count(name, getattr(self, name))
        set_(self, "coverage_weight", non_negative("coverage_weight", self.coverage_weight))
        check_search_settings(self)
        if self.search_cell_m is None:
            set_(self, "search_cell_m", math.sqrt(2.0) * rho)
        if self.search_serve_m is None:
            set_(self, "search_serve_m", 0.5 * rho)

    @property
    def sigma(self) -> float:
        """``σ`` resolved (m)."""
        return float(self.sigma_m) if self.sigma_m is not None else 2.0 * self.sensor_range_m

    @property
    def k_spring(self) -> float:
        """``K`` of ∇Q, resolved."""
        return float(self.spring_k) if self.spring_k is not None else 0.0

    @property
    def k_loiter(self) -> float:
        """``K`` of ∇L and ∇W, resolved."""
        return float(self.loiter_k) if self.loiter_k is not None else 0.0

    @property
    def cell_m(self) -> float:
        """Side of the search OPTW's cells, resolved (m)."""
        return float(self.search_cell_m) if self.search_cell_m is not None else 0.0

    @property
    def serve_m(self) -> float:
        """A search route's serving radius, resolved (m)."""
        return float(self.search_serve_m) if self.search_serve_m is not None else 0.0


def _vector(name: str, value: object, shape: tuple[int, ...]) -> NDArray[np.float64]:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise InvalidInputError(name, value, f"must be finite of shape {shape}")
    return a


@dataclass(frozen=True, eq=False)
class GuidanceView:
    """What a guidance backend sees each step (validated: shapes agree with the UAV count and
    map).

    Parameters
    ----------
    network
        The road network.
    uav_xy_m, uav_heading_rad, uav_speed_mps
        ``(O, 2)`` positions, ``(O,)`` headings and speeds of the ``O ≥ 1`` UAVs.
    field
        The search field the gradient force climbs (5.6)–(5.7): any
        :class:`~searchtrack.estimate.belief.SearchField` on the network's nodes, e.g. the
        :class:`~searchtrack.estimate.lrt.LikelihoodField`.
    bank
        The live track beliefs: any :class:`~searchtrack.estimate.belief.BeliefBank` on the
        network's nodes, e.g. a :class:`~searchtrack.estimate.node_tracker.TrackerBank`.
    time_s
        Mission time (s).
    coverage
        ``(n,)`` how recently the fleet covered each road node, in ``[0, 1]`` (1: just now, 0:
        long ago or never), read by the coverage force
        (:attr:`StrategyConfig.coverage_weight`); ``None`` (default): not tracked.
    """

    network: RoadNetwork
    uav_xy_m: NDArray[np.float64]
    uav_heading_rad: NDArray[np.float64]
    uav_speed_mps: NDArray[np.float64]
    field: SearchField
    bank: BeliefBank
    time_s: float
    coverage: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        xy = np.asarray(self.uav_xy_m, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2 or xy.shape[0] < 1 or not np.all(np.isfinite(xy)):
            raise InvalidInputError("uav_xy_m", self.uav_xy_m, "must be finite, shape (O ≥ 1, 2)")
        o, n = xy.shape[0], self.network.n_nodes
        set_ = object.__setattr__
        set_(self, "uav_xy_m", xy)
        set_(self, "uav_heading_rad", _vector("uav_heading_rad", self.uav_heading_rad, (o,)))
        set_(self, "uav_speed_mps", _vector("uav_speed_mps", self.uav_speed_mps, (o,)))
        if not isinstance(self.field, SearchField) or self.field.n_nodes != n:
            raise InvalidInputError("field", self.field, f"must be a SearchField (n_nodes, "
                                    f"node_score), e.g. a LikelihoodField, on {n} nodes")
        if not isinstance(self.bank, BeliefBank) or self.bank.n_nodes != n:
            raise InvalidInputError("bank", self.bank, f"must be a BeliefBank (n_nodes, len, "
                                    f"[index] → TrackBelief), e.g. a TrackerBank, on {n} nodes")
        if not math.isfinite(self.time_s):
            raise InvalidInputError("time_s", self.time_s, "must be finite (s)")
        if self.coverage is not None:
            cov = np.asarray(self.coverage, dtype=np.float64)
            if cov.shape != (n,) or not np.all((cov >= 0.0) & (cov <= 1.0)):
                raise InvalidInputError("coverage", self.coverage,
                                        f"must be ({n},) values in [0, 1]")
            set_(self, "coverage", cov)

    @property
    def n_uavs(self) -> int:
        """Number of UAVs ``O``."""
        return int(self.uav_xy_m.shape[0])


@dataclass(frozen=True)
class Reacquisition:
    """A reacquisition route being flown (5.33): what search-and-reacquire keeps between steps.

    Parameters
    ----------
    track_id
        The fading tracker's ``track_id``.
    uav
        Index of the UAV flying the route.
    nodes
        The route's road nodes in visiting order (the start excluded); may be empty.
    served
        Per node, whether the UAV has come within ``ρ`` of it.
    """

    track_id: int
    uav: int
    nodes: tuple[int, ...]
    served: tuple[bool, ...]

    def __post_init__(self) -> None:
        track_id, uav = count("track_id", self.track_id), count("uav", self.uav)
        nodes = tuple(int(v) for v in self.nodes)
        served = tuple(bool(v) for v in self.served)
        if len(served) != len(nodes) or any(v < 0 for v in nodes):
            raise InvalidInputError("served", self.served,
                                    f"must have one flag per node of {nodes} (indices ≥ 0)")
        set_ = object.__setattr__
        set_(self, "track_id", track_id)
        set_(self, "uav", uav)
        set_(self, "nodes", nodes)
        set_(self, "served", served)

    @classmethod
    def planned(cls, track_id: int, uav: int, nodes: tuple[int, ...]) -> Reacquisition:
        """A fresh route: nothing served yet."""
        return cls(track_id, uav, tuple(nodes), (False,) * len(nodes))

    def remaining(self) -> tuple[int, ...]:
        """The route nodes not served yet, in order."""
        return tuple(n for n, s in zip(self.nodes, self.served, strict=True) if not s)

    @property
    def done(self) -> bool:
        """True once every node is served (also for an empty route)."""
        return all(self.served)

    def serve(self, network: RoadNetwork, uav_xy_m: NDArray[np.float64],
              radius_m: float) -> Reacquisition:
        """The route with the nodes within ``radius_m`` of the UAV at ``uav_xy_m[uav]`` served."""
        if not self.nodes:
            return self
        d = network.coords[list(self.nodes)] - uav_xy_m[self.uav]
        near = np.hypot(d[:, 0], d[:, 1]) <= radius_m
        served = tuple(bool(s) or bool(c) for s, c in zip(self.served, near, strict=True))
        return self if served == self.served else Reacquisition(self.track_id, self.uav,
                                                                 self.nodes, served)


@dataclass(frozen=True, eq=False)
class Guidance:
    """A guidance backend's answer for one step.

    Parameters
    ----------
    force
        The net ``(O, 2)`` force per UAV (input of
        :func:`~searchtrack.models.dubins.step_force`).
    pairing
        The UAV-to-tracker pairing of the step.
    mode
        Per UAV ``"search"``, ``"loiter"``, ``"reacquire"`` or ``"route"`` (searching along a
        planned :class:`~searchtrack.plan.guidance.search_routes.SearchRoute`).
    route
        Per UAV the remaining reacquisition route, or the search route, node ids (empty if
        none).
    plan_ms
        Time spent planning routes this step (``T_r``, the instance and the OPTW solve).
    reacquisitions
        The reacquisition routes to keep flying: pass them to the next step's problem
        (:meth:`~searchtrack.plan.guidance.problem.GuidanceProblem.following`). Empty for every
        backend but ``search_and_reacquire`` and ``route_search_and_reacquire``.
    search_routes
        The search routes to keep flying, at most one per UAV (the route strategies only).
    """

    force: NDArray[np.float64]
    pairing: Pairing
    mode: tuple[str, ...]
    route: tuple[tuple[int, ...], ...]
    plan_ms: float = 0.0
    reacquisitions: tuple[Reacquisition, ...] = ()
    search_routes: tuple[SearchRoute, ...] = ()

    def __post_init__(self) -> None:
        f = np.asarray(self.force, dtype=np.float64)
        if f.ndim != 2 or f.shape[1] != 2 or not np.all(np.isfinite(f)):
            raise InvalidInputError("force", self.force, "must be finite of shape (O, 2)")
        o = f.shape[0]
        if len(self.mode) != o or any(m not in MODES for m in self.mode):
            raise InvalidInputError("mode", self.mode, f"must be {o} of {MODES}")
        if len(self.route) != o or self.pairing.n_uavs != o:
            raise InvalidInputError("route", self.route, f"route and pairing need {o} UAVs")
        if not (math.isfinite(self.plan_ms) and self.plan_ms >= 0):
            raise InvalidInputError("plan_ms", self.plan_ms, "must be finite and ≥ 0")
        reacq = tuple(self.reacquisitions)
        if any(not isinstance(r, Reacquisition) or r.uav >= o for r in reacq):
            raise InvalidInputError("reacquisitions", self.reacquisitions,
                                    f"must be Reacquisitions of UAVs in [0, {o})")
        searched = tuple(self.search_routes)
        uavs = [r.uav for r in searched if isinstance(r, SearchRoute)]
        if len(uavs) != len(searched) or len(set(uavs)) != len(uavs) or any(u >= o for u in uavs):
            raise InvalidInputError("search_routes", self.search_routes,
                                    f"must be SearchRoutes of distinct UAVs in [0, {o})")
        object.__setattr__(self, "force", f)
        object.__setattr__(self, "reacquisitions", reacq)
        object.__setattr__(self, "search_routes", searched)

    def turn_back(self, steering: str) -> NDArray[np.bool_]:
        """Per UAV, whether ``steering`` (one of :data:`STEERINGS`) turns it back by the whole
        force when the force points behind it: the anchored UAVs with ``"turn_back"``, none
        with ``"thesis"`` (pass it to :func:`~searchtrack.models.dubins.step_force`)."""
        if steering not in STEERINGS:
            raise InvalidInputError("steering", steering, f"must be one of {STEERINGS}")
        on = steering == "turn_back"
        return np.array([on and m in ANCHORED_MODES for m in self.mode], dtype=bool)
