"""Boundary checks: read-only arrays, and angles wrapped into [−π, π)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.angles import wrap_angle
from searchtrack.core.checks import readonly


def test_readonly_copies_unless_told_not_to() -> None:
    """readonly() freezes a copy, keeping the dtype; copy=False freezes the array itself."""
    a = np.arange(4)
    frozen = readonly(a)
    assert frozen.dtype == a.dtype and not frozen.flags.writeable and a.flags.writeable
    a[0] = 7
    assert frozen[0] == 0
    b = np.zeros(3)
    assert readonly(b, copy=False) is b and not b.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        frozen[1] = 5


@pytest.mark.parametrize("angle", [0.0, math.pi, -math.pi, 3.5, -7.0, 100.0])
def test_wrap_angle_scalars_and_arrays_agree(angle: float) -> None:
    """wrap_angle maps into [−π, π), the same for a float and for an array element."""
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.isclose(math.remainder(wrapped - angle, 2 * math.pi), 0.0, abs_tol=1e-12)
    assert wrap_angle(np.array([angle]))[0] == wrapped
