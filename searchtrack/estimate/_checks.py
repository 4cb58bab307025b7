"""Boundary checks shared by the estimate modules: each failure names the caller's field."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.errors import InvalidInputError


def real(name: str, value: object, *, positive: bool = False) -> float:
    """``value`` as a finite float (``> 0`` if ``positive``), else :class:`InvalidInputError`."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidInputError(name, value, "must be a real number")
    x = float(value)
    if not math.isfinite(x):
        raise InvalidInputError(name, value, "must be finite")
    if positive and x <= 0.0:
        raise InvalidInputError(name, value, "must be > 0")
    return x


def node_set(name: str, nodes: ArrayLike, n_nodes: int) -> NDArray[np.int64]:
    """``nodes`` as a 1-D array of node indices in ``[0, n_nodes)`` (may be empty)."""
    arr = np.asarray(nodes)
    if arr.size == 0:
        return np.empty(0, dtype=np.int64)
    if arr.ndim != 1 or arr.dtype.kind not in "iu":
        raise InvalidInputError(name, nodes, "must be a 1-D array of integer node indices")
    if arr.min() < 0 or arr.max() >= n_nodes:
        raise InvalidInputError(name, nodes, f"node indices must be in [0, {n_nodes})")
    return arr.astype(np.int64)


def node_vector(name: str, values: ArrayLike, n_nodes: int | None = None) -> NDArray[np.float64]:
    """``values`` as a finite ``(n,)`` float array (a new, read-only copy)."""
    arr = np.array(values, dtype=np.float64, copy=True)
    if arr.ndim != 1 or arr.size == 0 or (n_nodes is not None and arr.size != n_nodes):
        shape = "(n,)" if n_nodes is None else f"({n_nodes},)"
        raise InvalidInputError(name, values, f"must have shape {shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, values, "must be finite")
    arr.setflags(write=False)
    return arr


def points(name: str, xy_m: ArrayLike) -> NDArray[np.float64]:
    """``xy_m`` as a finite ``(k, 2)`` float array (``k`` may be 0)."""
    arr = np.asarray(xy_m, dtype=np.float64)
    if arr.size == 0:
        return np.empty((0, 2), dtype=np.float64)
    if arr.ndim == 1 and arr.shape == (2,):
        arr = arr.reshape(1, 2)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidInputError(name, xy_m, "must have shape (k, 2)")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, xy_m, "must be finite")
    return arr
