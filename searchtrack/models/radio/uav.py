"""The UAV of the radio-tag search and its action primitives (Nguyen et al., §IV-A, Table IV).

The UAV flies at a constant speed (20 m/s) with its heading rate bounded by ``π/3`` rad/s, from
``(0, 0)`` with heading ``π/4``. The paper does not list its action set; a primitive here
is a target heading ``θ + Δ``, ``Δ ∈ {−π + 2π i/N_θ : i = 0..N_θ−1}``: the UAV turns toward it
the shortest way at the maximum rate, then flies straight, with a pose every ``step_s`` over
one planning interval ``N_p``. Between two poses the UAV moves ``speed·step_s`` along the chord
of its constant-rate arc (the direction half-way through the turn of that step).

Primitives whose poses leave the area ``[0, W] × [0, H]`` are dropped (all are kept when every
one leaves). :func:`straight_sweep_heading` is the Experiment 2 baseline: back and forth along
the diagonal between ``(0, 0)`` and ``(W, H)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray

#: Most action primitives ``N_θ`` (one per degree).
MAX_HEADINGS = 360
#: Most poses ``N_p / step_s`` in one primitive.
MAX_STEPS_PER_PLAN = 1000


@dataclass(frozen=True)
class UavModel:
    """Kinematic limits, start pose and action set of the UAV (Table IV defaults).

    Parameters
    ----------
    speed_mps
        Constant ground speed (m/s).
    max_turn_rate
        Largest heading rate (rad/s).
    start_xy, start_heading
        Initial position (m) and heading (rad).
    n_headings
        Number ``N_θ`` of action primitives.
    plan_interval_s
        Duration ``N_p`` of one primitive (s).
    step_s
        Time between poses (s), the measurement interval ``T0``.
    """

    speed_mps: float = 20.0
    max_turn_rate: float = math.pi / 3.0
    start_xy: tuple[float, float] = (0.0, 0.0)
    start_heading: float = math.pi / 4.0
    n_headings: int = 8
    plan_interval_s: float = 5.0
    step_s: float = 1.0

    def __post_init__(self) -> None:
        put = object.__setattr__
        for name in ("speed_mps", "max_turn_rate", "plan_interval_s", "step_s"):
            put(self, name, checks.positive(name, getattr(self, name)))
        xy = checks.finite_array("start_xy", self.start_xy, (2,))  # type: ignore[arg-type]
        put(self, "start_xy", (float(xy[0]), float(xy[1])))
        put(self, "start_heading", checks.real("start_heading", self.start_heading))
        put(self, "n_headings", checks.count("n_headings", self.n_headings, least=1))
        if self.n_headings > MAX_HEADINGS:
            raise InvalidInputError("n_headings", self.n_headings,
                                    f"must be an integer in [1, {MAX_HEADINGS}]")
        steps = self.plan_interval_s / self.step_s
        if not 0.5 <= steps < MAX_STEPS_PER_PLAN + 0.5 or round(steps) < 1:
            raise InvalidInputError("plan_interval_s", self.plan_interval_s,
                                    f"must span 1 to {MAX_STEPS_PER_PLAN} steps of "
                                    f"{self.step_s:g} s")

    @property
    def start_pose(self) -> FloatArray:
        """``(3,)`` start pose ``(x, y, heading)``."""
        return np.array([*self.start_xy, self.start_heading], dtype=np.float64)

    @property
    def steps_per_plan(self) -> int:
        """Poses per primitive, ``round(N_p / step_s)``."""
        return round(self.plan_interval_s / self.step_s)


def _pose(value: ArrayLike) -> FloatArray:
    return checks.finite_array("pose", value, (3,))


def _area(value: ArrayLike) -> tuple[float, float]:
    arr = checks.finite_array("area_m", value, (2,))
    if np.any(arr <= 0.0):
        raise InvalidInputError("area_m", value, "must be two positive sizes (W, H) in m")
    return float(arr[0]), float(arr[1])


def _fly(model: UavModel, pose: FloatArray, targets: FloatArray, n: int) -> FloatArray:
    """``(A, n, 3)`` poses flying from ``pose`` toward each target heading."""
    return fly_toward(model, np.full(targets.shape, pose[0]), np.full(targets.shape, pose[1]),
                      np.full(targets.shape, pose[2]), targets, n)


def fly_toward(model: UavModel, x: FloatArray, y: FloatArray, heading: FloatArray,
               targets: FloatArray, n: int) -> FloatArray:
    """``(*S, n, 3)`` poses of ``n`` steps from the poses ``(x, y, heading)`` toward the target
    headings, element-wise over arrays of one shape ``S``: each step turns toward the target
    by at most ``ω_max Δt`` and flies ``v Δt`` along the chord of the turn."""
    max_turn = model.max_turn_rate * model.step_s
    length = model.speed_mps * model.step_s
    out = np.empty((*targets.shape, n, 3))
    for i in range(n):
        turn = np.clip(wrap_angle(targets - heading), -max_turn, max_turn)
        chord = heading + turn / 2.0
        x = x + length * np.cos(chord)
        y = y + length * np.sin(chord)
        heading = wrap_angle(heading + turn)
        out[..., i, 0], out[..., i, 1], out[..., i, 2] = x, y, heading
    return out


def fly_heading(model: UavModel, pose: ArrayLike, target_heading: float,
                duration_s: float) -> FloatArray:
    """Poses every ``step_s`` while turning toward ``target_heading`` at the maximum rate.

    Parameters
    ----------
    model
        The UAV.
    pose
        ``(3,)`` start pose ``(x, y, heading)``.
    target_heading
        Heading to turn to (rad), the shortest way; held once reached.
    duration_s
        Flight time (s); ``n = round(duration_s / step_s)`` poses.

    Returns
    -------
    ``(n, 3)`` poses after each step (the start pose excluded), headings in ``[−π, π)``.
    """
    start = _pose(pose)
    target = checks.real("target_heading", target_heading)
    n = round(checks.non_negative("duration_s", duration_s) / model.step_s)
    path: FloatArray = _fly(model, start, np.array([target]), n)[0]
    return path


def primitive_headings(model: UavModel, heading: float) -> FloatArray:
    """``(N_θ,)`` absolute target headings ``θ + Δ_i``, ``Δ_i = −π + 2π i / N_θ``."""
    theta = checks.real("heading", heading)
    deltas = -np.pi + 2.0 * np.pi * np.arange(model.n_headings) / model.n_headings
    return wrap_angle(theta + deltas)


#: When every primitive leaves the area, those ending within this distance (m) of the nearest
#: to it are kept.
OUTSIDE_TIE_M = 1.0


def primitives(model: UavModel, pose: ArrayLike,
               area_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The action primitives from ``pose`` that keep the UAV inside ``[0, W] × [0, H]``.

    Returns
    -------
    headings
        ``(A,)`` target headings of the kept primitives.
    paths
        ``(A, n, 3)`` their poses over one planning interval. When every primitive leaves the
        area (the UAV is outside it, or too close to its edge to turn back in time), those
        that end nearest to it are returned (within :data:`OUTSIDE_TIE_M`), so a UAV that had to
        leave flies back in.
    """
    start = _pose(pose)
    width, height = _area(area_m)
    headings = primitive_headings(model, float(start[2]))
    paths = _fly(model, start, headings, model.steps_per_plan)
    x, y = paths[..., 0], paths[..., 1]
    inside = np.all((x >= 0.0) & (x <= width) & (y >= 0.0) & (y <= height), axis=1)
    if not inside.any():
        out_x = np.maximum(0.0, np.maximum(-x[:, -1], x[:, -1] - width))
        out_y = np.maximum(0.0, np.maximum(-y[:, -1], y[:, -1] - height))
        outside = np.hypot(out_x, out_y)
        inside = outside <= outside.min() + OUTSIDE_TIE_M
    return headings[inside], paths[inside]


