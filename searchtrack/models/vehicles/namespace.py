"""The array namespace vehicle dynamics are written against, so one formula serves NumPy and CasADi.

Dynamics index the state and input by row (``x[0]``, ``u[1]``) and use only arithmetic and the
functions of :class:`ArrayNamespace`. NumPy arrays of shape ``(n,)`` or ``(n, batch)`` and CasADi
``SX``/``MX`` column vectors both index that way. This module deliberately knows nothing of CasADi
(the models layer stays NumPy-only); ``searchtrack.plan.trajectory.symbolic`` supplies the CasADi
namespace.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np


class ArrayNamespace(Protocol):
    """The elementwise functions and the row-stacking a dynamics function may call."""

    def sin(self, x: Any) -> Any:
        """Elementwise sine."""
        ...

    def cos(self, x: Any) -> Any:
        """Elementwise cosine."""
        ...

    def stack(self, rows: Sequence[Any]) -> Any:
        """Rows (scalars or equal-length vectors) stacked into one column/array."""
        ...


class NumpyNamespace:
    """:class:`ArrayNamespace` over NumPy; ``stack`` makes ``(n,)`` or ``(n, batch)`` arrays."""

    def sin(self, x: Any) -> Any:
        """Elementwise sine."""
        return np.sin(x)

    def cos(self, x: Any) -> Any:
        """Elementwise cosine."""
        return np.cos(x)

    def stack(self, rows: Sequence[Any]) -> Any:
        """Rows stacked along axis 0 (scalars broadcast against vector rows)."""
        try:
            return np.array(rows, dtype=np.float64)
        except ValueError:  # ragged: a scalar row beside batched rows
            return np.stack(np.broadcast_arrays(*rows)).astype(np.float64)


NUMPY = NumpyNamespace()
