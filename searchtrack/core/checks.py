"""Boundary checks used by every layer: each failure names the caller's field and the bad value."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.errors import InvalidInputError

_REAL = (int, float, np.integer, np.floating)
ScalarT = TypeVar("ScalarT", bound=np.generic)


def readonly(a: NDArray[ScalarT], *, copy: bool = True) -> NDArray[ScalarT]:
    """``a`` as an array nobody can write through: a read-only copy, or with ``copy=False``
    ``a`` itself made read-only (for an array the caller has just built and shares with no one)."""
    out = np.array(a, copy=True) if copy else a
    out.setflags(write=False)
    return out


def real(name: str, value: object, *, low: float = -math.inf, high: float = math.inf,
         low_open: bool = False, high_open: bool = False) -> float:
    """``value`` as a float, or :class:`InvalidInputError` unless a finite number in the range.

    The range is ``[low, high]``; ``low_open`` / ``high_open`` exclude the end.
    """
    ok = isinstance(value, _REAL) and not isinstance(value, bool) and math.isfinite(value)
    if ok:
        v = float(value)  # type: ignore[arg-type]
        ok = (v > low if low_open else v >= low) and (v < high if high_open else v <= high)
    if not ok:
        lo, hi = "(" if low_open else "[", ")" if high_open else "]"
        raise InvalidInputError(name, value,
                                f"must be a finite number in {lo}{low:g}, {high:g}{hi}")
    return v


def finite_or_none(value: float) -> float | None:
    """``value``, or ``None`` when it is not finite (no value to report, e.g. in JSON or a
    results table)."""
    return value if math.isfinite(value) else None


def positive(name: str, value: object) -> float:
    """``value`` as a float, or :class:`InvalidInputError` unless finite and > 0."""
    return real(name, value, low=0.0, low_open=True)


def non_negative(name: str, value: object) -> float:
    """``value`` as a float, or :class:`InvalidInputError` unless finite and ≥ 0."""
    return real(name, value, low=0.0)


def probability(name: str, value: object) -> float:
    """``value`` as a float, or :class:`InvalidInputError` unless strictly inside ``(0, 1)``."""
    return real(name, value, low=0.0, high=1.0, low_open=True, high_open=True)


def boolean(name: str, value: object) -> bool:
    """``value``, or :class:`InvalidInputError` unless it is ``True`` or ``False`` (not 0, 1 or
    a string)."""
    if not isinstance(value, bool):
        raise InvalidInputError(name, value, "must be True or False")
    return value


def count(name: str, value: object, least: int = 0) -> int:
    """``value`` as an int, or :class:`InvalidInputError` unless an integer ≥ ``least``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise InvalidInputError(name, value, f"must be an integer ≥ {least}")
    return int(value)


def finite_array(name: str, value: ArrayLike, shape: tuple[int | None, ...]) -> NDArray[np.float64]:
    """A read-only float copy of ``value``, or :class:`InvalidInputError` unless finite and of
    ``shape`` (``None`` matches any length)."""
    try:
        arr = np.array(value, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise InvalidInputError(name, value, "must be an array of numbers") from None
    if arr.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, arr.shape,
                                                                              strict=True)):
        want = "(" + ", ".join("k" if s is None else str(s) for s in shape) + ")"
        raise InvalidInputError(name, value, f"must have shape {want}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, value, "must be finite (no NaN or inf)")
    arr.setflags(write=False)
    return arr


def points(name: str, value: ArrayLike) -> NDArray[np.float64]:
    """Planar points as a read-only ``(k, 2)`` float array: accepts one point ``(2,)``, ``(k, 2)``
    or an empty sequence; :class:`InvalidInputError` otherwise or when not finite."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(name, value, "must be an array of numbers") from None
    if arr.size == 0:
        arr = arr.reshape(0, 2)
    elif arr.shape == (2,):
        arr = arr.reshape(1, 2)
    return finite_array(name, arr, (None, 2))


def index_array(name: str, value: ArrayLike, size: int) -> NDArray[np.int64]:
    """A read-only 1-D int copy of ``value``, or :class:`InvalidInputError` unless each entry is
    an integer in ``[0, size)``."""
    arr = np.array(value, copy=True)
    if arr.ndim != 1 or (arr.size and arr.dtype.kind not in "iu"):
        raise InvalidInputError(name, value, "must be a 1-D array of integer indices")
    arr = arr.astype(np.int64)
    if arr.size and (arr.min() < 0 or arr.max() >= size):
        raise InvalidInputError(name, value, f"indices must be in [0, {size})")
    arr.setflags(write=False)
    return arr


def generator(name: str, value: object) -> np.random.Generator:
    """``value`` if it is a ``numpy.random.Generator``, else :class:`InvalidInputError`."""
    if not isinstance(value, np.random.Generator):
        raise InvalidInputError(name, value, "must be a numpy.random.Generator "
                                "(np.random.default_rng(seed))")
    return value


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


def choice(name: str, value: object, allowed: Sequence[object]) -> None:
    """:class:`InvalidInputError` unless ``value`` is one of ``allowed``."""
    if value not in allowed:
        raise InvalidInputError(name, value, f"must be one of {list(allowed)}")


def node_vector(name: str, values: ArrayLike, n_nodes: int | None = None) -> NDArray[np.float64]:
    """``values`` as a finite ``(n,)`` float array (a new, read-only copy; ``n ≥ 1``)."""
    arr = np.array(values, dtype=np.float64, copy=True)
    if arr.ndim != 1 or arr.size == 0 or (n_nodes is not None and arr.size != n_nodes):
        shape = "(n,)" if n_nodes is None else f"({n_nodes},)"
        raise InvalidInputError(name, values, f"must have shape {shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, values, "must be finite")
    arr.setflags(write=False)
    return arr
