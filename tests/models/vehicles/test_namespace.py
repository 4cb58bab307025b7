"""The NumPy array namespace: elementwise functions and stacking of scalar and batched rows."""

from __future__ import annotations

import math

import numpy as np

from searchtrack.models.vehicles import NUMPY, NumpyNamespace


def test_sin_and_cos_are_elementwise() -> None:
    """sin and cos act elementwise on arrays and on scalars."""
    x = np.array([0.0, math.pi / 6, math.pi / 2])
    np.testing.assert_allclose(NUMPY.sin(x), [0.0, 0.5, 1.0], atol=1e-15)
    np.testing.assert_allclose(NUMPY.cos(x), [1.0, math.sqrt(3) / 2, 0.0], atol=1e-15)
    assert NUMPY.cos(math.pi) == -1.0


def test_stack_of_scalars_is_a_vector() -> None:
    """Scalar rows stack into an (n,) float64 array."""
    out = NumpyNamespace().stack([1, 2.5, np.float32(3.0)])
    assert out.dtype == np.float64 and out.shape == (3,)
    assert out.tolist() == [1.0, 2.5, 3.0]


def test_stack_of_vectors_is_a_batch() -> None:
    """Equal-length rows stack into an (n, batch) array, row by row."""
    out = NUMPY.stack([np.array([1.0, 2.0]), np.array([3.0, 4.0]), np.array([5.0, 6.0])])
    np.testing.assert_array_equal(out, [[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])


def test_scalar_rows_broadcast_beside_batched_rows() -> None:
    """A ragged mix (a constant input beside batched states) repeats the scalar along the batch."""
    out = NUMPY.stack([np.array([1.0, 2.0, 3.0]), 0.5, np.array([4.0, 5.0, 6.0])])
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [[1.0, 2.0, 3.0], [0.5, 0.5, 0.5], [4.0, 5.0, 6.0]])
