"""searchtrack.core: what every layer shares — the one result type, backend registries, time
limits and the stop flag Ctrl-C sets, boundary checks, errors, array types and angle utilities.
It imports nothing else of searchtrack."""

from __future__ import annotations

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError, ParseError, SearchtrackError
from searchtrack.core.interrupt import clear_stop, request_stop, sigint_stops, stop_requested
from searchtrack.core.registry import (
    MAX_SEED,
    Backend,
    Registry,
    SolveFn,
    Stage,
    check_seed,
    fallback_chain,
    heuristic_then_exact,
    relabel,
)
from searchtrack.core.result import Result, Sense, Status, interrupted, merge_answers
from searchtrack.core.types import BoolArray, FloatArray, IntArray

__all__ = [
    "MAX_SEED",
    "Backend",
    "BoolArray",
    "Deadline",
    "FloatArray",
    "IntArray",
    "InvalidInputError",
    "ParseError",
    "Registry",
    "Result",
    "SearchtrackError",
    "Sense",
    "SolveFn",
    "Stage",
    "Status",
    "check_seed",
    "check_time_limit",
    "clear_stop",
    "fallback_chain",
    "heuristic_then_exact",
    "interrupted",
    "merge_answers",
    "relabel",
    "request_stop",
    "sigint_stops",
    "stop_requested",
]
