"""What a guidance strategy sees each step, what it answers, and how it is configured."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.models.dubins import MPS_PER_MPH
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance.forces import default_loiter_k, default_spring_k
from searchtrack.plan.guidance.pairing import Pairing
from searchtrack.plan.optw.solve import BACKENDS

MODES = ("search", "loiter", "reacquire")


def _positive(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(float(value)) and float(value) > 0.0):
        raise InvalidInputError(name, value, "must be a positive finite number")
    return float(value)


@dataclass(frozen=True)
class StrategyConfig:
    """Parameters of the Ch. 5 guidance laws (defaults: Tables 6.2 and 6.4).

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
    optw_backend, optw_budget_s
        Backend of the reacquisition OPTW, and the planning budget of one step: the UAVs that
        re-plan in the same step share it (T_r simulation and instance building included, each
        OPTW solve gets an equal share of what is left, at least 1 ms).
    max_route_nodes, support_mass
        Candidate truncation of the OPTW (see
        :func:`~searchtrack.plan.guidance.reacquire.candidate_nodes`).
    max_reacquire_steps
        Cap on the prediction steps simulated for ``T_r``.

    ``α`` and ``Δt`` are those of the tracker diffusion each strategy is built with.
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
    optw_budget_s: float = 0.03
    max_route_nodes: int = 60
    support_mass: float = 0.95
    max_reacquire_steps: int = 2000

    def __post_init__(self) -> None:
        rho = _positive("sensor_range_m", self.sensor_range_m)
        set_ = object.__setattr__
        set_(self, "sigma_m", 2.0 * rho if self.sigma_m is None
             else _positive("sigma_m", self.sigma_m))
        _positive("epsilon", self.epsilon)
        speed = _positive("speed_mps", self.speed_mps)
        set_(self, "spring_k", default_spring_k(rho) if self.spring_k is None
             else _positive("spring_k", self.spring_k))
        set_(self, "loiter_k", default_loiter_k(rho, speed) if self.loiter_k is None
             else _positive("loiter_k", self.loiter_k))
        for name in ("revisit_threshold", "p_min", "support_mass"):
            v = _positive(name, getattr(self, name))
            if v > 1.0 or (v == 1.0 and name != "support_mass"):
                raise InvalidInputError(name, getattr(self, name), "must be in (0, 1)")
        if self.p_min >= self.revisit_threshold:
            raise InvalidInputError("p_min", self.p_min, "must be below revisit_threshold")
        if self.optw_backend not in BACKENDS.names():
            raise InvalidInputError("optw_backend", self.optw_backend,
                                    f"must be one of {sorted(BACKENDS.names())}")
        _positive("optw_budget_s", self.optw_budget_s)
        for name in ("max_route_nodes", "max_reacquire_steps"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise InvalidInputError(name, v, "must be an integer ≥ 1")

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


def _vector(name: str, value: object, shape: tuple[int, ...]) -> NDArray[np.float64]:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise InvalidInputError(name, value, f"must be finite of shape {shape}")
    return a


@dataclass(frozen=True, eq=False)
class GuidanceView:
    """What a strategy sees each step (validated: shapes agree with the UAV count and map)."""

    network: RoadNetwork
    uav_xy_m: NDArray[np.float64]
    uav_heading_rad: NDArray[np.float64]
    uav_speed_mps: NDArray[np.float64]
    llr: NDArray[np.float64]
    bank: TrackerBank
    time_s: float

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
        set_(self, "llr", _vector("llr", self.llr, (n,)))
        if not isinstance(self.bank, TrackerBank) or self.bank.n_nodes != n:
            raise InvalidInputError("bank", self.bank, f"must be a TrackerBank on {n} nodes")
        if not math.isfinite(self.time_s):
            raise InvalidInputError("time_s", self.time_s, "must be finite (s)")

    @property
    def n_uavs(self) -> int:
        """Number of UAVs ``O``."""
        return int(self.uav_xy_m.shape[0])


@dataclass(frozen=True, eq=False)
class Guidance:
    """A strategy's answer for one step.

    ``force`` is the net ``(O, 2)`` force per UAV (input of
    :func:`~searchtrack.models.dubins.step_force`),
    ``mode`` per UAV is ``"search"``, ``"loiter"`` or ``"reacquire"``, ``route`` per UAV the
    remaining route node ids (empty if none), ``plan_ms`` the time spent planning routes this
    step (``T_r``, the instance and the OPTW solve).
    """

    force: NDArray[np.float64]
    pairing: Pairing
    mode: tuple[str, ...]
    route: tuple[tuple[int, ...], ...]
    plan_ms: float = 0.0

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
        object.__setattr__(self, "force", f)
