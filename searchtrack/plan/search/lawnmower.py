"""Lawnmower (boustrophedon) coverage baselines: 2-D at a fixed altitude and 3-D in layers.

Paper 003 flies a fixed-altitude lawnmower with the robots spaced evenly along it; paper 004
stacks 2-D boustrophedon layers 48 m apart with 48 m line spacing. Neither paper gives the start
corner or the ordering: here lines run along x, start at the low corner, and the path is sampled
every ``step_m`` metres so it can be flown one waypoint per step. :func:`solve_lawnmower` is the
search backend that follows the 3-D pattern (a coverage pattern, not an optimiser: ``FEASIBLE``).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from searchtrack.core.checks import positive
from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.intervals import interval_count
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray
from searchtrack.plan.search.problem import SearchPlan, SearchProblem


def _box(bounds: FloatArray, dims: int) -> FloatArray:
    b = np.asarray(bounds, dtype=np.float64)
    if b.shape != (dims, 2) or not np.all(np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
        raise InvalidInputError("bounds", bounds, f"must be ({dims}, 2) with lo < hi")
    return b


def _levels(lo: float, hi: float, spacing: float) -> FloatArray:
    """Track positions ``spacing`` apart, half a spacing in from each edge, covering [lo, hi]."""
    n = interval_count(hi - lo, spacing)
    return lo + (np.arange(n) + 0.5) * (hi - lo) / n


def _sample(corners: FloatArray, step_m: float) -> FloatArray:
    """Points every ``step_m`` along the polyline ``corners`` (each corner included)."""
    out = [corners[:1]]
    for a, b in itertools.pairwise(corners):
        length = float(np.linalg.norm(b - a))
        n = interval_count(length, step_m)
        t = np.arange(1, n + 1)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out)


def lawnmower_2d(bounds: FloatArray, spacing_m: float, altitude_m: float,
                 step_m: float) -> FloatArray:
    """``(K, 3)`` waypoints of a boustrophedon over ``bounds`` ``[[x0, x1], [y0, y1]]``: lines
    along x at ``spacing_m`` apart (every point of the box within ``spacing_m / 2`` of a line),
    at ``altitude_m``, sampled every ``step_m`` (at most) along the path."""
    b = _box(bounds, 2)
    for name, v in (("spacing_m", spacing_m), ("step_m", step_m)):
        positive(name, v)
    if not math.isfinite(altitude_m):
        raise InvalidInputError("altitude_m", altitude_m, "must be finite")
    corners = []
    for i, y in enumerate(_levels(b[1, 0], b[1, 1], spacing_m)):
        xs = (b[0, 0], b[0, 1]) if i % 2 == 0 else (b[0, 1], b[0, 0])
        corners += [(xs[0], y), (xs[1], y)]
    path = _sample(np.array(corners), step_m)
    return np.concatenate([path, np.full((len(path), 1), float(altitude_m))], axis=1)


def lawnmower_3d(bounds: FloatArray, spacing_m: float, layer_spacing_m: float,
                 step_m: float) -> FloatArray:
    """``(K, 3)`` waypoints of stacked 2-D boustrophedons (004's 3-D lawnmower): layers
    ``layer_spacing_m`` apart in z, alternately reversed so consecutive layers join at a corner,
    with vertical transitions sampled like the rest of the path."""
    b = _box(bounds, 3)
    positive("layer_spacing_m", layer_spacing_m)
    layers = []
    for k, z in enumerate(_levels(b[2, 0], b[2, 1], layer_spacing_m)):
        layer = lawnmower_2d(b[:2], spacing_m, float(z), step_m)
        layers.append(layer if k % 2 == 0 else layer[::-1])
    corners = [layers[0]]
    for prev, nxt in itertools.pairwise(layers):
        link = _sample(np.stack([prev[-1], nxt[0]]), step_m)[1:-1]
        corners += [link, nxt]
    return np.concatenate(corners)


def lawnmower_supports(problem: SearchProblem) -> str | None:
    """``None`` when the box has a positive extent on every axis the pattern sweeps."""
    axes = problem.settings.dims
    if np.any(problem.bounds[:axes, 1] <= problem.bounds[:axes, 0]):
        return "the lawnmower needs a box with lo < hi on every swept axis"
    return None


def solve_lawnmower(problem: SearchProblem, *, time_limit_s: float = 10.0,
                    seed: int = 0) -> Result[SearchPlan]:
    """The next ``τ`` waypoints of the lawnmower over the problem's box after the waypoint
    nearest the UAV (the first on ties; the last waypoint repeats at the end of the pattern).

    3-D settings follow :func:`lawnmower_3d` (lines and layers ``lawnmower_spacing_m`` apart),
    2-D ones :func:`lawnmower_2d` at the UAV's altitude; both sampled every ``step_m``. FEASIBLE
    with the sequence's score ``α E + T`` (eq. 8) as objective, no bound. ``time_limit_s`` and
    ``seed`` are unused (closed form).
    """
    del seed
    deadline = Deadline(time_limit_s)
    s = problem.settings
    if s.dims == 3:
        route = lawnmower_3d(problem.bounds, s.lawnmower_spacing_m, s.lawnmower_spacing_m,
                             s.step_m)
    else:
        route = lawnmower_2d(problem.bounds[:2], s.lawnmower_spacing_m,
                             float(problem.position[2]), s.step_m)
    here = int(np.argmin(np.linalg.norm(route - problem.position, axis=1)))
    index = np.minimum(here + np.arange(1, s.horizon + 1), route.shape[0] - 1)
    sequence = route[index]
    ex, ref, score = problem.scores(sequence[None])
    plan = SearchPlan(sequence, float(ex[0]), float(ref[0]), float(score[0]), 1)
    return Result(Status.FEASIBLE, plan.score, None, deadline.elapsed(), "lawnmower", plan,
                  message=f"lawnmower: waypoint {here + 1} of {route.shape[0]}")
