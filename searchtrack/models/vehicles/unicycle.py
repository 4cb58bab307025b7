"""Unicycle / Dubins car (thesis 001 §5.1, eq. 5.1) with speed and turn-rate inputs and wind.

``ẋ = v cos θ + w_x``, ``ẏ = v sin θ + w_y``, ``θ̇ = ω``: states ``(x, y, θ)``, inputs
``(v, ω)``. A Dubins car is the case ``v_min = v_max``. :class:`UnicycleDynamics` is the one
implementation of these kinematics: the potential-field UAV of :mod:`searchtrack.models.dubins`
integrates it too, and :func:`searchtrack.models.dubins.unicycle_from_limits` builds this model
from that UAV's limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles.model import VehicleModel
from searchtrack.models.vehicles.namespace import ArrayNamespace

INF = math.inf


@dataclass(frozen=True)
class UnicycleDynamics:
    """(5.1) with an additive wind ``p = (w_x, w_y)``."""

    def __call__(self, x: Any, u: Any, p: Any, ns: ArrayNamespace) -> Any:
        """``ẋ`` of the unicycle."""
        th = x[2]
        return ns.stack([u[0] * ns.cos(th) + p[0], u[0] * ns.sin(th) + p[1], u[1]])


def unicycle(
    *,
    speed_min_mps: float = 5.0,
    speed_max_mps: float = 15.0,
    turn_rate_max_rps: float = 1.0,
    accel_max_mps2: float = 5.0,
    turn_accel_max_rps2: float = 4.0,
    cruise_speed_mps: float | None = None,
) -> VehicleModel:
    """A unicycle with ``v ∈ [v_min, v_max]``, ``|ω| ≤ ω_max`` and input-rate limits.

    Raises
    ------
    InvalidInputError
        Non-positive limits, ``v_min > v_max`` or a cruise speed outside ``[v_min, v_max]``.
    """
    lo = checks.non_negative("speed_min_mps", speed_min_mps)
    hi = checks.positive("speed_max_mps", speed_max_mps)
    if lo > hi:
        raise InvalidInputError("speed_min_mps", speed_min_mps, f"must not exceed {hi!r}")
    w = checks.positive("turn_rate_max_rps", turn_rate_max_rps)
    cruise = 0.5 * (lo + hi) if cruise_speed_mps is None else checks.real(
        "cruise_speed_mps", cruise_speed_mps, low=lo, high=hi)
    return VehicleModel(
        name="unicycle",
        state_names=("x_m", "y_m", "heading_rad"),
        input_names=("speed_mps", "turn_rate_rps"),
        dynamics=UnicycleDynamics(),
        state_lower=(-INF, -INF, -INF),
        state_upper=(INF, INF, INF),
        input_lower=(lo, -w),
        input_upper=(hi, w),
        input_rate_max=(checks.positive("accel_max_mps2", accel_max_mps2),
                        checks.positive("turn_accel_max_rps2", turn_accel_max_rps2)),
        nominal_input=(cruise, 0.0),
        position_indices=(0, 1),
        angle_indices=(2,),
    )

