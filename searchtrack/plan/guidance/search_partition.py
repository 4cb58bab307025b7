"""Splitting the search among the searching UAVs and valuing time in a search route's prize (a
strategy of this library beside the thesis's gradient search, thesis 001 Ch. 5).

The route strategies of :mod:`~searchtrack.plan.guidance.route_strategies` let each searching
UAV plan alone over the whole search field, leaving out only the cells of the other UAVs'
routes: two UAVs may each take half of two distant patches, and a route's OPTW values a cell
collected at the end of the look-ahead as much as one collected at once. The partitioned
route strategies change both:

- **partition** (:func:`balanced_partition`): the cells holding unexplored mass are split
  among the searching UAVs by a power diagram (a weighted Voronoi diagram) of the UAVs'
  positions, ``owner(c) = argmin_j ‖x_c − u_j‖² − w_j``, whose weights ``w_j`` are adjusted
  until each UAV owns as nearly as it can an equal share of the mass (a UAV left among
  searched road is handed unexplored road farther off; one in the middle of unexplored road
  gives some away).
  It is recomputed whenever a UAV plans, from where the searching UAVs are then; a UAV's
  OPTW (:func:`~searchtrack.plan.guidance.search_routes.search_instance`'s ``keep``) sees only
  the cells it owns;
- **latency** (:func:`discounted_prize`): a cell's prize is its mass discounted by the
  earliest time the UAV can reach it, ``m / (1 + t/τ)`` with ``t`` the straight-line flight
  time at ``S_max`` and ``τ`` the discount time: dense road near the UAV is worth more than
  equally dense road at the end of the look-ahead, so a route takes what is near first and
  the UAVs sweep their regions instead of crossing them. The OPTW's prizes stay constant per
  vertex (the family's problem); the discount is fixed when the instance is built.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.checks import count, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray


def discounted_prize(mass: ArrayLike, arrival_s: ArrayLike, discount_s: float) -> FloatArray:
    """Per cell ``mass / (1 + arrival_s/τ)`` with ``τ`` = ``discount_s`` (> 0): the prize of
    a cell the UAV reaches at the earliest at ``arrival_s`` (≥ 0)."""
    m = np.asarray(mass, dtype=np.float64)
    t = np.asarray(arrival_s, dtype=np.float64)
    if m.shape != t.shape:
        raise InvalidInputError("arrival_s", arrival_s, f"must have the shape {m.shape} of mass")
    if not (np.all(np.isfinite(m)) and np.all(m >= 0.0)):
        raise InvalidInputError("mass", mass, "must be finite and ≥ 0")
    if not (np.all(np.isfinite(t)) and np.all(t >= 0.0)):
        raise InvalidInputError("arrival_s", arrival_s, "must be finite and ≥ 0 (s)")
    tau = positive("discount_s", discount_s)
    return np.asarray(m / (1.0 + t / tau), dtype=np.float64)


def balanced_partition(points_xy: ArrayLike, mass: ArrayLike, sites_xy: ArrayLike, *,
                       rounds: int = 40) -> IntArray:
    """Per point, the index of the site that owns it: the power diagram of ``sites_xy``
    whose weights balance the ``mass`` the sites own (module docstring).

    The weights start at 0 (the plain Voronoi diagram, nearest site, lowest index on ties);
    each of ``rounds`` rounds raises the weight of a site owning less than the mean share and
    lowers that of one owning more, by a step (m²) that shrinks from the squared span of the
    points and sites. The most balanced diagram met (smallest largest share) is returned.
    Deterministic.
    """
    pts = np.asarray(points_xy, dtype=np.float64)
    sites = np.asarray(sites_xy, dtype=np.float64)
    w = np.asarray(mass, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1:] != (2,) or not np.all(np.isfinite(pts)):
        raise InvalidInputError("points_xy", points_xy, "must be finite points of shape (k, 2)")
    if sites.ndim != 2 or sites.shape[1:] != (2,) or sites.shape[0] < 1 \
            or not np.all(np.isfinite(sites)):
        raise InvalidInputError("sites_xy", sites_xy, "must be ≥ 1 finite points (s, 2)")
    if w.shape != (pts.shape[0],) or not np.all(np.isfinite(w)) or np.any(w < 0.0):
        raise InvalidInputError("mass", mass, f"must be finite and ≥ 0, shape ({pts.shape[0]},)")
    n_rounds = count("rounds", rounds)
    s = sites.shape[0]
    dist = ((pts[:, None, 0] - sites[None, :, 0]) ** 2
            + (pts[:, None, 1] - sites[None, :, 1]) ** 2)
    owner = np.argmin(dist, axis=1).astype(np.int64) if pts.shape[0] else np.zeros(0, np.int64)
    total = float(w.sum())
    if s == 1 or pts.shape[0] == 0 or total <= 0.0:
        return owner
    both = np.vstack([pts, sites])
    step = 0.5 * math.hypot(*(both.max(axis=0) - both.min(axis=0))) ** 2
    weight = np.zeros(s)
    share = total / s
    best, best_top = owner, float(np.bincount(owner, weights=w, minlength=s).max())
    for _ in range(n_rounds):
        got = np.bincount(owner, weights=w, minlength=s)
        weight += step * (share - got) / total
        step *= 0.85
        owner = np.argmin(dist - weight[None, :], axis=1).astype(np.int64)
        top = float(np.bincount(owner, weights=w, minlength=s).max())
        if top < best_top:
            best, best_top = owner, top
    return best
