"""Counting equal intervals on a segment without letting floating-point round-off add one."""

from __future__ import annotations

import math

#: A quotient within this relative distance of an integer is taken as that integer.
SNAP_REL = 1e-9


def interval_count(length: float, step: float) -> int:
    """Equal intervals covering ``length`` with spacing at most ``step``: ``⌈length / step⌉``,
    at least one, after snapping a quotient within :data:`SNAP_REL` (relative) of an integer onto
    that integer, so that ``(89.9 − 49.9) / 10 = 4.000000000000001`` gives 4 intervals, not 5."""
    q = length / step
    nearest = round(q)
    if abs(q - nearest) <= SNAP_REL * max(1.0, abs(q)):
        return max(1, int(nearest))
    return max(1, math.ceil(q))
