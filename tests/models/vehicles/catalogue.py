"""The three vehicle models, with random states and inputs inside their boxes and central
differences, shared by the vehicle tests."""

from __future__ import annotations

import math

import numpy as np

from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle

MODELS = {"unicycle": unicycle(), "fixed_wing": fixed_wing(), "uav7": uav7()}


def sample(model: VehicleModel, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random state in the state box (±50 where unbounded, angles in [−π, π]) and input."""
    lo = np.where(np.isfinite(model.state_lower), model.state_lower, -50.0)
    hi = np.where(np.isfinite(model.state_upper), model.state_upper, 50.0)
    x = rng.uniform(lo, hi)
    for i in model.angle_indices:
        x[i] = rng.uniform(-math.pi, math.pi)
    u = rng.uniform(model.input_lower, model.input_upper)
    return x, u


def central_differences(fun: object, x: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """The Jacobian of ``fun`` at ``x`` by central differences of step ``eps``."""
    f0 = fun(x)  # type: ignore[operator]
    cols = []
    for i in range(x.size):
        d = np.zeros_like(x)
        d[i] = eps
        cols.append((fun(x + d) - fun(x - d)) / (2 * eps))  # type: ignore[operator]
    return np.column_stack(cols).reshape(np.size(f0), x.size)
