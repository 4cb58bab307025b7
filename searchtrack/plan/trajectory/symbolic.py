"""CasADi versions of the vehicle models: the namespace, the RK4 step and its Jacobians.

The models layer writes dynamics against an array namespace and imports no CasADi; this module
supplies :data:`CASADI` and builds (and caches) ``casadi.Function`` objects from a model.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import casadi as ca

from searchtrack.models.vehicles import VehicleModel, rk4_step


class CasadiNamespace:
    """:class:`~searchtrack.models.vehicles.ArrayNamespace` over CasADi symbols."""

    def sin(self, x: Any) -> Any:
        """Symbolic sine."""
        return ca.sin(x)

    def cos(self, x: Any) -> Any:
        """Symbolic cosine."""
        return ca.cos(x)

    def stack(self, rows: Sequence[Any]) -> Any:
        """Rows stacked into a column."""
        return ca.vertcat(*rows)


CASADI = CasadiNamespace()


def symbols(model: VehicleModel) -> tuple[Any, Any, Any, Any]:
    """Fresh ``SX`` symbols ``(x, u, p, dt)`` sized for ``model``."""
    return (ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu), ca.SX.sym("p", model.n_wind),
            ca.SX.sym("dt"))


@lru_cache(maxsize=32)
def step_function(model: VehicleModel) -> ca.Function:
    """``F(x, u, p, dt) -> x⁺``: one RK4 step (the model's own :func:`rk4_step`)."""
    x, u, p, dt = symbols(model)
    nxt = rk4_step(model.dynamics, x, u, p, dt, CASADI)
    return ca.Function("F", [x, u, p, dt], [nxt], ["x", "u", "p", "dt"], ["x_next"])


@lru_cache(maxsize=32)
def step_jacobians(model: VehicleModel) -> ca.Function:
    """``J(x, u, p, dt) -> (x⁺, ∂x⁺/∂x, ∂x⁺/∂u)`` of the RK4 step."""
    x, u, p, dt = symbols(model)
    nxt = rk4_step(model.dynamics, x, u, p, dt, CASADI)
    return ca.Function("J", [x, u, p, dt], [nxt, ca.jacobian(nxt, x), ca.jacobian(nxt, u)],
                       ["x", "u", "p", "dt"], ["x_next", "A", "B"])


@lru_cache(maxsize=32)
def dynamics_jacobians(model: VehicleModel) -> ca.Function:
    """``(x, u, p) -> (∂f/∂x, ∂f/∂u)`` of the continuous dynamics."""
    x, u, p, _ = symbols(model)
    xdot = model.dynamics(x, u, p, CASADI)
    return ca.Function("Jf", [x, u, p], [ca.jacobian(xdot, x), ca.jacobian(xdot, u)],
                       ["x", "u", "p"], ["A", "B"])
