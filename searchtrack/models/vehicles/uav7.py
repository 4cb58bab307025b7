"""The 7-state UAV of paper 004 eq. (12) (after Sun, Beard & Pack 2014), errata fixed.

State ``(X, Y, Z, V_a, β, γ, φ)`` in NED (Z down): position, airspeed, heading, flight-path angle,
roll. Input ``u = (u_Va, u_β, u_γ, u_φ)``. With ``ϑ = (V_a, β, γ, φ)``::

    q̇ = y(ϑ) + w,   y = V_a (cos β cos γ, sin β cos γ, −sin γ)
    ϑ̇ = f(ϑ) + δ̄(ϑ) u,
    f = (−D/m − g sin γ, 0, −(g/V_a) cos γ, 0)
    δ̄ = diag(1/m, L/(m V_a cos γ), (g/V_a) cos φ, 1)

Errata, each fixed here:

(i) ``y₂`` is printed ``V_a sin β sin γ``; it is ``V_a sin β cos γ`` (the printed form makes
    ``S_y = ∂y/∂ϑ`` singular at γ = 0). (ii) ``y`` is printed with the wind inside while (12) adds
    it again; ``y`` here is wind-free. (iii) The rows of ``f`` and ``δ̄`` are those of Beard's
    ``(V_a, γ, ψ)`` ordering: the printed row 2 (``−(g/V_a) cos γ``, ``(g/V_a) cos φ``) is the
    flight-path-angle equation and row 3 (``L/(m V_a cos γ)``) the heading equation; here they
    sit on the γ and β rows of the stated ``ϑ`` order. (iv) ``δ̄`` is printed 4×3 with ``u ∈ ℝ⁴``
    and ``φ̇ = sin φ`` (no input); here roll is driven by its own rate input, ``φ̇ = u_φ``, so
    ``δ̄`` is square and invertible away from ``V_a = 0``, ``cos γ = 0``, ``cos φ = 0`` (the state
    box keeps clear of them). (v) The paper's ``L = 0.7 N`` with ``m = 10 kg`` cannot hold the
    aircraft up; the default lift is the weight ``m g`` (so ``u_γ`` is the load factor and
    ``u_β`` a normalised turn command); pass ``lift_n=0.7`` for the printed value.
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
GRAVITY_MPS2 = 9.81


@dataclass(frozen=True)
class Uav7Dynamics:
    """Eq. (12) with the errata fixed; ``p = (w_n, w_e, w_d)`` (m/s). ``lift_n=None`` (the
    default) is the weight ``mass_kg · gravity_mps2``, whatever the mass."""

    mass_kg: float = 10.0
    gravity_mps2: float = GRAVITY_MPS2
    drag_n: float = 0.9
    lift_n: float | None = None

    @property
    def lift(self) -> float:
        """The lift ``L`` (N): ``lift_n``, or the weight ``m g`` when it is ``None``."""
        return self.mass_kg * self.gravity_mps2 if self.lift_n is None else self.lift_n

    def __call__(self, x: Any, u: Any, p: Any, ns: ArrayNamespace) -> Any:
        """``ẋ`` of the 7-state UAV."""
        va, beta, gamma, phi = x[3], x[4], x[5], x[6]
        cg, sg = ns.cos(gamma), ns.sin(gamma)
        m, g = self.mass_kg, self.gravity_mps2
        return ns.stack([
            va * ns.cos(beta) * cg + p[0],
            va * ns.sin(beta) * cg + p[1],
            -va * sg + p[2],
            -self.drag_n / m - g * sg + u[0] / m,
            self.lift / (m * va * cg) * u[1],
            g / va * (ns.cos(phi) * u[2] - cg),
            u[3],
        ])


def uav7(
    *,
    dynamics: Uav7Dynamics | None = None,
    airspeed_min_mps: float = 8.0,
    airspeed_max_mps: float = 25.0,
    flight_path_max_rad: float = 0.5,
    roll_max_rad: float = 0.8,
    thrust_min_n: float = -20.0,
    thrust_max_n: float = 40.0,
    turn_input_max: float = 1.0,
    load_factor_max: float = 2.0,
    roll_rate_max_rps: float = 1.0,
    altitude_band_m: tuple[float, float] = (-INF, INF),
) -> VehicleModel:
    """The 7-state UAV with box limits (A17(vi): the paper's gains need saturations).

    ``altitude_band_m`` bounds ``Z`` (NED, so ``(-260, 20)`` is 20 m below to 260 m above the
    origin). Input rates are limited to ten times the input range per second.

    Raises
    ------
    InvalidInputError
        Non-positive limits, inverted ranges, or level cruise out of reach (thrust range
        without the drag, ``load_factor_max < 1``).
    """
    dyn = Uav7Dynamics() if dynamics is None else dynamics
    for name in ("mass_kg", "gravity_mps2", "lift_n"):
        if getattr(dyn, name) is not None:
            checks.positive(name, getattr(dyn, name))
    checks.non_negative("drag_n", dyn.drag_n)
    va_lo = checks.positive("airspeed_min_mps", airspeed_min_mps)
    va_hi = checks.real("airspeed_max_mps", airspeed_max_mps, low=va_lo)
    gam = checks.real("flight_path_max_rad", flight_path_max_rad, low=0.0, high=1.4,
                       low_open=True)
    roll = checks.real("roll_max_rad", roll_max_rad, low=0.0, high=1.4, low_open=True)
    t_lo = checks.real("thrust_min_n", thrust_min_n)
    t_hi = checks.real("thrust_max_n", thrust_max_n, low=t_lo, low_open=True)
    turn = checks.positive("turn_input_max", turn_input_max)
    load = checks.real("load_factor_max", load_factor_max, low=1.0)  # level flight needs 1
    rate = checks.positive("roll_rate_max_rps", roll_rate_max_rps)
    z_lo, z_hi = (float(v) for v in altitude_band_m)
    if not z_lo < z_hi:
        raise InvalidInputError("altitude_band_m", altitude_band_m,
                                "must be (low, high) with low < high")
    cruise = dyn.drag_n
    if not t_lo <= cruise <= t_hi:
        raise InvalidInputError("thrust_max_n", (t_lo, t_hi),
                                "level cruise (thrust = drag) must be reachable")
    return VehicleModel(
        name="uav7",
        state_names=("north_m", "east_m", "down_m", "airspeed_mps", "heading_rad",
                     "flight_path_rad", "roll_rad"),
        input_names=("thrust_n", "turn_input", "load_factor", "roll_rate_rps"),
        dynamics=dyn,
        state_lower=(-INF, -INF, z_lo, va_lo, -INF, -gam, -roll),
        state_upper=(INF, INF, z_hi, va_hi, INF, gam, roll),
        input_lower=(t_lo, -turn, 0.0, -rate),
        input_upper=(t_hi, turn, load, rate),
        input_rate_max=(10.0 * (t_hi - t_lo), 20.0 * turn, 10.0 * load, 20.0 * rate),
        nominal_input=(cruise, 0.0, 1.0, 0.0),
        position_indices=(0, 1, 2),
        angle_indices=(4,),
    )
