"""Angle utilities (radians throughout)."""

from __future__ import annotations

import math
from typing import overload

import numpy as np

from searchtrack.core.types import FloatArray


@overload
def wrap_angle(angle_rad: float) -> float: ...


@overload
def wrap_angle(angle_rad: FloatArray) -> FloatArray: ...


def wrap_angle(angle_rad: float | FloatArray) -> float | FloatArray:
    """``angle_rad`` wrapped into ``[−π, π)`` (element-wise for arrays)."""
    if isinstance(angle_rad, np.ndarray):
        out: FloatArray = np.mod(angle_rad + np.pi, 2.0 * np.pi) - np.pi
        return out
    return (float(angle_rad) + math.pi) % (2.0 * math.pi) - math.pi
