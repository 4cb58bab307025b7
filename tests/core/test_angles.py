"""Angles wrapped into [−π, π), for floats and arrays alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.angles import wrap_angle


@pytest.mark.parametrize("angle", [0.0, math.pi, -math.pi, 3.5, -7.0, 100.0])
def test_wrap_angle_scalars_and_arrays_agree(angle: float) -> None:
    """wrap_angle maps into [−π, π), the same for a float and for an array element."""
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.isclose(math.remainder(wrapped - angle, 2 * math.pi), 0.0, abs_tol=1e-12)
    assert wrap_angle(np.array([angle]))[0] == wrapped


@pytest.mark.parametrize(("angle", "expected"), [
    (0.0, 0.0),
    (math.pi / 2, math.pi / 2),
    (3 * math.pi / 2, -math.pi / 2),
    (-3 * math.pi / 2, math.pi / 2),
    (math.pi, -math.pi),
    (-math.pi, -math.pi),
    (5 * math.pi / 2, math.pi / 2),
    (-0.25, -0.25),
])
def test_wrap_angle_known_values(angle: float, expected: float) -> None:
    """Hand-wrapped angles: 3π/2 → −π/2, π → −π (the closed end), small angles unchanged."""
    assert wrap_angle(angle) == pytest.approx(expected, abs=1e-12)


def test_wrap_angle_keeps_the_array_shape_and_returns_floats() -> None:
    """An array keeps its shape element-wise; an int scalar comes back as a float."""
    grid = np.array([[0.0, 2 * math.pi], [-2 * math.pi, 7 * math.pi]])
    out = wrap_angle(grid)
    assert isinstance(out, np.ndarray) and out.shape == (2, 2)
    np.testing.assert_allclose(out, [[0.0, 0.0], [0.0, -math.pi]], atol=1e-12)
    scalar = wrap_angle(4)  # type: ignore[call-overload]
    assert isinstance(scalar, float) and scalar == pytest.approx(4 - 2 * math.pi)
