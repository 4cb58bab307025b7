"""Stopping rules: a wall-clock deadline that every solver loop and backend call honours.

A deadline also expires as soon as a stop is requested (:mod:`searchtrack.core.interrupt`), so
every loop that honours its time limit honours Ctrl-C too.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested


def check_time_limit(time_limit_s: float) -> float:
    """Return ``time_limit_s`` if it is a positive number of seconds (``inf`` allowed)."""
    if (isinstance(time_limit_s, bool) or not isinstance(time_limit_s, (int, float))
            or math.isnan(time_limit_s) or time_limit_s <= 0):
        raise InvalidInputError("time_limit_s", time_limit_s, "must be positive seconds")
    return float(time_limit_s)


@dataclass
class Deadline:
    """A point in wall-clock time after which work must stop.

    ``Deadline(5.0)`` expires five seconds after construction; ``sub(f)`` gives a deadline that
    takes at most fraction ``f`` of the time left, for a stage inside a larger solve.
    """

    time_limit_s: float
    started: float = field(default_factory=time.perf_counter)

    def __post_init__(self) -> None:
        check_time_limit(self.time_limit_s)

    @property
    def end(self) -> float:
        """perf_counter value at which the deadline expires."""
        return self.started + self.time_limit_s

    def elapsed(self) -> float:
        """Seconds since the deadline was started."""
        return time.perf_counter() - self.started

    def remaining(self) -> float:
        """Seconds left (never negative; 0 once a stop is requested)."""
        if stop_requested():
            return 0.0
        return max(0.0, self.end - time.perf_counter())

    def expired(self) -> bool:
        """True once the time is up or a stop is requested."""
        return time.perf_counter() >= self.end or stop_requested()

    def sub(self, fraction: float) -> Deadline:
        """A deadline for a stage: at most ``fraction`` of the remaining time, at least 1 ms."""
        return Deadline(max(1e-3, self.remaining() * fraction))
