"""Multi-target metrics: OSPA and GOSPA between point sets, OSPA(2) between sets of tracks.

- OSPA (Schuhmacher, Vo & Vo 2008), order ``p``, cut-off ``c``, for ``|X| = m ≤ n = |Y|``::

      d(X, Y) = ( (1/n) [ min_π Σ_{i≤m} min(c, ‖x_i − y_π(i)‖)^p + c^p (n − m) ] )^{1/p}

  and 0 when both sets are empty. Its two components (Schuhmacher et al. 2008, §IV-C),
  ``d^p = loc^p + card^p`` with ``loc^p = (1/n) min_π Σ_{i≤m} min(c, ‖x_i − y_π(i)‖)^p`` and
  ``card^p = c^p (n − m) / n``, separate position error from a wrong number of targets
  (:func:`ospa_components`).
- GOSPA (Rahmathullah, García-Fernández & Svensson 2017), for ``m ≤ n``::

      d(X, Y) = ( min_π Σ_{i≤m} min(c, ‖x_i − y_π(i)‖)^p + (c^p / α)(n − m) )^{1/p}

  With ``α = 2`` (the default) this equals the assignment form: localisation errors of the
  assigned pairs plus ``c^p / 2`` per missed and per false target.
- OSPA(2) (Beard, Vo & Vo 2017, "OSPA(2): using the OSPA metric to evaluate multi-target tracking
  performance"): the distance between two tracks over a window is the time average, over the
  scans where either exists, of ``min(c, ‖x_t − y_t‖)`` when both exist and ``c`` when one does;
  OSPA(2) is OSPA of order ``p`` and cut-off ``c`` on the track sets with that base distance.

The optimal assignment is :func:`scipy.optimize.linear_sum_assignment`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def _set(name: str, points: ArrayLike, dim: int | None = None) -> FloatArray:
    arr = np.asarray(points, dtype=np.float64)
    if arr.size == 0:
        return np.empty((0, dim or 0))
    if arr.ndim == 1:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2 or (dim is not None and arr.shape[1] != dim):
        raise InvalidInputError(name, points, "must be a (k, dim) array of points")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, points, "must be finite")
    return arr


def _pair(x: ArrayLike, y: ArrayLike) -> tuple[FloatArray, FloatArray]:
    a = _set("x", x)
    b = _set("y", y, a.shape[1] if a.shape[0] else None)
    if a.shape[0] == 0 and b.shape[0]:
        a = a.reshape(0, b.shape[1])
    return a, b


def _params(c: float, p: float) -> tuple[float, float]:
    return checks.positive("c", c), checks.positive("p", p)


def _assigned_cost(cost: FloatArray) -> float:
    """``min_π Σ cost[i, π(i)]`` over injective assignments of the smaller side."""
    if cost.size == 0:
        return 0.0
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].sum())


def _cut_distances(x: FloatArray, y: FloatArray, c: float, p: float) -> FloatArray:
    d = np.sqrt(((x[:, None, :] - y[None, :, :]) ** 2).sum(axis=2))
    return np.asarray(np.minimum(d, c) ** p, dtype=np.float64)


def ospa(x: ArrayLike, y: ArrayLike, c: float, p: float = 1.0) -> float:
    """OSPA distance of order ``p`` and cut-off ``c`` between point sets ``(m, dim)``, ``(n, dim)``.

    Raises
    ------
    InvalidInputError
        On non-finite points, mismatched dimensions or ``c, p ≤ 0``.
    """
    return ospa_components(x, y, c, p)[0]


def ospa_components(x: ArrayLike, y: ArrayLike, c: float,
                    p: float = 1.0) -> tuple[float, float, float]:
    """OSPA and its localisation and cardinality components, ``(total, loc, card)``.

    ``total^p = loc^p + card^p``: ``loc^p`` is the mean (over ``n = max(|X|, |Y|)``) cut-off
    distance of the optimal assignment, ``card^p = c^p (n − m) / n``; all three are 0 when both
    sets are empty. ``total`` equals :func:`ospa`.

    Raises
    ------
    InvalidInputError
        On non-finite points, mismatched dimensions or ``c, p ≤ 0``.
    """
    c, p = _params(c, p)
    a, b = _pair(x, y)
    m, n = sorted((a.shape[0], b.shape[0]))
    if n == 0:
        return 0.0, 0.0, 0.0
    loc_p = _assigned_cost(_cut_distances(a, b, c, p)) / n
    card_p = c**p * (n - m) / n
    root = 1.0 / p
    return float((loc_p + card_p) ** root), float(loc_p**root), float(card_p**root)


def gospa(x: ArrayLike, y: ArrayLike, c: float, p: float = 1.0, alpha: float = 2.0) -> float:
    """GOSPA distance (order ``p``, cut-off ``c``, ``α ∈ (0, 2]``) between point sets."""
    c, p = _params(c, p)
    alpha = checks.positive("alpha", alpha)
    if alpha > 2.0:
        raise InvalidInputError("alpha", alpha, "must be in (0, 2]")
    a, b = _pair(x, y)
    m, n = sorted((a.shape[0], b.shape[0]))
    total = _assigned_cost(_cut_distances(a, b, c, p)) + c**p / alpha * (n - m)
    return float(total ** (1.0 / p))


def _tracks(name: str, tracks: Sequence[ArrayLike]) -> list[FloatArray]:
    out = []
    for i, t in enumerate(tracks):
        arr = np.asarray(t, dtype=np.float64)
        if arr.ndim != 2:
            raise InvalidInputError(f"{name}[{i}]", t, "must be a (T, dim) array (NaN rows where "
                                    "the track does not exist)")
        out.append(arr)
    return out


def track_distance(x: FloatArray, y: FloatArray, c: float) -> float:
    """Beard et al.'s base distance between two ``(T, dim)`` tracks (NaN rows: absent).

    The mean over scans where either track exists of ``min(c, ‖x_t − y_t‖)`` (both exist) or
    ``c`` (one exists); 0 if neither ever exists.
    """
    if x.shape != y.shape:
        raise InvalidInputError("y", y.shape, f"must have the shape of x, {x.shape}")
    ex = ~np.any(np.isnan(x), axis=1)
    ey = ~np.any(np.isnan(y), axis=1)
    either = ex | ey
    if not np.any(either):
        return 0.0
    both = ex & ey
    d = np.full(x.shape[0], c)
    d[both] = np.minimum(np.linalg.norm(x[both] - y[both], axis=1), c)
    return float(d[either].mean())


def ospa2(x_tracks: Sequence[ArrayLike], y_tracks: Sequence[ArrayLike], c: float,
          p: float = 1.0) -> float:
    """OSPA(2) between two sets of tracks, each a ``(T, dim)`` array over the same window with
    NaN rows where the track does not exist."""
    c, p = _params(c, p)
    xs, ys = _tracks("x_tracks", x_tracks), _tracks("y_tracks", y_tracks)
    m, n = sorted((len(xs), len(ys)))
    if n == 0:
        return 0.0
    cost = np.array([[track_distance(a, b, c) ** p for b in ys] for a in xs]).reshape(
        len(xs), len(ys))
    total = _assigned_cost(cost) + c**p * (n - m)
    return float((total / n) ** (1.0 / p))
