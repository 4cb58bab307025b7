"""Fixed-wing kinematic model of paper 003 §2.3: forward speed, yaw-rate and pitch-rate inputs.

``ẋ = v cos θ cos ψ + w_x``, ``ẏ = v cos θ sin ψ + w_y``, ``ż = v sin θ + w_z``, ``ψ̇ = u_ψ``,
``θ̇ = u_θ``: states ``(x, y, z, ψ, θ)`` (z up), inputs ``(v, u_ψ, u_θ)``. The pitch is bounded
away from ±90° and the altitude to ``[z_min, z_max]`` (003 uses a 50 m ceiling).
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
class FixedWingDynamics:
    """003 §2.3 kinematics with an additive wind ``p = (w_x, w_y, w_z)``."""

    def __call__(self, x: Any, u: Any, p: Any, ns: ArrayNamespace) -> Any:
        """``ẋ`` of the fixed-wing kinematic model."""
        psi, theta, v = x[3], x[4], u[0]
        horizontal = v * ns.cos(theta)
        return ns.stack([horizontal * ns.cos(psi) + p[0], horizontal * ns.sin(psi) + p[1],
                         v * ns.sin(theta) + p[2], u[1], u[2]])


def fixed_wing(
    *,
    speed_min_mps: float = 8.0,
    speed_max_mps: float = 16.0,
    yaw_rate_max_rps: float = 0.8,
    pitch_rate_max_rps: float = 0.5,
    pitch_max_rad: float = math.radians(25.0),
    altitude_min_m: float = 0.0,
    altitude_max_m: float = 50.0,
    accel_max_mps2: float = 4.0,
    angular_accel_max_rps2: float = 3.0,
) -> VehicleModel:
    """The fixed-wing kinematic model with box limits; cruise is level flight at mid speed.

    Raises
    ------
    InvalidInputError
        Non-positive limits, inverted ranges or ``pitch_max_rad ≥ π/2``.
    """
    lo = checks.positive("speed_min_mps", speed_min_mps)
    hi = checks.positive("speed_max_mps", speed_max_mps)
    if lo > hi:
        raise InvalidInputError("speed_min_mps", speed_min_mps, f"must not exceed {hi!r}")
    z_lo = checks.real("altitude_min_m", altitude_min_m)
    z_hi = checks.real("altitude_max_m", altitude_max_m, low=z_lo, low_open=True)
    pitch = checks.real("pitch_max_rad", pitch_max_rad, low=0.0, high=0.5 * math.pi,
                         low_open=True, high_open=True)
    r_yaw = checks.positive("yaw_rate_max_rps", yaw_rate_max_rps)
    r_pitch = checks.positive("pitch_rate_max_rps", pitch_rate_max_rps)
    ang = checks.positive("angular_accel_max_rps2", angular_accel_max_rps2)
    return VehicleModel(
        name="fixed_wing",
        state_names=("x_m", "y_m", "z_m", "yaw_rad", "pitch_rad"),
        input_names=("speed_mps", "yaw_rate_rps", "pitch_rate_rps"),
        dynamics=FixedWingDynamics(),
        state_lower=(-INF, -INF, z_lo, -INF, -pitch),
        state_upper=(INF, INF, z_hi, INF, pitch),
        input_lower=(lo, -r_yaw, -r_pitch),
        input_upper=(hi, r_yaw, r_pitch),
        input_rate_max=(checks.positive("accel_max_mps2", accel_max_mps2), ang, ang),
        nominal_input=(0.5 * (lo + hi), 0.0, 0.0),
        position_indices=(0, 1, 2),
        angle_indices=(3,),
    )