def straight_sweep_heading(model: UavModel, pose: ArrayLike, area_m: ArrayLike) -> float:
    """The heading of the straight-path baseline: to the ``(W, H)`` corner, back to ``(0, 0)``.

    The corner aimed at is read from the pose: ``(W, H)`` while the heading points along the
    diagonal outward (non-negative component along ``(W, H)``), ``(0, 0)`` otherwise. The UAV
    switches to the other corner once within ``speed·step_s`` of the one aimed at or past it
    along the diagonal.

    Returns
    -------
    The bearing (rad, in ``[−π, π)``) from the pose to the corner aimed at.
    """
    p = _pose(pose)
    width, height = _area(area_m)
    diagonal = np.array([width, height]) / math.hypot(width, height)
    outbound = math.cos(p[2]) * diagonal[0] + math.sin(p[2]) * diagonal[1] >= 0.0
    corners = (np.array([width, height]), np.zeros(2))
    aimed = corners[0] if outbound else corners[1]
    ahead = aimed - p[:2]
    direction = diagonal if outbound else -diagonal
    reached = math.hypot(*ahead) <= model.speed_mps * model.step_s
    if reached or float(ahead @ direction) < 0.0:
        aimed = corners[1] if outbound else corners[0]
        ahead = aimed - p[:2]
    return wrap_angle(math.atan2(ahead[1], ahead[0]))
